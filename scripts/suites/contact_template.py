"""Suite ``contact_template``: where the style CVAE's draws' contact term holds their feet, chosen on **validation**
clips of every Bandai style at the reproduction's full budget (issue 27 item 1: styled samples whose stance foot
never plants).

    python scripts/benchmarks.py run contact_template --seeds 100 101

Why: in suite ``style_bandai``'s runs up to 0.68 of a CVAE's samples never plant the stance foot. A scratch look
at seed 0's masculine CVAE (not a figure of this suite) found the pose-only style term widening the leg sweep while
the root kept a neutral speed: the stance foot walks backwards under the body, too fast for the detector to call it
planted, so the draws' own-contact term (``model.sample_contacts=own``, suite ``contact_draws``) never sees it, and
the per-frame slower-point speed lets heel and ball take turns to stay still. ``model.sample_contacts=content`` holds
the draws' feet on the primitive's contact template from the content clips and, over the middle half of each
template contact run, holds heel and ball both (stylemotion/models/cvae.py).

Arms per training seed (not reported seeds), each the user's ``stylemotion-reproduce data=bandai`` (both walk
stances, every style) with ``evaluation.heldout_splits=[val]`` (no test clip in the figures the rule reads), sharing
the first arm's autoencoder and neutral VAE stages (copied; the reproduction checks their settings hash):

* ``off``: the configs' defaults (β = ``model.sample_contact_weight`` 0);
* ``own<β>``: β on the draws' own contacts (suite ``contact_draws``' arm, again beside the new one);
* ``content<β>``: β on the content template with the mid-stance term.

Rule (:func:`choose`, fixed before the run), over every (seed, stance, style) case: an arm is eligible when its
Table 5.1 rows on the diagonal are no fewer than ``off``'s, its mean recognition is at least min(0.9, ``off``'s) and
its mean capped log variation (V_SD, step_SD, diversity over the style's real clips) is no lower than ``off``'s
minus :data:`suites.style_channels.TIE` (suite ``contact_draws``' rule). The figure ruled on is the mean over cases
of the stance foot's mid-stance speed of the samples minus that of the style's real clips (m/s; every sample counts,
also one that never plants, which the skating share leaves out; a difference, not a ratio: real stance feet are
still to within 0.01–0.05 m/s, so a ratio would be ruled by the cases with the stillest real clips). Starting from
``off``, each eligible arm in turn (``own``, then ``content``) replaces the holder when its figure is more than
:data:`TIE` (5 %) below the holder's. The skating share (samples ÷ real) and the share of samples never planted are
shown beside.

Second look (:func:`choose_sliding_free`, written on 2026-12-07 after the rule above kept ``off`` on content100's
variation alone, before any of its figures were computed): V_SD and step_SD read the root, and a stance foot that
slides lets the root's pace vary without the legs (suite ``contact_template``'s stance block: ``off``'s roots travel
0.35–1.10 of the leg's sweep), so an arm whose samples slide may show variation that is not in their steps. The
stance block's samples give, over the middle half of each motion, the spread over motions of the root's travel and
speed and of the leg's (the root relative to the stance foot: what the root would travel were the foot planted;
:mod:`stylemotion.primitives.stance`), each as samples ÷ the style's real clips. The second look keeps the rule
above but for its variation test, which reads the sliding-free shares instead: leg travel SD, leg speed SD and the
case's diversity (mean capped log over cases no lower than ``off``'s minus the same tie). Root and leg shares are
shown side by side, so the block also says how much of each arm's step variation is sliding.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from suites import contact_draws, contact_full, style, style_channels
from suites.common import fmt, md_table, mean_capped_log, provenance_line, spread

DESCRIPTION = ("where the style CVAE's draws' contact term holds their feet (their own contacts or the content "
               "clips' template), chosen at full budget on Bandai validation clips of every style")
DEFAULT_SEEDS = (100, 101)
DEFAULT_WEIGHT = 100.0
#: relative difference of the ruled mid-stance ratio under which two arms tie
TIE = 0.05


def add_arguments(parser: argparse.ArgumentParser) -> None:
    style_channels.run_arguments(parser, "folder of the arms' reproduction runs (reused and resumed)")
    parser.set_defaults(runs=style.ROOT / "runs" / "benchmarks" / "contact_template")
    parser.add_argument("--weight", type=float, default=DEFAULT_WEIGHT, metavar="BETA",
                        help="β of the own and content arms (model.sample_contact_weight)")
    parser.add_argument("--stance-samples", type=int, default=300, metavar="N",
                        help="samples per model of the stance block (0: no stance block)")
    parser.add_argument("--arms", nargs="+", choices=("off", "own", "content"), default=["off", "own", "content"],
                        help="arms to run; off is always first (the rule's reference)")


def arms(beta: float, kinds: list[str]) -> dict[str, list[str]]:
    """Arm name (``off``, ``own<β>``, ``content<β>``) → the CVAE stages' ``train`` overrides, ``off`` first."""
    b = f"{beta:g}"
    out: dict[str, list[str]] = {"off": []}
    for kind in ("own", "content"):
        if kind in kinds:
            out[f"{kind}{b}"] = [f"model.sample_contact_weight={b}", f"model.sample_contacts={kind}"]
    return out


