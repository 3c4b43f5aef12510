"""Pictures in TensorBoard: sample animations and evaluation figures as image summaries.

* :func:`log_sample_images`: the contact sheet of a model's samples and evenly spaced frames of their GIF
  (the sample callback calls it after training, beside the hyperparameters and the monitored metric that
  :mod:`stylemotion.training.fit` logs);
* :func:`write_report_events`: an evaluation report's PNG figures (Table 5.1 heat maps, confusion
  matrices, variance ratios) with its settings as hyperparameters and its headline numbers as metrics, in
  an event folder of its own (``<report>/tensorboard``).

Images are read back from the PNG/GIF files the figures were written to, so TensorBoard shows exactly them.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from PIL import Image, ImageSequence


def _rgb(image: Image.Image) -> np.ndarray:
    return np.asarray(image.convert("RGB"))


def gif_frames(path: str | Path, count: int = 8) -> np.ndarray:
    """``(count, height, width, 3)`` uint8: ``count`` evenly spaced frames of a GIF (fewer if it has fewer)."""
    with Image.open(path) as gif:
        frames = [_rgb(f) for f in ImageSequence.Iterator(gif)]
    pick = np.unique(np.linspace(0, len(frames) - 1, min(count, len(frames))).round().astype(int))
    return np.stack([frames[i] for i in pick])


def log_sample_images(writer: Any, gif: str | Path, sheet: str | Path, step: int, tag: str = "samples",
                      frames: int = 8) -> None:
    """Add ``<tag>/last_frames`` (the contact sheet) and ``<tag>/animation`` (``frames`` GIF frames) to a
    ``torch.utils.tensorboard.SummaryWriter`` at ``step``."""
    with Image.open(sheet) as image:
        writer.add_image(f"{tag}/last_frames", _rgb(image), step, dataformats="HWC")
    writer.add_images(f"{tag}/animation", gif_frames(gif, frames), step, dataformats="NHWC")
    writer.flush()


def _headline(results: Mapping[str, Any]) -> dict[str, float]:
    """The report's numbers worth a glance: Table 5.1 diagonal rows and columns, classifier accuracy."""
    out: dict[str, float] = {}
    for p, t in results.get("table_5_1", {}).items():
        out[f"table_5_1/{p}/diagonal_rows"] = float(len(t["diagonal"]["rows"]))
        out[f"table_5_1/{p}/diagonal_columns"] = float(len(t["diagonal"]["columns"]))
    accuracy = results.get("style_recognition", {}).get("classifier_heldout_accuracy")
    if accuracy is not None and np.isfinite(accuracy):
        out["style_recognition/classifier_heldout_accuracy"] = float(accuracy)
    return out


def write_report_events(folder: Path, results: Mapping[str, Any], figures: Sequence[str],
                        events: str = "tensorboard") -> Path:
    """Write the report's figures, settings and headline numbers as TensorBoard events into
    ``folder/events`` (``tensorboard --logdir <report>``); returns that folder."""
    from torch.utils.tensorboard import SummaryWriter

    meta = results.get("meta", {})
    samples = meta.get("samples") or {}
    hparams = {"data": str(meta.get("data_name", "?")), "seed": int(meta.get("seed", -1)),
               **{f"samples_{k}": int(v) for k, v in samples.items() if isinstance(v, int)}}
    out = folder / events
    writer = SummaryWriter(log_dir=str(out))
    try:
        for name in figures:
            with Image.open(folder / name) as image:
                writer.add_image(f"report/{Path(name).stem}", _rgb(image), 0, dataformats="HWC")
        metrics = _headline(results)
        if metrics:
            writer.add_hparams(hparams, metrics, run_name=".")
    finally:
        writer.close()
    return out
