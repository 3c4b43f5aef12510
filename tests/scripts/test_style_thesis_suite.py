"""Suite ``style_thesis`` (scripts/suites/style_thesis.py): each arm trains on its preset with its own overrides and
the suite's epochs (the stage's α only on our preset); each arm's Table 5.1 is read out of the evaluation's table of
every model (owners and shared rows) — hand-made figures, no training."""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import style_thesis  # noqa: E402

STAGE = ["experiment=style_cvae", "trainer.max_epochs=60", "model.samples_per_item=10",
         "callbacks.checkpoint_last.every_n_epochs=1", "model.style_weight=5.0"]


def test_each_arm_changes_only_its_own_values() -> None:
    ours = style_thesis.arm_overrides(STAGE, "ours", 15)
    # ours pins the Gram over every channel, as the suite measured it (the commands' default became pose-only)
    assert ours == ["experiment=style_cvae", "model.samples_per_item=10", "callbacks.checkpoint_last.every_n_epochs=1",
                    "model.style_weight=5.0", "trainer.max_epochs=15", "callbacks.samples=null",
                    "model.style_channels=all", "model.style_subset=0"]
    assert style_thesis.arm_overrides(STAGE, "alpha200", 15) == [*ours[:3], "trainer.max_epochs=15",
                                                                 "callbacks.samples=null", "model.style_channels=all",
                                                                 "model.style_subset=0", "model.style_weight=200.0"]
    pose = style_thesis.arm_overrides(STAGE, "pose_gram", 15)
    assert pose[-2:] == ["model.style_channels=pose", "model.style_subset=128"]
    assert style_thesis.arm_overrides(STAGE, "lr1e-5", 15) == [*ours, "model.lr=1e-05"]
    # the preset brings its own α (200): the stage's α of our preset is not passed on
    thesis = style_thesis.arm_overrides(STAGE, "thesis", 15)
    assert thesis[0] == "experiment=style_cvae_thesis" and not any(o.startswith("model.style_weight") for o in thesis)
    assert "trainer.max_epochs=15" in thesis


def test_an_arms_table_5_1_is_read_from_owner_and_shared_rows() -> None:
    # columns owned by the first arm of each example; the other arm's rows are shared (extra) rows
    table = {"models": ["neutral", "a:x", "a:y"],
             "distance": [[1.0, 5.0, 6.0], [4.0, 2.0, 7.0], [4.0, 6.0, 3.0]],
             "extra_rows": {"b:x": [0.5, 3.0, 9.0], "b:y": [4.0, 8.0, 2.0]}}
    a = style_thesis.arm_table(table, "a", ["x", "y"])
    assert a["rows_on_diagonal"] == 3 and a["columns_on_diagonal"] == 3
    assert a["own_vs_neutral"] == {"x": 2.0 / 5.0, "y": 3.0 / 6.0}
    b = style_thesis.arm_table(table, "b", ["x", "y"])
    assert b["distance"] == [[1.0, 5.0, 6.0], [0.5, 3.0, 9.0], [4.0, 8.0, 2.0]]
    # b:x sits nearer the neutral column than its own (row off the diagonal), and the neutral VAE is not nearest
    # to the neutral column among b's rows (b:x is): 2 rows, 2 columns on the diagonal
    assert b["rows_on_diagonal"] == 2 and b["columns_on_diagonal"] == 2