def case_stance(report: dict[str, Any], styles: list[str]) -> dict[str, dict[str, Any]]:
    """Per ``<primitive>/<style>``: the stance foot's never-planted share and mid-stance speed of the samples and of
    the style's real clips (the report's ``foot_skating_detail``)."""
    out = {}
    for primitive, models in report.get("foot_skating_detail", {}).items():
        for s in styles:
            d = models.get(s) or {}
            sam, real = d.get("samples", {}), d.get("real", {})
            out[f"{primitive}/{s}"] = {"no_plant_samples": sam.get("no_plant_share"),
                                       "no_plant_real": real.get("no_plant_share"),
                                       "mid_mps_samples": sam.get("planted_mid_mps"),
                                       "mid_mps_real": real.get("planted_mid_mps")}
    return out


def arm_summary(runs: list[dict[str, Any]]) -> dict[str, Any]:
    """Over every (seed, stance, style) case of one arm: suite style_channels' figures, skating ÷ real, never-planted
    shares and the mid-stance speed ÷ real."""
    cases = [c for run in runs for c in run["cases"].values()]
    stance = [c for run in runs for c in run["stance"].values()]
    return {"styled": style_channels.candidate_summary(cases),
            "styled_skating_relative": spread(contact_full.relative(c["skating_samples"], c["skating_real"])
                                              for c in cases),
            "no_plant_samples": spread(c["no_plant_samples"] for c in stance),
            "no_plant_real": spread(c["no_plant_real"] for c in stance),
            "mid_mps_samples": spread(c["mid_mps_samples"] for c in stance),
            "mid_mps_real": spread(c["mid_mps_real"] for c in stance),
            "mid_excess": spread(None if c["mid_mps_samples"] is None or c["mid_mps_real"] is None
                                 else c["mid_mps_samples"] - c["mid_mps_real"] for c in stance),
            "cvae_minutes": sum(run["cvae_minutes"] for run in runs) / len(runs) if runs else None}


def choose(summaries: dict[str, dict[str, Any]]) -> dict[str, Any]:
    """The module doc's rule; the first key is ``off``."""
    eligible, floor, variation_floor = contact_draws.eligibility(summaries)
    return {"eligible": eligible, "recognition_floor": floor, "variation_floor": variation_floor,
            "chosen": slowest_eligible(summaries, eligible)}


def slowest_eligible(summaries: dict[str, dict[str, Any]], eligible: dict[str, bool]) -> str:
    """Starting from the first arm, each eligible arm in turn replaces the holder when its mean mid-stance speed over
    real is more than :data:`TIE` below the holder's."""
    names = list(summaries)

    def mid(n: str) -> float:
        mean = summaries[n]["mid_excess"].get("mean")
        return float("inf") if mean is None else float(mean)

    chosen = names[0]
    for n in names[1:]:  # in order: own before content; a later arm must beat the holder by more than TIE
        if eligible[n] and mid(n) < mid(chosen) * (1 - TIE):
            chosen = n
    return chosen


#: The stance block's spreads over motions, shown as samples ÷ the style's real clips (key, header).
SPREADS = (("root_travel_sd_m", "root travel SD"), ("leg_travel_sd_m", "leg travel SD"),
           ("root_speed_sd_mps", "root speed SD"), ("leg_speed_sd_mps", "leg speed SD"))
#: The sliding-free variation shares the second look reads.
SLIDING_FREE = ("leg_travel_sd_m", "leg_speed_sd_mps", "diversity")


