"""Suite ``markers``: full poses from six *skin* markers (Krüger §2.5.2 with markers off the joints) on recordings of
actors not in the database, what the largest per-joint errors come from, and how constant the output's bones are.

Per seed: Bandai is split by take (``TakeSet.split(seed, 0.1, 0.1)``, grouped by content and style).

* **Other captures** (``other-skeletons``: other actors, studios and skeletons, never in any database): the
  default skin-marker set (:data:`stylemotion.reconstruct.marker_set.SKIN_MARKERS`) put **virtually** on their
  joints (no real C3D capture exists in the shared data), with the noise model of
  :func:`stylemotion.reconstruct.benchmark.skin_marker_noise` (placement ± 10 mm per axis per recording, jitter
  ± 1 mm per frame); database = the seed's train takes. Conditions: today's method (markers at the joint centres,
  no bone holding), skin markers on the database's bones, skin markers with the database scaled to the subject
  from the markers (:func:`~stylemotion.reconstruct.sparse.subject_scale`), skin markers with the subject's
  bone lengths given, and with the subject's skeleton given (bone lengths and the directions of the bones fixed in
  the pelvis and chest: :func:`stylemotion.reconstruct.subject.subject_from_motion` on the recording itself, as a
  capture system's subject calibration gives them; no separate calibration take exists in the shared data);
  beside them the nearest-neighbour baseline and
  the **floor**: the database pose (on the same skeleton, in the markers' frame) nearest to the truth in all
  joints, which the k-NN alone cannot beat.
* **Bandai leave-actor-out**: :func:`stylemotion.datasets.actors.actor_groups` finds Bandai's three actors by
  the rest poses of their files (suite ``actors``); every actor performed every content, so leaving one out is a
  cross-actor test of reconstruction. Seed ``s`` leaves actor group ``s mod 3`` out of the database (train takes of
  the other actors); the marker-only feature set, ``k`` and the local model's prior weight are chosen together on
  that actor's val takes (a grid, ``--features``, ``--k``, ``--prior-weights``) and reported on its test takes.
  The other captures use the seed's choice (beside them the library's defaults), so nothing is chosen on them.
"""

from __future__ import annotations

import argparse
import os
import time
from collections import Counter
from typing import Any

import numpy as np
from suites.common import DATA_ROOT, fmt, fmt_spread, md_table, provenance_line, spread, take_split_record

DESCRIPTION = ("six skin markers → 21 joints on other captures (virtual markers, noise model stated) and Bandai "
               "leave-actor-out; bone lengths held; where the largest per-joint errors come from")
VAL_FRACTION, TEST_FRACTION = 0.1, 0.1
OTHER_CAPTURES = ("walk_21joint_60fps.bvh", "female-walk_21joint_60fps.bvh", "xia_neutral_01_000_31joint_120fps.bvh")
CONDITIONS = {
    "joints": "the method before: markers at the joint centres, database's bones, bones not held",
    "skin": "skin markers, database's bones",
    "skin_scaled": "skin markers, database scaled to the subject from the markers",
    "skin_lengths": "skin markers, the subject's bone lengths given",
    "skin_subject": "skin markers, the subject's skeleton given (bone lengths, rigid bones, feet: calibration)",
    "skin_subject_no_feet": "the same without the feet's convention (the database's foot bones)",
    "skin_subject_defaults": "the same with the settings before (E15, k 512, prior weight 1) instead of the val "
                             "choice",
    "skin_subject_unheld": "the same, bones not held (the local model's poses as they come)",
    "skin_subject_nn": "nearest neighbour (k = 1), the subject's skeleton given",
    "floor_subject": "floor: the database pose nearest to the truth in all joints, on the subject's skeleton",
}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--contents", nargs="+", default=["walk", "run", "wave-both-hands", "raise-up-both-hands"],
                        help="Bandai queries' contents (leave-actor-out)")
    parser.add_argument("--k", type=int, nargs="+", default=[128, 512], help="candidates of k (chosen on val)")
    parser.add_argument("--features", nargs="+", default=["E15", "E15x3", "E15x5"],
                        help="candidate marker-only feature sets (chosen on val with k and the prior weight)")
    parser.add_argument("--prior-weights", type=float, nargs="+", default=[1.0, 3.0, 10.0, 30.0, 100.0],
                        help="candidates of the local model's prior weight (chosen on val)")
    parser.add_argument("--placement-mm", type=float, default=10.0, help="marker placement error, ± mm per axis")
    parser.add_argument("--jitter-mm", type=float, default=1.0, help="per-frame marker jitter, ± mm per axis")


