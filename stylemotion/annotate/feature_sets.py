"""The relational feature sets templates can be learned with, by name.

* ``ours`` (the default): :mod:`stylemotion.annotate.features`, 42 features with turning and speed relations;
* ``mueller_roeder``: :mod:`stylemotion.annotate.mueller_roeder`, Müller & Röder's 39 with hysteresis and
  Krüger's root angular velocity (40).

A templates folder records the set it was learned with; documents are annotated with that set, and templates of
two sets are never matched together (:func:`same_feature_set`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

import numpy as np

from stylemotion.annotate import features, mueller_roeder
from stylemotion.io.errors import UserInputError

DEFAULT_FEATURE_SET = "ours"
_SETS: dict[str, tuple[tuple[str, ...], Callable[[np.ndarray, float], np.ndarray]]] = {
    "ours": (features.FEATURE_NAMES, features.relational_features),
    "mueller_roeder": (mueller_roeder.FEATURE_NAMES, mueller_roeder.mueller_roeder_features),
}
FEATURE_SETS: tuple[str, ...] = tuple(_SETS)


class FeatureSetError(UserInputError, ValueError):
    """An unknown feature set, or templates of two sets used together; the message names them."""


def checked_feature_set(name: object, key: str = "feature_set") -> str:
    """``name`` if it is a known set; :class:`FeatureSetError` naming ``key``, the value and the sets."""
    if name not in _SETS:
        raise FeatureSetError(f"{key}={name!r} is not a feature set; use one of {', '.join(FEATURE_SETS)}")
    return str(name)


def feature_names(name: str) -> tuple[str, ...]:
    """Column names of set ``name``."""
    return _SETS[checked_feature_set(name)][0]


def compute_features(positions: np.ndarray, fps: float, name: str = DEFAULT_FEATURE_SET) -> np.ndarray:
    """``(frames, features)`` bool features of ``(frames, 21, 3)`` positions in set ``name``."""
    return _SETS[checked_feature_set(name)][1](positions, fps)


def same_feature_set(sets: Iterable[str], what: str = "templates") -> str:
    """The one set of ``sets``; :class:`FeatureSetError` when they mix two or more (or are empty)."""
    found = sorted(set(sets))
    if len(found) != 1:
        raise FeatureSetError(f"{what} mix feature sets {found or 'none'}; learn and match with one set")
    return found[0]
