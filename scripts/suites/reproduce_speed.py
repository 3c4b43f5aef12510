"""Suite ``reproduce_speed``: the wall-clock time of ``stylemotion-reproduce data=bandai`` (every take), stage by
stage, with the tables it has to keep (issue 29).

    python scripts/benchmarks.py run reproduce_speed --label before --cpu-kind fp32-avx2
    python scripts/benchmarks.py run reproduce_speed --label after --cpu-kind fp32-avx2

Each run is the user's command in a subprocess, into a fresh folder (a finished one is never reused: the time is
the figure), run alone on the machine. ``--cpu-kind fp32-avx2`` stands in for the CPUs most laptops and CI runners
have, on a machine with AVX-512: float32 autoencoder (``budget.autoencoder.precision=32-true``) and kernels limited
to AVX2 (``ONEDNN_MAX_CPU_ISA=AVX2``, ``ATEN_CPU_CAPABILITY=avx2``); ``native`` is the command as it runs here.
The clock speed stays this machine's, so the emulation is an estimate of that kind, said so in the docs.

Runs of other labels already in the results file are kept with their own commit, date and load (a before/after pair
cannot come from one commit), so one file holds the comparison; every entry says what it ran.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

from suites.common import fmt, md_table

DESCRIPTION = "wall-clock of stylemotion-reproduce data=bandai (all takes) per stage, with its tables (run alone)"
DEFAULT_SEEDS = (0,)
ROOT = Path(__file__).resolve().parents[2]
RESULTS = ROOT / "benchmarks" / "results" / "reproduce_speed.json"
#: environment and overrides that stand in for a CPU kind on this machine
CPU_KINDS: dict[str, tuple[dict[str, str], list[str]]] = {
    "native": ({}, []),
    "fp32-avx2": ({"ONEDNN_MAX_CPU_ISA": "AVX2", "ATEN_CPU_CAPABILITY": "avx2"},
                  ["budget.autoencoder.precision=32-true"]),
}
AIM_MINUTES = 25.0


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--label", default="current", help="name of this run in the results file (e.g. before, after)")
    parser.add_argument("--cpu-kind", choices=sorted(CPU_KINDS), default="fp32-avx2",
                        help="fp32-avx2: float32 and AVX2 kernels (the issue's machine kind); native: as it runs here")
    parser.add_argument("--runs", type=Path, default=ROOT / "runs" / "benchmarks" / "reproduce_speed",
                        help="parent of the run folders (each run's folder is made fresh)")
    parser.add_argument("--override", nargs="*", default=[], metavar="KEY=VALUE",
                        help="extra stylemotion-reproduce overrides (recorded)")


def stage_seconds(out: Path) -> dict[str, float]:
    """Seconds of every finished stage of a reproduction folder, from its ``done.json`` records."""
    stages = {}
    for done in sorted(out.rglob("done.json")):
        record = json.loads(done.read_text())
        stages[str(done.parent.relative_to(out))] = round(float(record.get("seconds", 0.0)), 1)
    return stages


STEP = re.compile(r"^\[(?P<when>[\d-]+ [\d:,]+)\]\[[^]]+\]\[INFO\] - (?:\[(?P<k>\d+)/(?P<n>\d+)\] (?P<what>\S+)|"
                  r"(?P<done>done in ))")


def phases(out: Path) -> dict[str, float] | None:
    """Minutes of the reproduction's phases from its own log (``<out>/hydra/*/reproduce.log``): data, autoencoder
    (alone), the VAE/CVAE stages (in parallel), evaluation. None without a log."""
    from datetime import datetime

    logs = sorted(out.glob("hydra/*/reproduce.log"))
    if not logs:
        return None
    marks: dict[str, datetime] = {}
    for line in logs[-1].read_text(errors="replace").splitlines():
        m = STEP.match(line)
        if not m:
            continue
        when = datetime.strptime(m["when"], "%Y-%m-%d %H:%M:%S,%f")
        if m["done"]:
            marks["done"] = when
        elif m["k"] == "1":
            marks.setdefault("start", when)
        elif m["k"] == "2":
            marks.setdefault("autoencoder", when)
        elif m["k"] == "3":
            marks.setdefault("stages", when)
        elif m["k"] == m["n"]:
            marks.setdefault("evaluation", when)
    order = ["autoencoder", "stages", "evaluation", "done"]
    if any(k not in marks for k in order):
        return None
    return {name: round((marks[b] - marks[a]).total_seconds() / 60, 2)
            for name, a, b in [("autoencoder", "autoencoder", "stages"), ("vae_cvae_stages", "stages", "evaluation"),
                               ("evaluation", "evaluation", "done")]}


def table_figures(report: dict[str, Any]) -> dict[str, Any]:
    """What the faster command must keep: Table 5.1's diagonal rows per primitive, styled recognition, the
    autoencoder's test MPJPE."""
    diagonal = {p: {"rows": len(t["diagonal"]["rows"]), "models": len(t["models"])}
                for p, t in report["table_5_1"].items()}
    per_model = report["style_recognition"]["per_model"]
    styled = [v for m, v in per_model.items() if m != "neutral" and not m.startswith("shift:")]
    ae = report["autoencoder"]
    return {"table_5_1_diagonal": diagonal,
            "recognition_styled_mean": sum(styled) / len(styled) if styled else None,
            "recognition_styled_min": min(styled) if styled else None,
            "autoencoder_test_mpjpe_m": ae.get("test_mpjpe_m"),
            "autoencoder_test_local_mpjpe_m": ae.get("test_local_mpjpe_m")}