def _floor(rec, markers: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """The database pose (in the markers' frame) nearest to the truth in all joints, placed back → (frames, 21, 3)."""
    from scipy.spatial import cKDTree

    from stylemotion.reconstruct.sparse import marker_frames, to_local, to_world

    rotation, origin = marker_frames(markers, rec.roles)
    local = to_local(truth, rotation, origin).reshape(len(truth), -1)
    _, nearest = cKDTree(rec.local).query(local, 1)
    return to_world(rec.local[nearest].reshape(len(truth), -1, 3), rotation, origin)


def _other_captures(args, database, chosen: dict[str, Any], rng: np.random.Generator) -> dict[str, Any]:
    from stylemotion.bones import median_bone_lengths
    from stylemotion.reconstruct import DEFAULT_MARKERS, SparseReconstructor, read_markers
    from stylemotion.reconstruct.benchmark import (
        bone_length_spread_cm,
        error_figures,
        joint_error_table,
        skin_marker_noise,
    )
    from stylemotion.reconstruct.marker_set import SKIN_MARKERS, virtual_markers
    from stylemotion.reconstruct.settings import JOINT_CENTRE_PRIOR_WEIGHT
    from stylemotion.reconstruct.sparse import subject_scale
    from stylemotion.reconstruct.subject import Subject, subject_from_motion
    from stylemotion.skeleton import CANONICAL_JOINTS, JOINT_INDEX

    def skin_reconstructor(bones=None, **settings) -> SparseReconstructor:
        return SparseReconstructor(database, SKIN_MARKERS, bones=bones, **{**chosen, **settings})

    joint_rec = SparseReconstructor(database, DEFAULT_MARKERS, hold_bones=False)  # the library's joint defaults
    skin_rec = skin_reconstructor()
    database_bones = median_bone_lengths(np.asarray(database.positions[:: max(1, database.num_frames // 50_000)],
                                                    np.float64))
    tables: dict[str, list[np.ndarray]] = {c: [] for c in CONDITIONS}
    bones: dict[str, list[dict]] = {"joints": [], "skin_subject": [], "skin_subject_unheld": [], "truth": []}
    files = []
    for name in OTHER_CAPTURES:
        truth = read_markers(DATA_ROOT / "other-skeletons" / name, list(CANONICAL_JOINTS), fps=database.fps).full
        joint_markers = skin_marker_noise(truth[:, [JOINT_INDEX[j] for j in DEFAULT_MARKERS]], rng,
                                          args.placement_mm, args.jitter_mm)
        skin = skin_marker_noise(virtual_markers(truth, SKIN_MARKERS), rng, args.placement_mm, args.jitter_mm)
        scale = subject_scale(skin, SKIN_MARKERS, database)
        calibration = subject_from_motion(truth)
        subject = skin_reconstructor(calibration)
        outputs = {"joints": joint_rec.reconstruct(joint_markers).positions,
                   "skin": skin_rec.reconstruct(skin).positions,
                   "skin_scaled": skin_reconstructor(database_bones * scale).reconstruct(skin).positions,
                   "skin_lengths": skin_reconstructor(median_bone_lengths(truth)).reconstruct(skin).positions,
                   "skin_subject": subject.reconstruct(skin).positions,
                   "skin_subject_no_feet": skin_reconstructor(Subject(calibration.lengths, calibration.rigid))
                   .reconstruct(skin).positions,
                   "skin_subject_defaults": SparseReconstructor(database, SKIN_MARKERS, bones=calibration,
                                                                prior_weight=JOINT_CENTRE_PRIOR_WEIGHT)
                   .reconstruct(skin).positions,
                   "skin_subject_nn": subject.nearest_neighbour(skin),
                   "floor_subject": _floor(subject, skin, truth)}
        subject.hold_bones = False
        outputs["skin_subject_unheld"] = subject.reconstruct(skin).positions
        for condition, positions in outputs.items():
            tables[condition].append(joint_error_table(positions, truth))
        for key in ("joints", "skin_subject", "skin_subject_unheld"):
            bones[key].append(bone_length_spread_cm(outputs[key]))
        bones["truth"].append(bone_length_spread_cm(truth))
        files.append({"file": name, "frames": int(len(truth)), "scale": round(scale, 4),
                      **{f"{c}_mean_cm": float(tables[c][-1].mean()) for c in CONDITIONS}})
    return {"figures": {c: error_figures(t) for c, t in tables.items()},
            "bone_spread": {key: {m: float(np.mean([v[m] for v in values])) for m in values[0]}
                            for key, values in bones.items()},
            "files": files}


def _leave_actor_out(args, bandai, parts, rng, actor: list[str], everyone) -> dict[str, Any]:
    """The Bandai arm: the styles of one actor group (``actor``) out of the database, chosen on their val takes and
    reported on their test takes; beside it the same queries against ``everyone`` (the seed's whole train database)."""
    from stylemotion.reconstruct import SparseReconstructor
    from stylemotion.reconstruct.benchmark import (
        bone_length_spread_cm,
        choose_queries,
        choose_setting,
        database_of,
        error_figures,
        joint_error_table,
        skin_marker_noise,
    )
    from stylemotion.reconstruct.marker_set import SKIN_MARKERS, virtual_markers

    database = database_of(f"bandai-train-without-{'+'.join(actor)}",
                           [t for t in parts["train"] if t.style not in actor], bandai.fps)
    queries = {part: choose_queries([t for t in parts[part] if t.style in actor], args.contents, 1, rng)
               for part in ("val", "test")}
    markers = {part: [skin_marker_noise(virtual_markers(q.positions, SKIN_MARKERS), rng, args.placement_mm,
                                        args.jitter_mm) for q in qs] for part, qs in queries.items()}
    candidates = []
    for features in args.features:
        rec = SparseReconstructor(database, SKIN_MARKERS, features=features, k=max(args.k))
        for k in args.k:
            for prior_weight in args.prior_weights:
                rec.k, rec.prior_weight = k, prior_weight
                score = error_figures([joint_error_table(rec.reconstruct(m).positions, q.positions)
                                       for q, m in zip(queries["val"], markers["val"])])["mean_cm"]
                candidates.append({"features": features, "k": k, "prior_weight": prior_weight, "val_mean_cm": score})
    best = candidates[choose_setting({i: c["val_mean_cm"] for i, c in enumerate(candidates)})]
    chosen = {key: best[key] for key in ("features", "k", "prior_weight")}
    rec = SparseReconstructor(database, SKIN_MARKERS, **chosen)
    with_actor = SparseReconstructor(everyone, SKIN_MARKERS, **chosen)
    ours, nn, unheld, same, spread_held, spread_unheld = [], [], [], [], [], []
    for q, m in zip(queries["test"], markers["test"]):
        rec.hold_bones = True
        held = rec.reconstruct(m).positions
        ours.append(joint_error_table(held, q.positions))
        same.append(joint_error_table(with_actor.reconstruct(m).positions, q.positions))
        nn.append(joint_error_table(rec.nearest_neighbour(m), q.positions))
        rec.hold_bones = False
        free = rec.reconstruct(m).positions
        unheld.append(joint_error_table(free, q.positions))
        spread_held.append(bone_length_spread_cm(held)["mean_sd_cm"])
        spread_unheld.append(bone_length_spread_cm(free)["mean_sd_cm"])
    return {"actor_styles": actor, "val_takes": [q.name for q in queries["val"]],
            "test_takes": [q.name for q in queries["test"]], "database_frames": database.num_frames,
            "candidates": candidates, "chosen": chosen,
            "figures": {"ours": error_figures(ours), "nn": error_figures(nn), "unheld": error_figures(unheld),
                        "same_actor": error_figures(same)},
            "bone_sd_cm": {"held": float(np.mean(spread_held)), "unheld": float(np.mean(spread_unheld))}}


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    from stylemotion.datasets.actors import actor_groups
    from stylemotion.datasets.registry import load_dataset
    from stylemotion.reconstruct.benchmark import database_of

    bandai = load_dataset("bandai", root=str(DATA_ROOT / "bandai-namco-motion-2" / "data.zip"))
    groups = actor_groups(bandai.takes)
    actors = [groups.styles[g] for g in sorted(groups.styles)]
    per_seed, splits = [], []
    for seed in seeds:
        started = time.perf_counter()
        parts = bandai.split(seed, VAL_FRACTION, TEST_FRACTION, group_by=("content", "style"))
        splits.append(take_split_record(parts, seed, VAL_FRACTION, TEST_FRACTION))
        rng = np.random.default_rng(seed)
        everyone = database_of("bandai-train", parts["train"], bandai.fps)
        bandai_part = _leave_actor_out(args, bandai, parts, rng, actors[seed % len(actors)], everyone)
        other = _other_captures(args, everyone, bandai_part["chosen"], rng)
        per_seed.append({"seed": seed, "bandai": bandai_part, "other": other,
                         "seconds": round(time.perf_counter() - started, 1)})
        print(f"seed {seed}: actor of {'/'.join(bandai_part['actor_styles'])} chose {bandai_part['chosen']}: "
              f"{bandai_part['figures']['ours']['mean_cm']:.2f} cm; other captures "
              f"{other['figures']['skin_subject']['mean_cm']:.2f} cm", flush=True)
    return {"splits": {"kind": "by take, one split per seed; Bandai: one actor group left out of the database per "
                               "seed (seed mod the number of groups)",
                       "choose": "val (the left-out actor's val takes)", "report": "test", "per_seed": splits,
                       "actor_groups_in_bandai": actors,
                       "other_captures": "the three walks of other-skeletons, never in any split; virtual skin "
                                         "markers; database = the seed's train takes (all styles)"},
            "settings": {"contents": args.contents, "k_candidates": args.k, "feature_candidates": args.features,
                         "prior_weight_candidates": args.prior_weights, "placement_mm": args.placement_mm,
                         "jitter_mm": args.jitter_mm, "marker_set": "skin"},
            "choice": {"most_frequent": dict(Counter(tuple(sorted(r["bandai"]["chosen"].items())) for r in per_seed)
                                             .most_common(1)[0][0]),
                       "rule": "each seed chooses features, k and the prior weight together on the left-out actor's "
                               "val takes (lowest mean per-joint error, the first in grid order on a tie); the other "
                               "captures use the seed's choice"},
            "per_seed": per_seed}


# -- render -------------------------------------------------------------------------------------------------


def _values(r: dict, path: list[str]) -> list[Any]:
    out = []
    for seed in r["per_seed"]:
        node: Any = seed
        for key in path:
            node = node.get(key) if isinstance(node, dict) else None
        out.append(node)
    return out


def _cm(r: dict, path: list[str], digits: int = 2) -> str:
    return fmt_spread(spread(_values(r, path)), digits)


def _chosen_text(chosen: dict[str, Any]) -> str:
    return f"{chosen['features']}, k {chosen['k']}, prior weight {fmt(chosen['prior_weight'], 0)}"


def _validation_table(r: dict) -> str:
    first = r["per_seed"][0]["bandai"]["candidates"]
    rows = []
    for i, candidate in enumerate(first):
        scores = [seed["bandai"]["candidates"][i]["val_mean_cm"] for seed in r["per_seed"]]
        times = sum(seed["bandai"]["chosen"] == {k: candidate[k] for k in ("features", "k", "prior_weight")}
                    for seed in r["per_seed"])
        rows.append([candidate["features"], str(candidate["k"]), fmt(candidate["prior_weight"], 0),
                     fmt_spread(spread(scores), 2), f"{times} of {len(r['per_seed'])}"])
    return md_table(["features", "k", "prior weight", "val mean cm", "chosen by"], rows)


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    prov = provenance_line(record)
    rows = []
    for c in CONDITIONS:
        base = ["other", "figures", c]
        rows.append(["other captures (3 walks, other actors)", CONDITIONS[c], _cm(r, base + ["mean_cm"]),
                     _cm(r, base + ["p95_cm"]), _cm(r, base + ["max_cm"])])
    for key, text in (("ours", "skin markers, bones held (features, k and prior weight chosen on val)"),
                      ("unheld", "skin markers, bones not held"), ("nn", "nearest neighbour (k = 1)"),
                      ("same_actor", "the same queries with their actor in the database (easier): bones held, the "
                                     "seed's choice")):
        base = ["bandai", "figures", key]
        rows.append(["Bandai, one actor left out of the database", text, _cm(r, base + ["mean_cm"]),
                     _cm(r, base + ["p95_cm"]), _cm(r, base + ["max_cm"])])
    left = ", ".join("/".join(styles) for styles in _values(r, ["bandai", "actor_styles"]))
    headline = md_table(["queries", "method", "mean cm", "p95 cm", "max cm"], rows) + (
        f"\n\nPer-joint, per-frame errors; mean ± sd over {len(r['per_seed'])} seeds. Markers: the default skin set "
        f"(wrists' lateral side 3 cm, lateral malleoli 4 cm, top of head 8 cm, sacrum 8 cm off the joints), put "
        f"**virtually** on the recordings (no real C3D capture is in the shared data), placement ± "
        f"{fmt(r['settings']['placement_mm'], 0)} mm per axis per recording, jitter ± "
        f"{fmt(r['settings']['jitter_mm'], 0)} mm per frame. Other captures: {', '.join(OTHER_CAPTURES)}; truth = "
        f"their own skeleton's joints; database = the seed's Bandai train takes. Bandai: actor_groups finds "
        f"{len(r['splits']['actor_groups_in_bandai'])} actors (by their files' rest poses); per seed one actor's "
        f"takes are left out of the database ({left}; 1 test take of each of "
        f"{', '.join(r['settings']['contents'])}, drawn in turn from its styles). Per seed the feature set, k and the "
        f"local "
        f"model's prior weight are chosen together on the left-out actor's val takes (below), and the other captures "
        f"use the seed's choice: {'; '.join(_chosen_text(c) for c in _values(r, ['bandai', 'chosen']))}. {prov}"
        "\n\nThe choice: mean per-joint error (cm) on the val takes of the left-out actor, mean ± sd over seeds.\n\n"
        + _validation_table(r))
    from stylemotion.skeleton import CANONICAL_JOINTS

    joint_rows = []
    for j in CANONICAL_JOINTS:
        cells = [j]
        for c in ("joints", "skin_subject_unheld", "skin_subject", "skin_subject_nn", "floor_subject"):
            cells.append(_cm(r, ["other", "figures", c, "per_joint", j, "mean_cm"], 1))
        joint_rows.append(cells)
    spreads = []
    for key, text in (("truth", "the recordings' own joints"), ("joints", "the method before (joint centres)"),
                      ("skin_subject_unheld", "skin, subject's skeleton, bones not held"),
                      ("skin_subject", "skin, subject's skeleton, bones held")):
        spreads.append([text, _cm(r, ["other", "bone_spread", key, "mean_sd_cm"], 2),
                        _cm(r, ["other", "bone_spread", key, "max_range_cm"], 1)])
    spreads.append(["Bandai left-out actor: bones not held", _cm(r, ["bandai", "bone_sd_cm", "unheld"], 2), ""])
    spreads.append(["Bandai left-out actor: bones held", _cm(r, ["bandai", "bone_sd_cm", "held"], 2), ""])
    diagnosis = (md_table(["joint", "method before (joint centres)", "skin, subject's skeleton, bones not held",
                           "the same, bones held", "nearest neighbour", "floor (best database pose)"], joint_rows)
                 + "\n\nOther captures, mean cm per joint (± sd over seeds).\n\n"
                 + md_table(["output", "bone length sd over frames, cm (mean over bones)",
                             "largest change of a bone, cm"], spreads) + f"\n\n{prov}")
    figures = {c: _cm(r, ["other", "figures", c, "mean_cm"]) for c in CONDITIONS}
    ours = ["other", "figures", "skin_subject"]
    mean = spread(_values(r, ours + ["mean_cm"])).get("mean")
    aim = "met" if mean is not None and mean <= 3.0 else "not met"
    summary = (f"Krüger §2.5.2 with six skin markers (virtual, on 3 walks of actors not in the database; "
               f"[benchmarks/reconstruct.md](benchmarks/reconstruct.md)): mean per-joint error "
               f"**{figures['skin_subject']} cm** with the subject's skeleton given and the settings chosen on val "
               f"(p95 {_cm(r, ours + ['p95_cm'])}, max {_cm(r, ours + ['max_cm'])} cm; "
               f"{figures['skin_subject_defaults']} cm with the settings before), {figures['skin']} cm on the "
               f"database's skeleton, against "
               f"{figures['joints']} cm for the method before (markers at the joint centres); the aim of ≤ 3 cm is "
               f"{aim}. Bandai with one actor left out of the database: "
               f"{_cm(r, ['bandai', 'figures', 'ours', 'mean_cm'])} cm "
               f"({_cm(r, ['bandai', 'figures', 'same_actor', 'mean_cm'])} cm with the actor in it). "
               f"Bones held: length sd over frames "
               f"{_cm(r, ['other', 'bone_spread', 'skin_subject', 'mean_sd_cm'])} cm per bone (the method before: "
               f"{_cm(r, ['other', 'bone_spread', 'joints', 'mean_sd_cm'])} cm). {prov}")
    return {"headline": headline, "diagnosis": diagnosis, "summary": summary}
