"""``stylemotion-data``: build a dataset (or load it from the cache), print and save its summary.

    stylemotion-data                              # the embedded synthetic dataset
    stylemotion-data data=bandai                  # Bandai from ../shared/data (or $STYLEMOTION_DATA)
    stylemotion-data data=bvh_folder data.root=my_bvhs data.pattern='(?P<style>[a-z]+)_(?P<take>\\d+)'
"""

from __future__ import annotations

import json
import logging
from pathlib import Path

import hydra
from hydra.core.hydra_config import HydraConfig
from omegaconf import DictConfig

from stylemotion.config import config_dir
from stylemotion.datasets import build_dataset
from stylemotion.io.atomic import atomic_write_bytes
from stylemotion.summary import dataset_summary, format_summary

log = logging.getLogger(__name__)


def run(cfg: DictConfig, out_dir: Path) -> dict:
    """Build ``cfg.data`` and write ``summary.json`` into ``out_dir``; returns the summary."""
    takeset = build_dataset(cfg.data)
    split_cfg = cfg.data.get("split") or {}
    split = takeset.split(**split_cfg)
    summary = dataset_summary(takeset, split)
    atomic_write_bytes(out_dir / "summary.json", json.dumps(summary, indent=2).encode())
    print(format_summary(summary))
    print(f"summary written to {out_dir / 'summary.json'}")
    return summary


def main() -> None:
    hydra.main(config_path=config_dir(), config_name="prepare", version_base="1.3")(_main)()


def _main(cfg: DictConfig) -> None:
    run(cfg, Path(HydraConfig.get().runtime.output_dir))


if __name__ == "__main__":
    main()