def run_folder(parent: Path, label: str, cpu_kind: str, seed: int) -> Path:
    return parent / f"{label}_{cpu_kind}_seed{seed}"


def earlier_runs(label: str, parent: Path) -> dict[str, Any]:
    """Entries of other labels in the committed results file, kept with their own provenance."""
    if not RESULTS.is_file():
        return {}
    record = json.loads(RESULTS.read_text())
    runs = {k: v for k, v in record.get("results", {}).get("runs", {}).items() if k != label}
    for name, entry in runs.items():  # phases of entries recorded before the suite read them from the run's log
        folder = run_folder(parent, name, entry["cpu_kind"], entry["seed"])
        if "phases_min" not in entry and folder.is_dir():
            entry["phases_min"] = phases(folder)
    return runs


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    from stylemotion.provenance import git_commit

    env_extra, kind_overrides = CPU_KINDS[args.cpu_kind]
    seed = seeds[0]
    out = run_folder(args.runs, args.label, args.cpu_kind, seed)
    if out.exists():
        shutil.rmtree(out)
    command = [str(Path(sys.executable).parent / "stylemotion-reproduce"), "data=bandai", f"seed={seed}",
               f"out={out}", *kind_overrides, *args.override]
    env = {**os.environ, **env_extra}
    started = time.strftime("%Y-%m-%dT%H:%M:%S%z")
    load_before = os.getloadavg()
    t0 = time.perf_counter()
    completed = subprocess.run(command, env=env, cwd=ROOT)
    wall = time.perf_counter() - t0
    entry: dict[str, Any] = {
        "label": args.label, "cpu_kind": args.cpu_kind, "env": env_extra, "command": " ".join(command[1:]),
        "commit": git_commit(ROOT), "started": started, "load_before": [round(x, 2) for x in load_before],
        "load_after": [round(x, 2) for x in os.getloadavg()], "exit": completed.returncode,
        "wall_s": round(wall, 1), "stages_s": stage_seconds(out), "phases_min": phases(out), "seed": seed}
    if completed.returncode == 0:
        entry.update(table_figures(json.loads((out / "report" / "report.json").read_text())))
    runs = {**earlier_runs(args.label, args.runs), args.label: entry}
    return {"runs": runs, "aim_minutes": AIM_MINUTES,
            "splits": {"kind": "the reproduction's own take split (data.split, seed 0); nothing is chosen here",
                       "report": "Table 5.1 and recognition as the report computes them; autoencoder on test windows"}}


def group_stages(stages: dict[str, float]) -> dict[str, float]:
    """Stage seconds summed per kind (autoencoder, vae, cvae, …): the first path part of each stage."""
    out: dict[str, float] = {}
    for name, seconds in stages.items():
        key = name.split("/")[0]
        out[key] = out.get(key, 0.0) + seconds
    return out


def render(record: dict[str, Any]) -> dict[str, str]:
    runs = record["results"]["runs"]
    header = ["run", "CPU kind", "commit", "wall (min)", "autoencoder (min)", "VAE + CVAE stages, 2 at a time (min)",
              "evaluation (min)", "stage minutes summed: VAE / CVAE", "Table 5.1 diagonal rows",
              "recognition styled mean (min)", "AE test MPJPE int. / local (cm)"]
    rows = []
    for label, e in runs.items():
        grouped = group_stages(e["stages_s"])
        ph = e.get("phases_min") or {}
        diag = ", ".join(f"{p.split('_')[-1]} {d['rows']}/{d['models']}"
                         for p, d in e.get("table_5_1_diagonal", {}).items()) or f"exit {e['exit']}"
        rec = (f"{fmt(e['recognition_styled_mean'], 3)} ({fmt(e['recognition_styled_min'], 3)})"
               if e.get("recognition_styled_mean") is not None else "—")
        ae = (f"{fmt(100 * e['autoencoder_test_mpjpe_m'], 2)} / {fmt(100 * e['autoencoder_test_local_mpjpe_m'], 2)}"
              if e.get("autoencoder_test_mpjpe_m") is not None else "—")
        rows.append([label, e["cpu_kind"], e["commit"][:12], fmt(e["wall_s"] / 60, 1),
                     *[fmt(ph.get(k), 1) for k in ("autoencoder", "vae_cvae_stages", "evaluation")],
                     f"{fmt(grouped.get('vae', 0.0) / 60, 1)} / {fmt(grouped.get('cvae', 0.0) / 60, 1)}",
                     diag, rec, ae])
    notes = "; ".join(f"{label}: `stylemotion-reproduce {e['command']}`"
                      f"{' with ' + ', '.join(f'{k}={v}' for k, v in e['env'].items()) if e['env'] else ''}"
                      f" ({e['started'][:16].replace('T', ' ')}, load {e['load_before'][0]} → {e['load_after'][0]})"
                      for label, e in runs.items())
    text = (f"`stylemotion-reproduce data=bandai` (all takes, seed 0), each run alone in a fresh folder; aim ≤ "
            f"{record['results']['aim_minutes']:g} min. Phases from the run's own log; the data stage (cached "
            "conversion) is the rest of the wall clock.\n\n"
            + md_table(header, rows) + f"\n\nRuns: {notes}. Command: `python scripts/benchmarks.py run "
            "reproduce_speed --label <run> --cpu-kind <kind>` (machine "
            f"{record['machine']['cpu']}, {record['machine']['cores']} cores).")
    return {"headline": text}
