"""``report.md`` of an evaluation, readable on its own: the thesis comparison, every table with units,
and the definitions of all numbers."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from stylemotion.evaluation.tables import VARIANCE_KEYS
from stylemotion.io.markdown import md_table

#: The thesis' numbers this evaluation is compared with (Tables 5.1–5.3 of Du's dissertation).
THESIS: dict[str, Any] = {
    # Table 5.1 (walk left stance only): every row has its minimum on the diagonal; the columns of
    # "depressed" and "female" have theirs in the neutral row.
    "table_5_1_rows": "7 / 7", "table_5_1_columns": "5 / 7",
    # Tables 5.2 / 5.3: pose_SD, V_SD, Step_SD of the training data, the neutral VAE and six style models.
    "variance": {
        "walk_leftStance": {"training_data": (52.8613, 0.4816, 10.1233), "neutral": (52.6766, 0.4197, 7.6634),
                            "proud": (50.6545, 0.5782, 11.2539), "depressed": (48.3101, 0.5892, 9.3205),
                            "angry": (49.9446, 0.6611, 11.7906), "female": (49.7224, 0.5974, 10.7240),
                            "childlike": (51.1589, 0.5058, 9.6104), "old": (46.0082, 0.5383, 9.9513)},
        "walk_rightStance": {"training_data": (53.0372, 0.4985, 9.9842), "neutral": (52.8817, 0.4610, 7.5081),
                             "proud": (51.1320, 0.6147, 11.8916), "depressed": (48.5037, 0.6031, 9.9183),
                             "angry": (50.2103, 0.7035, 12.7569), "female": (50.3722, 0.6669, 10.7090),
                             "childlike": (51.3179, 0.5389, 8.8596), "old": (45.5661, 0.5998, 10.2023)},
    },
}


def thesis_ratios(primitive: str) -> dict[str, dict[str, float]]:
    """The thesis' SD / training-data SD per row of Table 5.2 (left) or 5.3 (right stance), or {}."""
    table = THESIS["variance"].get(primitive)
    if table is None:
        return {}
    base = table["training_data"]
    return {row: {k: v / b for k, v, b in zip(VARIANCE_KEYS, values, base)} for row, values in table.items()}

