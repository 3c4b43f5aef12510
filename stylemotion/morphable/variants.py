"""Turn variants of a stance primitive: the clips of one primitive split by how much the step turns.

Du's Morphable Graph has several primitives competing for one step — a straight step, turning steps, a
sidestep — and its graph walk picks among them (§4.5.1, :mod:`.lookahead`). Bandai's walk stances come from
straight walks and from walks turning left or right, so one stance's clips can be split by their heading
change ``Δψ`` (degrees, positive = to the body's left, the integral of the frames' yaw rate):

* ``left``: ``Δψ > threshold``; ``right``: ``Δψ < −threshold``; ``straight``: ``|Δψ| ≤ threshold``;
* ``None`` (no variant): every clip.

Each variant is fitted as its own model (``stylemotion-train experiment=morphable_graph turn=left``), and
``stylemotion-generate model=morphable`` takes a list of models per stance as that stance's variants.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from stylemotion.primitives.segmentation import Clip
from stylemotion.representation import YAW_RATE_DIM

#: Turn variants (None: every clip).
TURNS = ("straight", "left", "right")
#: Default |Δψ| (degrees) that separates turning steps from straight ones.
TURN_THRESHOLD_DEG = 10.0


def clip_turn_deg(clip: Clip) -> float:
    """Heading change over the clip, degrees (positive: to the left)."""
    return float(np.degrees(clip.frames[:-1, YAW_RATE_DIM].astype(np.float64).sum() / clip.fps))


def select_turn(clips: Sequence[Clip], turn: str | None, threshold_deg: float = TURN_THRESHOLD_DEG) -> list[Clip]:
    """The clips of turn variant ``turn`` (see the module doc)."""
    if turn is None:
        return list(clips)
    if turn not in TURNS:
        raise ValueError(f"unknown turn variant {turn!r}; one of {list(TURNS)} or null (every clip)")
    if not threshold_deg > 0:
        raise ValueError(f"turn threshold must be positive degrees, got {threshold_deg}")
    turns = np.array([clip_turn_deg(c) for c in clips])
    keep = {"left": turns > threshold_deg, "right": turns < -threshold_deg,
            "straight": np.abs(turns) <= threshold_deg}[turn]
    return [c for c, k in zip(clips, keep) if k]


def variant_name(turn: str | None) -> str:
    """``turn-left`` etc.; ``all`` for every clip."""
    return "all" if turn is None else f"turn-{turn}"
