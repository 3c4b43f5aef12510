"""A :class:`~stylemotion.synthesis.graph.MotionGraph` whose nodes are Morphable Graph primitives (Du ch. 3–4).

The primitives and their MAP step search are :mod:`stylemotion.morphable.synthesis`; this module puts them
into the graph the path-following controller walks (:func:`~stylemotion.synthesis.controller.follow_path`),
so ``stylemotion-generate model=morphable`` walks them like the deep models. The Morphable Graph code
imports nothing of synthesis; synthesis builds on it here.
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from stylemotion.config import ConfigError
from stylemotion.geometry import wrap_angle
from stylemotion.morphable.model import MorphableModel
from stylemotion.morphable.synthesis import MapSettings, MorphablePrimitive
from stylemotion.synthesis.controller import LOOKAHEAD_TARGETS, SynthesizedMotion, restitch
from stylemotion.synthesis.graph import TRANSITIONS, MotionGraph, short_primitive
from stylemotion.synthesis.joint_walk import JointStep, optimize_steps
from stylemotion.synthesis.settings import FollowSettings

__all__ = ["MapSettings", "finish_walk", "link_graph", "load_morphable_graph", "optimize_walk", "target_error"]


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


def target_error(walk: SynthesizedMotion, follow: FollowSettings) -> float:
    """How far a walk's stitched steps end from their targets: ``Σ_i ‖p_i − p*_i‖² / σ_p² + wrap(θ_i − θ*_i)² / σ_θ²``
    over its steps (``p_i, θ_i``: where step ``i`` ends in the stitched motion; the scales ``follow.*``)."""
    total = 0.0
    for step in walk.steps:
        gap = np.asarray(step.end_xz) - np.asarray(step.target_xz)
        total += float(gap @ gap) / follow.position_scale_m ** 2
        total += float(wrap_angle(step.end_yaw - step.target_yaw)) ** 2 / follow.heading_scale_rad ** 2
    return total


def optimize_walk(graph: MotionGraph, walk: SynthesizedMotion, follow: FollowSettings,
                  max_evaluations: int) -> tuple[SynthesizedMotion, dict[str, Any]]:
    """Algorithm 1, line 9 (Du): the codes of all of ``walk``'s steps optimized together after the graph walk
    (:func:`stylemotion.synthesis.joint_walk.optimize_steps`: each step keeps its primitive, variant and target),
    then the walk re-stitched from them (:func:`~stylemotion.synthesis.controller.restitch`); ``walk`` itself when LM
    found no lower objective. Returns the walk and what happened: ``objective_before``/``_after`` (the joint
    objective), ``target_error_before``/``_after`` (:func:`target_error` of the stitched walks), ``kept``,
    ``evaluations`` and ``seconds``."""
    began = time.perf_counter()
    models = []
    for step in walk.steps:
        node = graph.models[step.primitive]
        if not isinstance(node, MorphablePrimitive):
            raise ValueError(f"optimize_walk needs Morphable Graph steps; step {step.primitive} is a "
                             f"{type(node).__name__}")
        models.append(node.variants.get(step.variant, node.model))
    steps = [JointStep(m, np.asarray(s.latent, dtype=np.float64), np.asarray(s.target_xz, dtype=np.float64),
                       float(s.target_yaw)) for m, s in zip(models, walk.steps)]
    result = optimize_steps(steps, walk.path.start, float(walk.path.heading_at(0.0)), follow, max_evaluations)
    before = target_error(walk, follow)
    record = {"objective_before": result.start_cost, "objective_after": result.cost,
              "target_error_before": before, "target_error_after": before, "kept": result.improved,
              "evaluations": result.evaluations}
    if result.improved:
        walk = restitch(walk, [m.decode_latent for m in models], result.latents, follow)
        record["target_error_after"] = target_error(walk, follow)
    record["seconds"] = time.perf_counter() - began
    return walk, record


def finish_walk(graph: MotionGraph, walk: SynthesizedMotion, follow: FollowSettings
                ) -> tuple[SynthesizedMotion, dict[str, Any] | None]:
    """``walk`` after Algorithm 1's line 9 (:func:`optimize_walk`) where its nodes' settings ask for it
    (``MapSettings.joint_evaluations`` > 0), with what that did; else ``(walk, None)``."""
    budgets = {node.settings.joint_evaluations for node in graph.models.values()
               if isinstance(node, MorphablePrimitive)}
    budget = max(budgets, default=0)
    if budget < 1:
        return walk, None
    return optimize_walk(graph, walk, follow, budget)