DEFINITIONS = {
    "table_5_1": "D(m, s) = mean over N samples x_i of model m of ‖Gram(Φ(x_i)) − Gram(Φ(s))‖_F (eq. 5.12); x_i "
                 "the sample on the canonical timeline re-encoded by the autoencoder Φ, Gram over time divided by "
                 "the number of time steps (stylemotion.models.style); s the style example clip(s) the style model "
                 "was trained with, and for the neutral column the frame-wise mean motion of the neutral training "
                 "clips. Lower = closer to that example's style.",
    "shift_baseline": "row shift:<s> (Tables 5.1–5.3; evaluation.shift_baseline): the neutral VAE's samples, each "
                      "moved in the autoencoder's feature space by (mean features of s's example clip(s) − mean "
                      "features of the neutral training clips), durations by the same offset in log duration, then "
                      "decoded: the baseline any style model has to beat.",
    "morphable": "row morphable (morphable:<s>): a Morphable Graph model (Du ch. 3–4) fitted on the neutral clips "
                 "(on those of style s; all: every style), its samples time-normalized onto the evaluation's "
                 "timeline: rows of Tables 5.1–5.3 only (no example, so no recognition or column).",
    "zero_shot": "rows zero_shot:<s>: a zero-shot network bound to the example clip(s) of style s (a CVAE's example: "
                 "its Table 5.1 row is measured against that CVAE's column, no column of its own).",
    "pose_sd": "sqrt(Σ‖p_i − p̄‖² / (N−1)) over all valid frames of all motions, p_i the 21 joints relative to the "
               "root's ground projection, facing +Z (eq. 5.13); cm.",
    "v_sd": "sqrt((Σ(v_i − v̄)² + Σ(ω_i − ω̄)²) / (N−1)) over motions, v_i the mean root ground speed (m/s), ω_i the "
            "mean yaw rate (rad/s, signed) (eq. 5.14).",
    "step_sd": "standard deviation over motions of the step length, the ground distance of the summed relative "
               "root translation from first to last frame (eq. 5.15); cm.",
    "pose_across_sd": "sqrt(1/T Σ_t Σ_c Var_i(x_itc)) in cm: the spread across motions at aligned frames t of the "
                      "canonical timeline, x_itc coordinate c of the 21 root-local joints of motion i (beyond the "
                      "thesis: copies of one motion score 0, while pose_SD stays high from the motion within a step).",
    "variation_vs_style": "a model's pose_across_SD, V_SD and step_SD divided by those of all real clips of its own "
                          "style, and its diversity divided by that of its ground truth clips (beyond the thesis, "
                          "whose ratios divide by the neutral training data): near 100 % keeps the style's "
                          "variation, near 0 copies one motion.",
    "classifier": "z-scored descriptor (the clip's 66-dim frames on the canonical timeline + log duration) → PCA → "
                  "multinomial logistic regression, fitted on real train-split clips of every style; held-out "
                  "accuracy on real val+test clips; a model's share = fraction of its samples assigned its style.",
    "frechet": "‖μ_a − μ_b‖² + tr(Σ_a + Σ_b − 2(Σ_aΣ_b)^½) between the model's samples and its ground truth (real "
               "clips of its style it never saw: all but the example; for neutral, the val+test clips), in the "
               "classifier's PCA feature space. References: neutral-model samples vs the same clips; real floor = "
               "train-split vs val+test clips of the style.",
    "diversity": "mean Euclidean distance between all pairs of motions in the classifier's feature space.",
    "foot_skating": "share of contact foot-frames (stylemotion.primitives.contacts.foot_contacts, resting heights of "
                    "real train takes) whose planted-point speed (slower of heel and ball) exceeds skate_speed_mps; "
                    "contact_share, no_plant_share (stance foot never in contact) and planted_mid_mps (stance "
                    "foot speed over the middle half) catch feet that slide too fast to be detected as contact.",
    "stance_travel": "over the middle half of each motion of a stance primitive, the root's horizontal travel ÷ its "
                     "travel relative to the stance foot (median over motions; 1 when the foot holds the ground), "
                     "the stance foot's own travel (drift, m), the root speed and the duration "
                     "(stylemotion.primitives.stance): a leg sweep the root does not follow makes the foot slide.",
    "nearest_training": "RMS joint distance (root-local poses on the canonical timeline, metres) from each motion "
                        "to its nearest training clip (neutral train clips + the model's example); medians. Samples "
                        "much closer than real unseen clips are copies.",
    "autoencoder": "MPJPE (m) of the autoencoder's reconstruction of the test split's windows; test_mpjpe_m "
                   "integrates both roots from the origin, test_local_mpjpe_m compares root-local poses.",
}


def fmt(value: Any, digits: int = 4) -> str:
    """A number with ``digits`` significant digits (``–`` for None/NaN)."""
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "–"
    if isinstance(value, (int, np.integer)):
        return f"{int(value):,}"
    return f"{float(value):.{digits}g}"


def pct(value: Any) -> str:
    return "–" if value is None or not math.isfinite(value) else f"{100 * value:.1f} %"


