"""A :class:`~stylemotion.synthesis.graph.MotionGraph` whose nodes are Morphable Graph primitives (Du ch. 3–4).

The primitives and their MAP step search are :mod:`stylemotion.morphable.synthesis`; this module puts them
into the graph the path-following controller walks (:func:`~stylemotion.synthesis.controller.follow_path`),
so ``stylemotion-generate model=morphable`` walks them like the deep models. The Morphable Graph code
imports nothing of synthesis; synthesis builds on it here.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

from stylemotion.config import ConfigError
from stylemotion.morphable.model import MorphableModel
from stylemotion.morphable.synthesis import MapSettings, MorphablePrimitive
from stylemotion.synthesis.controller import LOOKAHEAD_TARGETS
from stylemotion.synthesis.graph import TRANSITIONS, MotionGraph, short_primitive

__all__ = ["MapSettings", "link_graph", "load_morphable_graph"]


def link_graph(graph) -> None:
    """Tell every Morphable Graph node of ``graph`` which nodes take the steps after it (alternating stances,
    as the controller walks), for the look-ahead."""
    for name, node in graph.models.items():
        if not isinstance(node, MorphablePrimitive):
            continue
        node.following, current = [], name
        for _ in range(LOOKAHEAD_TARGETS):  # as many nodes as the controller hands on targets of later steps
            nxt = [p for p in TRANSITIONS[current] if p in graph.models and not p.startswith("end")]
            if not nxt or not isinstance(graph.models[nxt[0]], MorphablePrimitive):
                break
            current = nxt[0]
            node.following.append(graph.models[current])


def load_morphable_graph(models: Mapping[str, str | Path | Sequence[str | Path]], action: str = "walk",
                         settings: MapSettings | None = None):
    """A :class:`~stylemotion.synthesis.graph.MotionGraph` of Morphable Graph primitives from
    ``{primitive: model file or run folder, or a list of them}`` (``walk_leftStance`` or ``leftStance``); a list
    gives the primitive's variants (e.g. its turn variants), chosen per step by look-ahead."""
    if not models:
        raise ConfigError("model=morphable needs +models.walk_leftStance=<run folder or model.npz> "
                          "+models.walk_rightStance=<…>")
    loaded, sources = {}, {}
    for key, paths in sorted(models.items()):
        primitive = short_primitive(str(key), action)
        paths = [paths] if isinstance(paths, (str, Path)) else list(paths)
        if not paths:
            raise ConfigError(f"models.{key} is an empty list; give a run folder or model.npz (or several)")
        variants = []
        for path in paths:
            try:
                model = MorphableModel.load(path)
            except (OSError, ValueError, KeyError) as err:
                raise ConfigError(f"models.{key}={path}: {err}") from err
            have = f"{model.meta.get('action')}_{model.meta.get('primitive')}"
            if have != f"{action}_{primitive}":
                raise ConfigError(f"models.{key}={path} holds a {have} model, not {action}_{primitive}")
            variants.append(model)
        try:
            loaded[primitive] = MorphablePrimitive(variants, settings)
        except ValueError as err:
            raise ConfigError(f"models.{key}: {err}") from err
        sources[primitive] = ", ".join(str(m.meta["path"]) for m in variants)
    styles = {m.meta.get("style") for node in loaded.values() for m in node.variants.values()}
    graph = MotionGraph(action=action, style="/".join(sorted(str(s) for s in styles)), models=loaded, sources=sources)
    link_graph(graph)
    return graph
