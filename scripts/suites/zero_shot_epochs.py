"""Suite ``zero_shot_epochs``: the training epochs of the zero-shot network (``experiment=zero_shot``'s
``trainer.max_epochs``), chosen on **validation** clips, and with them stylemotion-style's ``method`` (issue 27
item 3).

    python scripts/benchmarks.py run zero_shot_epochs --seeds 100 101 --epochs 10 30 100

Suite ``style_method`` at the experiment's 100 epochs kept ``cvae``: the zero-shot network lost recognition of
unseen styles (exhausted 0.40–0.73), while a narrowed 10-epoch run had kept it. Each arm here is suite
``style_method``'s leave-one-style-out (:func:`suites.style_method.seed_record`: per training seed, per left-out
style an autoencoder without it; per primitive the zero-shot network and the CVAE on that autoencoder; judged by the
seed's reproduction evaluated with ``evaluation.heldout_splits=[val]``) with the networks trained for one epoch count.
The autoencoders and the CVAEs are shared by every arm (``seed<k>/``; the networks of an arm in ``seed<k>_e<n>/``,
the experiment's own count in ``seed<k>/``), so arms differ only in the networks' epochs.

Rule (:func:`choose_epochs`, fixed before any run): an arm **qualifies** when its zero-shot network passes
``style_method``'s own-column and recognition tests against the CVAE; the chosen count is the qualifying arm with the
highest mean capped log variation (arms within ``style_method.TIE`` of it: the fewest epochs). When none qualifies:
the arm with the most own-column rows, then the highest mean recognition (within :data:`RECOGNITION_TIE`: the fewest
epochs). ``style_method``'s rule applied to the chosen arm gives the ``method`` verdict.
"""

from __future__ import annotations

import argparse
import copy
from pathlib import Path
from typing import Any

from suites import contact_full, style_method
from suites.common import fmt, md_table, number_above, provenance_line, spread

DESCRIPTION = ("the zero-shot network's training epochs (experiment=zero_shot trainer.max_epochs) and with them "
               "stylemotion-style's method, chosen on validation clips")
DEFAULT_SEEDS = style_method.DEFAULT_SEEDS
ROOT = style_method.ROOT
DEFAULT_ARMS = (10, 30, 100)
#: Mean recognitions this close count as tied (fallback of the rule).
RECOGNITION_TIE = 0.01


def add_arguments(parser: argparse.ArgumentParser) -> None:
    style_method.leave_one_out_arguments(parser)
    parser.add_argument("--epochs", type=number_above(1), nargs="+", default=list(DEFAULT_ARMS),
                        help="epoch counts of the zero-shot networks, one arm each")


def network_minutes(out: str, cases: dict[str, Any]) -> list[float]:
    """Training minutes of each network of one seed's arm, read from its ``done.json`` (also when reused)."""
    from stylemotion.evaluation.zero_shot import model_folder
    from stylemotion.io.jsonfile import read_json_object

    minutes = []
    for key in cases:
        primitive, style = key.split("/", 1)
        done = model_folder(Path(out), primitive, style) / "done.json"
        record = read_json_object(done, "a network's record", "run the suite again")
        minutes.append(round(float(record["seconds"]) / 60, 2))
    return minutes


def arm_summary(per_seed: dict[str, Any]) -> dict[str, Any]:
    """Over every (seed, primitive, style) case of one arm: each method's summary and the networks' minutes."""
    summaries = style_method.method_summaries(per_seed)
    minutes = [m for s in per_seed.values() for m in network_minutes(s.get("networks", s["out"]), s["cases"])]
    return {"summary": summaries, "network_minutes": spread(minutes), "choice": style_method.choose(summaries)}


