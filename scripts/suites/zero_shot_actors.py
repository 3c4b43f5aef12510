"""Suite ``zero_shot_actors``: stylemotion-style's default for a new style (the zero-shot network) on a style **and
an actor** it never saw, judged on test clips only (issue 27 item 3: leave-one-style-out across Bandai's actor
groups).

    python scripts/benchmarks.py run zero_shot_actors --seeds 100 101 102 --judge-seeds 0 1 2

In Bandai dataset-2 each actor performed whole styles: the takes' skeletons have equal bone lengths, but the rest
offset of the root's child (``Hips``) is one per actor, and it groups the styles (:func:`actor_groups`, read from
the BVH files of the judge's data here, not typed in). Suite ``zero_shot_test`` leaves one style out, so the
autoencoder and the network still saw the other styles of its actor. Here every style of the actor is left out
together (:func:`stylemotion.evaluation.zero_shot.leave_one_style_out` with ``groups``): per training seed and actor
group one autoencoder without any take of the group and, per primitive, one network without any clip of it, each
conditioned in turn on each style's example. A group holding the neutral style cannot be left out (every network
needs it); its other styles are left out alone and labelled so (same actor in the training data).

Everything else is suite ``zero_shot_test``'s: the same judges and their test reports (each left-out style's test
clips only), the network's epochs, sampling and foot-contact weight as ``stylemotion-style`` uses them today, seeds
paired with judges. The CVAE on the autoencoder without the group is not trained (``--cvae`` trains it: ~1.5 min
per style and primitive); the judge's CVAE (its autoencoder saw the style and its actor) stands beside as a
reference. Nothing is chosen here.
"""

from __future__ import annotations

import argparse
from typing import Any

from suites import contact_full, style_method, zero_shot, zero_shot_test
from suites.common import md_table, provenance_line, spread

DESCRIPTION = ("stylemotion-style's default (the zero-shot network) on a style and an actor it never saw: each "
               "Bandai actor's styles left out together, judged on test clips only")
DEFAULT_SEEDS = zero_shot_test.DEFAULT_SEEDS
#: The folder tag of this protocol's evaluations (``seed<k>_e<epochs>…_test_actors/``).
OUT_TAG = "_actors"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    zero_shot_test.add_arguments(parser)
    parser.add_argument("--cvae", action="store_true",
                        help="also train the CVAE of each style on the autoencoder without its actor's styles")