def spread_cases(per_seed: dict[str, dict[str, Any]], stance_real: dict[str, dict[str, Any]]
                 ) -> dict[str, list[dict[str, float | None]]]:
    """Per arm, per styled (seed, primitive, style) case: the stance spreads of its samples ÷ those of the style's
    real clips (None where either is missing or the real one is 0) and the case's diversity share."""
    out: dict[str, list[dict[str, float | None]]] = {}
    for seed, arms_ in per_seed.items():
        real = stance_real.get(seed, {})
        for arm, record in arms_.items():
            cases = out.setdefault(arm, [])
            for key, figures in record.get("stance_travel", {}).items():
                if key.endswith("/neutral"):
                    continue
                ref = real.get(key, {})
                case: dict[str, float | None] = {
                    k: figures[k] / ref[k] if figures.get(k) is not None and ref.get(k) else None for k, _ in SPREADS}
                case["diversity"] = record["cases"][key]["diversity"]
                cases.append(case)
    return out


def choose_sliding_free(per_seed: dict[str, dict[str, Any]], stance_real: dict[str, dict[str, Any]],
                        summaries: dict[str, dict[str, Any]]) -> dict[str, Any]:
    """The module doc's second look: :func:`choose` with the variation test on the sliding-free shares."""
    cases = spread_cases(per_seed, stance_real)
    names = list(summaries)
    figure = {n: mean_capped_log(cases.get(n, []), SLIDING_FREE) for n in names}
    eligible, floor, variation_floor = contact_draws.eligibility(summaries, figure)
    shares = {n: {k: spread(c[k] for c in cases.get(n, [])) for k in (*(k for k, _ in SPREADS), "diversity")}
              for n in names}
    return {"capped_log_sliding_free": figure, "variation_floor": variation_floor, "recognition_floor": floor,
            "eligible": eligible, "chosen": slowest_eligible(summaries, eligible), "shares": shares}