def format_markdown(results: dict[str, Any], figures: list[str], tables: list[str]) -> str:
    """``report.md``: every table with its units and definitions, readable without the other files."""
    meta = results.get("meta", {})
    out = ["# Evaluation report", ""]
    samples = meta.get("samples", {})
    out += [f"Data `{meta.get('data_name', '?')}`, seed {meta.get('seed', '?')}, samples per model: Table 5.1 "
            f"{fmt(samples.get('table_5_1'))}, Tables 5.2/5.3 {fmt(samples.get('variance'))}, other metrics "
            f"{fmt(samples.get('metrics'))}. Git commit `{meta.get('git_commit', '?')}`; "
            f"{fmt(meta.get('seconds'), 3)} s.", ""]
    if meta.get("command"):
        out += ["```", meta["command"], "```", ""]
    ae = results.get("autoencoder", {})
    out += [f"Autoencoder `{ae.get('path', '?')}` (weights {ae.get('fingerprint', '?')}): test MPJPE "
            f"{fmt(100 * ae['test_mpjpe_m'], 3)} cm (root-local poses {fmt(100 * ae['test_local_mpjpe_m'], 3)} cm) "
            f"over {fmt(ae['test_windows'])} test windows of {ae['window_frames']} frames." if ae else "", ""]
    if meta.get("checkpoints"):
        out += ["Models:", "", md_table(["primitive", "model", "kind", "style", "checkpoint"],
                                         [[c.get("primitive", ""), c.get("name", ""), c.get("kind") or "",
                                           c.get("style", ""), f"`{c.get('path')}`"] for c in meta["checkpoints"]]),
                ""]
    out += _thesis_section(results)
    out += _table_5_1_section(results)
    out += _variance_section(results)
    out += _variation_section(results)
    out += _recognition_section(results)
    out += _metric_sections(results)
    out += ["## Files", "", "Tables as CSV: " + ", ".join(f"`{t}`" for t in tables) + ".", ""]
    out += ["Figures: " + ", ".join(f"`{f}`" for f in figures) + ".", ""]
    out += ["## Definitions", ""] + [f"* **{k}**: {v}" for k, v in DEFINITIONS.items()] + [""]
    return "\n".join(out)


def _thesis_section(results: dict[str, Any]) -> list[str]:
    out = ["## Against the thesis", ""]
    rows = []
    for p, t in results.get("table_5_1", {}).items():
        d = t["diagonal"]
        rows.append([f"Table 5.1 {p}: rows with their minimum on the diagonal",
                     f"{len(d['rows'])} / {len(t['models'])}", THESIS["table_5_1_rows"] + " (left stance)"])
        rows.append([f"Table 5.1 {p}: columns with their minimum on the diagonal",
                     f"{len(d['columns'])} / {len(t['models'])}", THESIS["table_5_1_columns"] + " (left stance)"])
    for p, ratios in results.get("variance_ratio", {}).items():
        thesis = thesis_ratios(p)
        extra = results.get("extra_rows", {}).get(p, [])
        styles = [r for r in ratios if r not in ("training_data", "neutral", *extra)]
        thesis_styles = [r for r in thesis if r not in ("training_data", "neutral")]
        for k in VARIANCE_KEYS:
            if "neutral" in ratios:
                rows.append([f"{p}: neutral {k} / training data", pct(ratios["neutral"][k]),
                             pct(thesis.get("neutral", {}).get(k))])
            if styles:
                here = [ratios[s][k] for s in styles]
                there = [thesis[s][k] for s in thesis_styles]
                rows.append([f"{p}: style models {k} / training data (min – max)",
                             f"{pct(min(here))} – {pct(max(here))}",
                             f"{pct(min(there))} – {pct(max(there))}" if there else "–"])
    out += ["The thesis' styles (proud, depressed, angry, female, childlike, old) are not Bandai's, so style rows "
            "are compared as ranges.", "",
            md_table(["what", "here", "thesis"], rows) if rows else "(no comparable result)", ""]
    return out