def actor_groups(data_cfg: dict[str, Any], styles: list[str], contents: tuple[str, ...] = ("walk",)
                 ) -> dict[str, list[str]]:
    """Style → the styles of its actor: styles whose takes (of ``contents``) share one skeleton rest pose (every
    joint's rest offset, file units, to 1e-3: :func:`stylemotion.datasets.actors.bvh_rest_pose`, the rest pose
    :func:`~stylemotion.datasets.actors.actor_groups` splits by), read from the BVH files' hierarchies in
    ``data_cfg["root"]`` (Bandai's zip).

    Raises:
        SystemExit: a style whose takes have several rest poses (no actor per style), or none found.
    """
    from stylemotion.datasets.actors import bvh_rest_pose
    from stylemotion.io.sources import list_sources

    poses: dict[str, set[tuple[float, ...]]] = {s: set() for s in styles}
    for source in list_sources(data_cfg["root"], "*.bvh"):
        parts = source.stem.split("_")
        if len(parts) >= 3 and parts[1] in contents and parts[2] in poses:
            poses[parts[2]].add(bvh_rest_pose(source))
    bad = {s: len(p) for s, p in poses.items() if len(p) != 1}
    if bad:
        raise SystemExit(f"zero_shot_actors: styles without exactly one rest pose in {data_cfg['root']}: {bad}")
    by_pose: dict[tuple[float, ...], list[str]] = {}
    for s, p in poses.items():
        by_pose.setdefault(next(iter(p)), []).append(s)
    return {s: sorted(group) for group in by_pose.values() for s in group}


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    from concurrent.futures import ProcessPoolExecutor
    from multiprocessing import get_context

    from stylemotion.evaluation.zero_shot import read_run

    by_seed = zero_shot_test.judges(args, seeds)
    source = read_run(next(iter(by_seed.values())), style_method.JUDGE_REPORTS["test"][0])
    neutral = source.settings.neutral_style
    styles = sorted({s for p in source.primitives for s in source.styles(p)})
    actors = actor_groups(source.data_cfg, sorted({*styles, neutral}))
    groups = {s: (actors[s] if neutral not in actors[s] else [s]) for s in (args.styles or styles)}
    seed_args = zero_shot_test.seed_options(args)
    seed_args.groups, seed_args.cvae_unseen, seed_args.out_tag = groups, bool(args.cvae), OUT_TAG
    processes = max(1, min(args.workers, len(seeds)))
    with ProcessPoolExecutor(max_workers=processes, mp_context=get_context("spawn")) as pool:
        futures = {seed: pool.submit(style_method.seed_record, seed_args, seed, by_seed[seed]) for seed in seeds}
        per_seed: dict[str, Any] = {str(seed): future.result() for seed, future in futures.items()}
    return {"data": args.data, "epochs": seed_args.epochs, "sampling": zero_shot_test.sampling(),
            "contact_weight": zero_shot_test.contact_weight(), "samples": args.samples,
            "narrowed": {"primitives": args.primitives, "styles": args.styles},
            "actors": actors, "groups": groups, "cross_actor": {s: len(g) > 1 or actors[s] == [s]
                                                                for s, g in groups.items()},
            "judges": {str(seed): zero_shot.relative(judge) for seed, judge in by_seed.items()},
            "splits": {"report": "the judges' report_test: each left-out style's test clips but its example",
                       "left_out": "every take of the style's actor group (every split), from the autoencoder and "
                                   "the network; a group holding the neutral style: the style alone",
                       "seeds": "training seeds, each paired with its judge"},
            "per_seed": per_seed, "summary": style_method.method_summaries(per_seed),
            "aims": zero_shot_test.aims(per_seed)}


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    sd = contact_full.sd
    label = zero_shot_test.block_label(r)
    cases = zero_shot_test.per_style(r["per_seed"])
    rows = []
    for style, group in cases.items():
        kinds = [k for k in ("zero_shot", "cvae_unseen", "cvae") if all(k in c for c in group)]
        cross = "yes" if r["cross_actor"][style] else "**no**: its actor's other style is the neutral one"
        rows.append([style, ", ".join(r["groups"][style]), cross, *(
            cell for kind in kinds for cell in (
                sd(spread(c[kind]["recognition"] for c in group), 3),
                f"{sum(c[kind]['own_column'] for c in group)}/{len(group)}",
                sd(spread(c[kind]["diversity"] for c in group)),
                sd(spread(c[kind].get("skating_vs_real") for c in group), 1)))])
    kinds = [k for k in ("zero_shot", "cvae_unseen", "cvae") if k in r["summary"]]
    names = {"zero_shot": "zero-shot", "cvae_unseen": "CVAE, AE without the actor", "cvae": "judge's CVAE"}
    header = ["left-out style", "left out with it", "actor unseen",
              *(h for k in kinds for h in (f"{names[k]}: recognition", "own column", "diversity / style",
                                           "skating × real"))]
    z, a = r["summary"]["zero_shot"], r["aims"]["zero_shot"]
    headline = (
        f"{label}A style **and its actor** never seen, judged on **test** clips only ({r['data']}, training seeds "
        f"{', '.join(r['per_seed'])}; {zero_shot_test.network_line(r)}): per training seed and Bandai actor group "
        f"(styles sharing one skeleton rest pose in the BVH files: "
        f"{'; '.join(sorted({', '.join(g) for g in r['actors'].values()}))}) one autoencoder without any take of the "
        f"group and one zero-shot network per primitive without any clip of it, conditioned on each style's "
        f"example; judges and figures as suite zero_shot_test's ({zero_shot_test.judges_line(r)}). Over every "
        f"(seed, primitive, style): the zero-shot network's recognition {sd(z['recognition'], 3)}, own column "
        f"{z['own_column']}/{z['cases']}, styles recognized ≥ {zero_shot_test.AIM_RECOGNITION:g}: "
        f"{a['recognition_styles']}/{a['styles']} (least: {a['worst_style']}), diversity / style "
        f"{sd(z['diversity'])}, raw skating × real {sd(z.get('skating_vs_real', {}), 1)}. Mean ± sd (min–max) over "
        f"seeds and primitives per style:\n\n" + md_table(header, rows) + f"\n\n{provenance_line(record)}")
    return {"headline": headline}