def stance_figures(out: Path, report: dict[str, Any], styles: list[str], samples: int, seed: int,
                   real_cache: dict[str, dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """``<primitive>/<model>`` → stance travel of ``samples`` samples of the run's neutral VAE and CVAEs (seed
    ``seed``); the style's real clips (train + val) go into ``real_cache`` (the same for every arm of a seed)."""
    from stylemotion.datasets.registry import build_dataset
    from stylemotion.evaluation.reference import primitive_data
    from stylemotion.evaluation.sources import motions_from_clips
    from stylemotion.models.loading import load_generative
    from stylemotion.primitives.segmentation import parse_primitive, stance_foot
    from stylemotion.primitives.stance import stance_travel

    meta = report["meta"]
    neutral_style = meta["settings"]["neutral_style"]
    takeset = None
    figures: dict[str, dict[str, Any]] = {}
    for primitive in report["primitives"]:
        foot = stance_foot(parse_primitive(primitive)[1])
        folders = {"neutral": out / "vae" / primitive, **{st: out / "cvae" / f"{primitive}_{st}" for st in styles}}
        data = None  # the primitive's real clips, segmented and split once (only when a style is not cached yet)
        for name, folder in folders.items():
            model = load_generative(folder / "checkpoints" / "best.ckpt")
            motions = model.sample(samples, seed=seed)
            key = f"{primitive}/{name}"
            figures[key] = stance_travel(motions.positions.numpy(), motions.num_frames.numpy(), motions.fps,
                                         foot).as_dict()
            if key in real_cache:
                continue
            if data is None:
                takeset = takeset or build_dataset(meta["data"])
                data = primitive_data(takeset, primitive, model.timeline_frames, neutral_style,
                                      meta["settings"]["segment"], meta["data"].get("split"), heldout_splits=("val",))
            style_name = neutral_style if name == "neutral" else name
            real = motions_from_clips(data.split("train", style_name) + data.split("val", style_name),
                                      model.timeline_frames)
            real_cache[key] = stance_travel(real.positions.numpy(), real.num_frames.numpy(), real.fps,
                                            foot).as_dict()
    return figures


def arm_record(args: argparse.Namespace, seed: int, first: Path, name: str, overrides: list[str],
               real_cache: dict[str, dict[str, Any]]) -> dict[str, Any]:
    """Arm ``name`` of ``seed`` in ``first``'s sibling folder ``name`` (``first`` is the ``off`` run, whose
    autoencoder and VAE stages the others copy), its CVAE stages with ``overrides``, evaluated on validation clips:
    :func:`contact_draws.val_arm`'s record with the stance figures (``stance_travel`` when ``--stance-samples`` > 0;
    the style's real clips cached in ``real_cache``)."""
    out = first.with_name(name)
    out.mkdir(parents=True, exist_ok=True)
    copied = style_channels.share_stages(first, out) if out != first else []
    report, styles, record = contact_draws.val_arm(args, seed, out, {"cvae": overrides})
    record = {**record, "cvae_overrides": overrides, "shared_from_off": copied, "stance": case_stance(report, styles)}
    if args.stance_samples > 0:
        record["stance_travel"] = stance_figures(out, report, styles, args.stance_samples, seed, real_cache)
    return record


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    import torch


    torch.set_num_threads(1)
    table = arms(args.weight, list(args.arms))
    per_seed: dict[str, dict[str, Any]] = {}
    stance_real: dict[str, dict[str, Any]] = {}
    for seed in seeds:
        first = args.runs / args.data / f"seed{seed}" / "off"
        for name, overrides in table.items():
            per_seed.setdefault(str(seed), {})[name] = arm_record(args, seed, first, name, overrides,
                                                                  stance_real.setdefault(str(seed), {}))
    summaries = {name: arm_summary([s[name] for s in per_seed.values()]) for name in table}
    sliding_free = choose_sliding_free(per_seed, stance_real, summaries) if args.stance_samples > 0 else None
    return {"data": args.data, "weight": args.weight, "arms": table, "overrides": args.override,
            "splits": {"choose": "evaluation.heldout_splits=[val], as suites style_channels and contact_draws: no "
                                 "test clip is read by the figures the rule uses",
                       "seeds": "training seeds, not reported seeds"},
            "per_seed": per_seed, "summary": summaries, "choice": choose(summaries),
            "stance_samples": args.stance_samples, "stance_real": stance_real, "sliding_free": sliding_free}


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    choice = r["choice"]
    label, sd = contact_full.run_label(r), contact_full.sd
    rows = contact_draws.arm_rows(r, lambda s: [
        sd(s["mid_mps_samples"], 2), sd(s["mid_mps_real"], 3), sd(s["mid_excess"], 2), sd(s["no_plant_samples"], 2),
        sd(s["styled"]["skating_samples"], 1, 100), sd(s["styled"]["skating_real"], 1, 100),
        sd(s["styled_skating_relative"]), *contact_draws.styled_cells(s["styled"])])
    seeds = ", ".join(r["per_seed"])
    verdict = ("`off` **stays**" if choice["chosen"] == "off" else f"**{choice['chosen']}** is chosen")
    return {"headline": (
        f"{label}Where the style CVAE's draws' contact term holds their feet (`model.sample_contacts`, β = "
        f"`model.sample_contact_weight` = {r['weight']:g}) at the reproduction's budget on **validation** clips "
        f"({r['data']}, both walk stances, every style, training seeds {seeds}: not reported seeds), "
        f"`evaluation.heldout_splits=[val]`; the arms share `off`'s autoencoder and VAE stages. Mid-stance speed: the "
        f"stance foot's planted-point speed over the middle half of each motion (m/s), every sample counted; never "
        f"planted: share of samples whose stance foot is never in contact; skating: share of contact foot-frames "
        f"moving > 0.2 m/s (%), which leaves never-planted samples out. Mean ± sd (min–max) over (seed, stance, "
        f"style). Rule: eligible when Table 5.1 rows on the diagonal are no fewer than `off`'s, mean recognition ≥ "
        f"{fmt(choice['recognition_floor'], 3)} and mean capped log variation ≥ {fmt(choice['variation_floor'], 3)} "
        f"(`off`'s minus {style_channels.TIE:g}); then the lowest mean mid-stance speed minus real, beating the holder "
        f"by more than {TIE:.0%}. Verdict: {verdict}.\n\n"
        + md_table(["arm", "mid-stance speed, samples (m/s)", "mid-stance speed, real (m/s)", "samples − real (m/s)",
                    "never planted, samples", "skating, samples (%)", "skating, real (%)", "skating ÷ real",
                    "rows on diagonal", "recognition", "V_SD / style", "step_SD / style", "diversity / style",
                    "mean capped log variation", "CVAE minutes per run", "eligible"], rows)
        + f"\n\n{provenance_line(record)}"),
        **({"stance": f"{render_stance(r)}\n\n{provenance_line(record)}"} if r.get("stance_samples") else {}),
        **({"sliding": f"{render_sliding(r)}\n\n{provenance_line(record)}"} if r.get("sliding_free") else {}),
        "reading": render_reading(r)}


#: Columns of the stance block: key of :class:`stylemotion.primitives.stance.StanceTravel`, header, digits.
STANCE_COLUMNS = (("travel_ratio", "root ÷ leg travel", 2), ("foot_drift_m", "stance foot drift (m)", 3),
                  ("root_speed_mps", "root speed (m/s)", 2), ("duration_s", "duration (s)", 2))


def render_stance(r: dict[str, Any]) -> str:
    """The stance block: per model (neutral, then styles) and arm, mean ± sd (min–max) over seeds and stances."""
    sd = contact_full.sd
    arms_ = list(r["summary"])
    models: list[str] = []
    for seed in r["per_seed"].values():
        for key in seed[arms_[0]].get("stance_travel", {}):
            model = key.split("/", 1)[1]
            if model not in models:
                models.append(model)

    def values(source: list[dict[str, Any]], model: str, column: str) -> dict[str, Any]:
        return spread(v[column] for d in source for k, v in d.items() if k.split("/", 1)[1] == model)

    rows = []
    for model in models:
        real = list(r["stance_real"].values())
        rows.append([model, "real clips (train + val)", *(sd(values(real, model, c), d) for c, _, d in STANCE_COLUMNS)])
        for arm in arms_[:1] if model == "neutral" else arms_:  # the arms share the neutral VAE stage
            source = [seed[arm].get("stance_travel", {}) for seed in r["per_seed"].values()]
            label = "VAE samples (every arm's)" if model == "neutral" else arm
            rows.append(["", label, *(sd(values(source, model, c), d) for c, _, d in STANCE_COLUMNS)])
    return (f"Stance travel over the middle half of each motion ({r['stance_samples']} samples per model and seed; "
            "real clips: the style's train + val clips), mean ± sd (min–max) over training seeds and both stances. "
            "Root ÷ leg travel: the root's travel over that of the root relative to the stance foot (median over "
            "motions; 1 when the foot holds the ground); drift: the stance foot's own travel. Not ruled on.\n\n"
            + md_table(["model", "arm", *(h for _, h, _ in STANCE_COLUMNS)], rows))


def render_sliding(r: dict[str, Any]) -> str:
    """The second look's block: root and leg spread shares side by side, the sliding-free figure and its verdict."""
    look, sd = r["sliding_free"], contact_full.sd
    rows = [[f"**{n}**" if n == look["chosen"] else n, *(sd(look["shares"][n][k]) for k, _ in SPREADS),
             sd(look["shares"][n]["diversity"]), fmt(look["capped_log_sliding_free"][n], 3),
             "yes" if look["eligible"][n] else "no"] for n in r["summary"]]
    verdict = ("`off` **stays**" if look["chosen"] == "off" else f"**{look['chosen']}** is chosen")
    return ("Second look (the module doc's rule, written after the first rule kept `off` and before these figures): "
            "the first rule with its variation test on sliding-free shares. Spreads over motions of the middle half "
            "of each stance (the stance block's samples), samples ÷ the style's real clips (train + val), mean ± sd "
            "(min–max) over (seed, stance, style): root travel and speed as the root moves, leg travel and speed "
            "as the root moves relative to the stance foot (what it would travel were the foot planted); a root "
            "share above the leg share is variation a sliding foot makes. Eligible when Table 5.1 rows and "
            f"recognition hold as in the first rule and the mean capped log of (leg travel SD, leg speed SD, "
            f"diversity) ≥ {fmt(look['variation_floor'], 3)} (`off`'s minus {style_channels.TIE:g}); then the "
            f"lowest mid-stance speed over real as before. Verdict: {verdict}.\n\n"
            + md_table(["arm", *(f"{h} ÷ real" for _, h in SPREADS), "diversity ÷ real",
                        "mean capped log (leg travel, leg speed, diversity)", "eligible"], rows))


def _span(values: list[float], digits: int, scale: float = 1.0) -> str:
    """``lo–hi`` of ``values`` × ``scale``."""
    return f"{fmt(scale * min(values), digits)}–{fmt(scale * max(values), digits)}"


def render_reading(r: dict[str, Any]) -> str:
    """The reading of the blocks, every figure taken from the results: the verdict and what each arm does."""
    summary, choice = r["summary"], r["choice"]
    arms_ = list(summary)
    off = summary["off"]
    lines = [f"Reading (figures from the blocks above): by the rule **{choice['chosen']}** is the default."]
    for arm in arms_[1:]:
        s = summary[arm]
        missed = []
        if s["styled"]["rows_on_diagonal"] < off["styled"]["rows_on_diagonal"]:
            missed.append("Table 5.1 rows")
        if s["styled"]["recognition"]["mean"] < choice["recognition_floor"]:
            missed.append("recognition")
        if s["styled"]["capped_log_variation"] < choice["variation_floor"]:
            missed.append(f"variation (mean capped log {fmt(s['styled']['capped_log_variation'], 3)} against the "
                          f"floor {fmt(choice['variation_floor'], 3)})")
        status = "eligible" if choice["eligible"][arm] else "not eligible: " + ", ".join(missed)

        def change(key: str, digits: int = 2, *path: str, arm_summary: dict[str, Any] = s) -> str:
            before, after = off, arm_summary
            for step in path:
                before, after = before[step], after[step]
            return f"{fmt(before[key]['mean'], digits)} to {fmt(after[key]['mean'], digits)}"

        lines.append(
            f"`{arm}` ({status}): the stance foot's mid-stance speed over real falls from {change('mid_excess')} m/s, "
            f"the share of samples never planted from {change('no_plant_samples')}, the skating share from "
            f"{change('styled_skating_relative', 1)} times the real clips'; V_SD {change('v_sd', 2, 'styled')}, "
            f"step_SD {change('step_sd', 2, 'styled')}, diversity {change('diversity', 2, 'styled')} of the style's "
            f"clips; recognition {fmt(s['styled']['recognition']['mean'], 3)}.")
    stance = [(arm, [v for seed in r["per_seed"].values() for k, v in seed[arm].get("stance_travel", {}).items()
                     if not k.endswith("/neutral")]) for arm in arms_]
    real = [v for seed in r.get("stance_real", {}).values() for k, v in seed.items() if not k.endswith("/neutral")]
    if real and all(values for _, values in stance):
        lines.append(
            "Block `stance`: in the style models' samples the root travels "
            + "; ".join(f"{_span([v['travel_ratio'] for v in values], 2)} of the leg's sweep with the stance foot "
                        f"drifting {_span([v['foot_drift_m'] for v in values], 1, 100)} cm (`{arm}`)"
                        for arm, values in stance)
            + f"; in the styles' real clips {_span([v['travel_ratio'] for v in real], 2)} and "
              f"{_span([v['foot_drift_m'] for v in real], 1, 100)} cm. Where the root travels less than the leg "
              "sweeps, the stance foot slides back by the difference.")
    look = r.get("sliding_free")
    if look:
        parts = [f"`{n}` root travel SD {fmt(look['shares'][n]['root_travel_sd_m'].get('mean'))} and leg travel SD "
                 f"{fmt(look['shares'][n]['leg_travel_sd_m'].get('mean'))} of the real clips' (mean capped log "
                 f"{fmt(look['capped_log_sliding_free'][n], 3)})" for n in arms_]
        wider = [n for n in arms_ if (look["shares"][n]["root_travel_sd_m"].get("mean") or 0)
                 > (look["shares"][n]["leg_travel_sd_m"].get("mean") or 0)]
        lines.append(f"Second look (block `sliding`): by its rule **{look['chosen']}** is the default. "
                     + "; ".join(parts) + ". "
                     + (f"Root spread above the legs' (variation a sliding foot makes) in {', '.join(wider)}."
                        if wider else "In no arm is the root's travel spread above the legs': sliding does not "
                        "widen the step variation the first rule read."))
    chosen = look["chosen"] if look else choice["chosen"]
    if chosen == "off":
        lines.append("To train with the template anyway: `model.sample_contact_weight=100 "
                     "model.sample_contacts=content` (`stylemotion-train experiment=style_cvae`, or a reproduction's "
                     "`stages.cvae`).")
    return "\n\n".join(lines)