def choose_epochs(arms: dict[str, dict[str, Any]]) -> dict[str, Any]:
    """The module doc's rule over ``{epochs: arm_summary}``."""
    def qualifies(arm: dict[str, Any]) -> bool:
        return arm["choice"]["tests"]["own_column"] and arm["choice"]["tests"]["recognition"]

    def zero_shot(epochs: str) -> dict[str, Any]:
        return arms[epochs]["summary"]["zero_shot"]

    qualifying = [e for e in arms if qualifies(arms[e])]
    if qualifying:
        best = max(zero_shot(e)["capped_log_variation"] for e in qualifying)
        near = [e for e in qualifying if zero_shot(e)["capped_log_variation"] >= best - style_method.TIE]
        how = "qualifying arm with the most variation"
    else:
        rows = max(zero_shot(e)["own_column"] for e in arms)
        most = [e for e in arms if zero_shot(e)["own_column"] == rows]
        best = max(zero_shot(e)["recognition"]["mean"] for e in most)
        near = [e for e in most if zero_shot(e)["recognition"]["mean"] >= best - RECOGNITION_TIE]
        how = "no arm qualifies: most own-column rows, then the highest recognition"
    epochs = min(near, key=int)
    return {"qualifying": qualifying, "how": how, "epochs": int(epochs), "method": arms[epochs]["choice"]["default"]}


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    from concurrent.futures import ProcessPoolExecutor
    from multiprocessing import get_context

    default = style_method.experiment_epochs()
    judges = {seed: style_method.judge_for(args, seed) for seed in seeds}
    # The experiment's own count first: it trains the shared autoencoders and CVAEs when they are missing.
    counts = sorted(set(args.epochs), key=lambda e: (e != default, e))
    arms: dict[str, dict[str, Any]] = {}
    per_arm: dict[str, dict[str, Any]] = {}
    processes = max(1, min(args.workers, len(seeds)))
    for epochs in counts:
        arm_args = copy.copy(args)
        arm_args.epochs = None if epochs == default else epochs
        with ProcessPoolExecutor(max_workers=processes, mp_context=get_context("spawn")) as pool:
            futures = {seed: pool.submit(style_method.seed_record, arm_args, seed, judge)
                       for seed, judge in judges.items()}
            per_arm[str(epochs)] = {str(seed): future.result() for seed, future in futures.items()}
        arms[str(epochs)] = arm_summary(per_arm[str(epochs)])
    return {"experiment_epochs": default, **arms_record(args, per_arm, arms), "choice": choose_epochs(arms)}


def arms_record(args: argparse.Namespace, per_arm: dict[str, Any], arms: dict[str, Any]) -> dict[str, Any]:
    """What every arm suite on style_method's leave-one-style-out records beside its arms and its choice."""
    first = next(iter(arms.values()))["summary"]["cvae_unseen"]
    return {"data": args.data, "samples": args.samples,
            "narrowed": {"primitives": args.primitives, "styles": args.styles},
            "splits": {"choose": "the judges' evaluation.heldout_splits=[val]: real clips of the train and val "
                                 "splits; no test clip", "seeds": "training seeds, not reported seeds"},
            "per_arm": per_arm, "arms": arms,
            "cvae_unseen_same_in_every_arm": all(a["summary"]["cvae_unseen"] == first for a in arms.values())}


def run_arms(args: argparse.Namespace, judges: dict[int, Any], options: dict[str, argparse.Namespace]
             ) -> tuple[dict[str, dict[str, Any]], dict[str, dict[str, Any]]]:
    """Each arm's ``style_method.seed_record`` per seed (``options``: arm → its options, in the order run; seeds in
    parallel, ``--workers`` processes of one thread), and each arm's :func:`arm_summary`."""
    from concurrent.futures import ProcessPoolExecutor
    from multiprocessing import get_context

    per_arm: dict[str, dict[str, Any]] = {}
    processes = max(1, min(args.workers, len(judges)))
    for key, arm_options in options.items():
        with ProcessPoolExecutor(max_workers=processes, mp_context=get_context("spawn")) as pool:
            futures = {seed: pool.submit(style_method.seed_record, arm_options, seed, judge)
                       for seed, judge in judges.items()}
            per_arm[key] = {str(seed): future.result() for seed, future in futures.items()}
    return per_arm, {key: arm_summary(per_seed) for key, per_seed in per_arm.items()}


def zero_shot_by_style(r: dict[str, Any]) -> dict[str, dict[str, list[dict[str, Any]]]]:
    """Left-out style → arm → the zero-shot network's cases of every seed and primitive (``r["per_arm"]``)."""
    styles: dict[str, dict[str, list[dict[str, Any]]]] = {}
    for arm, per_seed in r["per_arm"].items():
        for seed in per_seed.values():
            for key, case in seed["cases"].items():
                styles.setdefault(key.split("/", 1)[1], {}).setdefault(arm, []).append(case["zero_shot"])
    return styles