def _table_5_1_section(results: dict[str, Any]) -> list[str]:
    out = ["## Table 5.1: style distance D(model, example)", "",
           "Rows: models; columns: style examples (neutral = mean motion). Bold: row minimum. Lower = closer.", ""]
    for p, t in results.get("table_5_1", {}).items():
        matrix = np.asarray(t["distance"])
        rows = [[f"**{m}**"] + [f"**{fmt(v)}**" if j == matrix[i].argmin() else fmt(v) for j, v in enumerate(matrix[i])]
                for i, m in enumerate(t["models"])]
        shared = t.get("shared_columns", {})
        rows += [[f"*{name}* " + (f"(example of {shared[name]['column']})" if name in shared else
                                  "(shift baseline)" if name.startswith("shift:") else
                                  "(Morphable Graph)" if name.split(":")[0] == "morphable" else "(extra row)")]
                 + [f"*{fmt(v)}*" if name in shared and j == int(np.argmin(values)) else fmt(v)
                    for j, v in enumerate(values)]
                 for name, values in t.get("extra_rows", {}).items()]
        d = t["diagonal"]
        out += [f"### {p} ({fmt(t['samples'])} samples per model)", "",
                md_table(["model \\ example"] + t["examples"], rows), "",
                f"Rows with the minimum on the diagonal: {len(d['rows'])} of {len(t['models'])} "
                f"({', '.join(d['rows'])}); columns: {len(d['columns'])} of {len(t['models'])} "
                f"({', '.join(d['columns'])}).",
                "Rows whose minimum is elsewhere: " + (", ".join(f"{r} → {c}" for r, c in d["row_argmin"].items()
                                                              if r != c) or "none") + ".", "",
                *(["Rows on another model's example (zero-shot networks bound to a CVAE's example; no column of "
                   "their own, italic: row minimum): " + ", ".join(
                       f"{n} → {r['row_argmin']} ({'its' if r['own_column_is_minimum'] else 'not its'} example's "
                       f"column {r['column']})" for n, r in shared.items()) + ".", ""] if shared else []),
                "Examples: " + "; ".join(f"{m}: {e if isinstance(e, str) else ', '.join(e)}"
                                         for m, e in t["example_clips"].items()) + ".", "",
                f"![Table 5.1 {p}](table_5_1_{p}.png)", ""]
    return out


def _variance_section(results: dict[str, Any]) -> list[str]:
    out = ["## Tables 5.2/5.3: variance", "",
           "pose_SD in cm, V_SD in m/s ⊕ rad/s, step_SD in cm (definitions below); ratio = value / training data.", ""]
    for p, rows in results.get("variance", {}).items():
        ratio = results["variance_ratio"][p]
        body = [[r] + [fmt(s[k]) for k in VARIANCE_KEYS] + [pct(ratio[r][k]) for k in VARIANCE_KEYS]
                + [fmt(s["speed_mean_mps"], 3), fmt(s["step_mean_cm"], 3), fmt(s["motions"])] for r, s in rows.items()]
        out += [f"### {p}", "", md_table(["row", "pose_SD", "V_SD", "step_SD", "pose %", "V %", "step %",
                                           "mean speed m/s", "mean step cm", "motions"], body), ""]
        real = results.get("variance_real", {}).get(p, {})
        if real:
            out += ["Real clips of each style (all splits), for reference:", "",
                    md_table(["style", "pose_SD", "V_SD", "step_SD", "mean speed m/s", "mean step cm", "clips"],
                              [[st] + [fmt(s[k]) for k in VARIANCE_KEYS]
                               + [fmt(s["speed_mean_mps"], 3), fmt(s["step_mean_cm"], 3), fmt(s["motions"])]
                               for st, s in real.items()]), ""]
    if results.get("variance_ratio"):
        out += ["![variance](variance.png)", ""]
    return out


def _variation_section(results: dict[str, Any]) -> list[str]:
    if not results.get("variation_vs_style"):
        return []
    out = ["## Variation across samples, against the real clips of each model's style", "",
           "pose_across_SD in cm (spread across motions at aligned canonical frames); % = the model's value / its "
           "style's real clips (diversity: / its ground truth). A model that copies one motion scores near 0 here "
           "whatever its pose_SD.", ""]
    for p, ratios in results["variation_vs_style"].items():
        rows, real = results["variance"][p], results.get("variance_real", {}).get(p, {})
        body = [[m, r["style"], fmt(rows[m].get("pose_across_sd")), fmt(real.get(r["style"], {}).get("pose_across_sd")),
                 pct(r["pose_across_sd"]), pct(r["v_sd"]), pct(r["step_sd"]), pct(r["diversity"])]
                for m, r in ratios.items()]
        header = ["model", "style", "pose_across_SD", "its style's real clips", "pose_across %", "V_SD %", "step_SD %",
                  "diversity %"]
        out += [f"### {p}", "", md_table(header, body), ""]
    return out