def arms_frame(r: dict[str, Any]) -> tuple[str, list[str], bool, str]:
    """The label of an arm suite's blocks (synthetic, narrowed), its training seeds, whether it is full (not
    narrowed, two seeds or more: its verdict applies) and what it says of the CVAE rows across arms."""
    label = "**Synthetic data: a smoke run of the suite, not evidence.** " if r["data"] == "synthetic" else ""
    narrowed = {k: v for k, v in r["narrowed"].items() if v}
    seeds = sorted({s for arm in r["per_arm"].values() for s in arm})
    if narrowed:
        label += "**Narrowed:** " + "; ".join(f"{k} {', '.join(v)}" for k, v in narrowed.items()) + ". "
    same = ("the CVAE rows are the same in every arm (shared trainings)" if r["cvae_unseen_same_in_every_arm"]
            else "**the CVAE rows differ between arms**")
    return label, seeds, not narrowed and len(seeds) >= 2, same


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    choice, sd = r["choice"], contact_full.sd
    label, seeds, full, same = arms_frame(r)
    rows = []
    for epochs, arm in sorted(r["arms"].items(), key=lambda item: int(item[0])):
        s = arm["summary"]["zero_shot"]
        tests = arm["choice"]["tests"]
        rows.append([f"zero-shot, {epochs} epochs", f"{s['own_column']}/{s['cases']}", sd(s["recognition"], 3),
                     *(sd(s[k]) for k in style_method.VARIATION), fmt(s["capped_log_variation"], 3),
                     sd(arm["network_minutes"], 1),
                     "yes" if tests["own_column"] and tests["recognition"] else "no"])
    cv = next(iter(r["arms"].values()))["summary"]["cvae_unseen"]
    rows.append([style_method.LABELS["cvae_unseen"], f"{cv['own_column']}/{cv['cases']}", sd(cv["recognition"], 3),
                 *(sd(cv[k]) for k in style_method.VARIATION), fmt(cv["capped_log_variation"], 3), "", ""])
    method = "zero_shot" if choice["method"] == "zero_shot" else "cvae"
    verdict = (f"experiment=zero_shot trains **{choice['epochs']} epochs** ({choice['how']}; the experiment had "
               f"{r['experiment_epochs']}), and at that count style_method's rule gives **method={method}**")
    if not full:
        verdict = f"{choice['epochs']} epochs and method={method} by the rule, **not applied**: a narrowed run"
    headline = (
        f"{label}The zero-shot network's epochs, on **validation** clips ({r['data']}, training seeds "
        f"{', '.join(seeds)}: not reported seeds): suite style_method's leave-one-style-out per arm, the autoencoders "
        f"without each style and the CVAEs on them shared by every arm; {same}. Figures as in style_method's block; "
        f"minutes: training of one network (one torch thread, two seeds at once). An arm qualifies when its own "
        f"column and recognition pass style_method's tests. Verdict: {verdict}.\n\n"
        + md_table(["model", "own column", "recognition", "V_SD / style", "step_SD / style", "diversity / style",
                    "mean capped log variation", "minutes / network", "qualifies"], rows)
        + f"\n\n{provenance_line(record)}")
    return {"headline": headline, "styles": f"{render_styles(r)}\n\n{provenance_line(record)}"}


def render_styles(r: dict[str, Any]) -> str:
    """Per left-out style, the zero-shot network's recognition and own-column rows in each arm."""
    styles: dict[str, dict[str, list[dict[str, Any]]]] = {}
    for epochs, per_seed in r["per_arm"].items():
        for seed in per_seed.values():
            for key, case in seed["cases"].items():
                styles.setdefault(key.split("/", 1)[1], {}).setdefault(epochs, []).append(case["zero_shot"])
    arms = sorted(r["per_arm"], key=int)
    rows = [[style, *(cell for e in arms for cell in (
        contact_full.sd(spread(c["recognition"] for c in by_arm.get(e, [])), 3),
        f"{sum(c['own_column'] for c in by_arm.get(e, []))}/{len(by_arm.get(e, []))}"))]
        for style, by_arm in styles.items()]
    header = [h for e in arms for h in (f"{e} epochs: recognition", "own column")]
    return ("The zero-shot network per left-out style, mean ± sd (min–max) over training seeds and primitives "
            "(same runs as above).\n\n" + md_table(["style", *header], rows))