def _recognition_section(results: dict[str, Any]) -> list[str]:
    rec = results.get("style_recognition")
    if not rec:
        return []
    out = ["## Style recognition", "",
           f"Classifier accuracy on real held-out clips: **{pct(rec['classifier_heldout_accuracy'])}** "
           f"(chance {pct(rec['chance'])}).", ""]
    for p, c in rec["per_primitive"].items():
        out += [f"### {p}: confusion on {fmt(c['heldout_clips'])} real held-out clips (rows true, columns predicted; "
                f"{fmt(c['train_clips'])} train clips, {c['components']} PCA dims)", "",
                md_table(["true \\ predicted"] + c["styles"], [[s] + [str(v) for v in row]
                                                                  for s, row in zip(c["styles"], c["confusion"])]), "",
                f"![confusion {p}](classifier_confusion_{p}.png)", ""]
    body = []
    for p, models in rec["per_model_detail"].items():
        for m, d in models.items():
            top = max(d["predicted"], key=d["predicted"].get)
            body.append([p, m, d["target_style"], pct(d["share"]), pct(d["real_share"]),
                         f"{top} ({pct(d['predicted'][top])})"])
    out += ["Share of each model's samples assigned to its target style (real ground truth clips for reference):", "",
            md_table(["primitive", "model", "target", "samples", "real", "most predicted"], body), ""]
    return out


def _metric_sections(results: dict[str, Any]) -> list[str]:
    out = ["## Fréchet distance and diversity (classifier feature space)", ""]
    body = []
    for p, models in results.get("frechet", {}).items():
        for m, fd in models.items():
            ref, div = results["frechet_reference"][p][m], results["diversity"][p][m]
            body.append([p, m, fmt(fd), fmt(ref.get("neutral_samples")), fmt(ref.get("real_floor")),
                         fmt(ref["ground_truth_clips"]), fmt(div["samples"]), fmt(div["real"])])
    out += [md_table(["primitive", "model", "FD samples↔truth", "FD neutral samples↔truth", "FD real floor",
                       "truth clips", "diversity samples", "diversity real"], body), ""]
    pooled = [f"{m} {pct(v)} (real {pct(results['foot_skating_real'].get(m))})"
              for m, v in results.get("foot_skating", {}).items()]
    out += ["## Foot skating", "", "Pooled over primitives: " + ", ".join(pooled) + ".", ""]
    body = []
    for p, models in results.get("foot_skating_detail", {}).items():
        for m, d in models.items():
            s, r = d["samples"], d["real"]
            body.append([p, m, pct(s["ratio"]), pct(r["ratio"]), pct(s["contact_share"]), pct(r["contact_share"]),
                         pct(s["no_plant_share"]), pct(r["no_plant_share"]), fmt(s["planted_mid_mps"], 3),
                         fmt(r["planted_mid_mps"], 3)])
    out += [md_table(["primitive", "model", "skating", "real", "contact", "real", "no plant", "real",
                       "planted mid m/s", "real"], body), ""]
    body = [[p, m, fmt(d["samples"]["travel_ratio"], 3), fmt(d["real"]["travel_ratio"], 3),
             fmt(d["samples"]["foot_drift_m"], 3), fmt(d["real"]["foot_drift_m"], 3),
             fmt(d["samples"]["root_speed_mps"], 3), fmt(d["real"]["root_speed_mps"], 3),
             fmt(d["samples"]["duration_s"], 3), fmt(d["real"]["duration_s"], 3)]
            for p, models in results.get("stance_travel", {}).items() for m, d in models.items()]
    if body:
        out += ["Stance travel (middle half of each motion; real: the model's ground-truth clips):", "",
                md_table(["primitive", "model", "root ÷ leg travel", "real", "stance foot drift m", "real",
                          "root speed m/s", "real", "duration s", "real"], body), ""]
    out += ["## Nearest training clip (copying check)", "", "Medians, cm (RMS joint distance of root-local poses).", ""]
    body = []
    for p, models in results.get("nearest_training", {}).items():
        for m, d in models.items():
            cm = [d.get(k) for k in ("samples_median_m", "heldout_neutral_median_m", "ground_truth_median_m",
                                     "to_example_median_m", "ground_truth_to_example_median_m")]
            body.append([p, m] + [fmt(None if v is None else 100 * v, 3) for v in cm])
    out += [md_table(["primitive", "model", "samples → training", "unseen neutral → training",
                       "ground truth → training", "samples → example", "ground truth → example"], body), ""]
    return out
