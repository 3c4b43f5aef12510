"""Suite ``annotate_actors``: annotation by motion templates across actors inside Bandai (issue 24 item 6:
templates from other actors beside templates that saw the document's actor; issue 28 item 5's aim counted).

    python scripts/benchmarks.py run annotate_actors

Bandai dataset-2's three actors are told apart by the rest poses of their files
(:func:`stylemotion.datasets.actors.actor_groups`, suite ``actors``), and every actor performed every content.
Per seed and left-out actor, the documents are that actor's **test** takes (Bandai's split,
``configs/data/bandai.yaml``), every take once in a seeded order, joined by 8 unlabelled blend frames into documents
of at least 40 s, and the same takes cut to their middle 2–3 s and joined the same way (suite ``annotate``'s two
kinds, :func:`suites.annotate.seed_documents`' recipe). Each document is annotated as ``stylemotion-annotate``
annotates a user's file (:func:`stylemotion.annotate.command.annotate_positions`, every setting at its default,
chosen on validation documents by suite ``annotate``) with templates learned as ``stylemotion-annotate learn`` does
(9 train takes per content, drawn with the seed) from

* **cross-actor**: the train takes of the *other* actors;
* **same-actor**: the train takes of every actor (suite ``annotate``'s templates: easier).

Scores are Table 3.2's (frames: P1/R1/F1; segments: F2), pooled over a seed's documents of one kind; R1, the share
of take frames (blend frames are unlabelled truth) labelled with their take's class, is issue 28 item 5's figure.
Nothing is chosen here.
"""

from __future__ import annotations

import argparse
from typing import Any

import numpy as np
from suites.annotate import CUT_FRAMES, cut_takes, load_bandai, pooled_scores, take_pool
from suites.common import fmt, fmt_spread, md_table, provenance_line, spread, take_split_record

DESCRIPTION = ("annotation across Bandai's actors: templates from the other actors beside templates that saw the "
               "document's actor, on that actor's test takes")
DEFAULT_SEEDS = (0, 1, 2)
ARMS = ("cross_actor", "same_actor")
KINDS = {"takes": "whole test takes", "cuts": f"their middle {CUT_FRAMES[0] // 30}–{CUT_FRAMES[1] // 30} s"}
#: Issue 28 item 5's aim: share of take frames labelled with the right class.
AIM = 0.8


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--seconds", type=float, default=40.0, help="least length of a document, s")
    parser.add_argument("--blend", type=int, default=8, help="unlabelled blend frames between two takes")
    parser.add_argument("--per-class", type=int, default=9, help="train takes averaged into each template")


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    from stylemotion.annotate.command import annotate_positions
    from stylemotion.annotate.documents import partition_documents
    from stylemotion.annotate.model import learn_model
    from stylemotion.datasets.actors import actor_groups

    takeset, split, split_cfg = load_bandai()
    fps = float(takeset.fps)
    groups = actor_groups(takeset.takes)
    actors = [groups.styles[g] for g in sorted(groups.styles)]
    rows = []
    for seed in seeds:
        same = learn_model(split["train"], fps, args.per_class, seed, tensors=False)
        for a, styles in enumerate(actors):
            cross = learn_model([t for t in split["train"] if t.style not in styles], fps, args.per_class, seed,
                                tensors=False)
            rng = np.random.default_rng([seed, a])
            pool = take_pool([t for t in split["test"] if t.style in styles], 1.0, rng)
            docs = {"takes": partition_documents(pool, fps, args.seconds, rng, args.blend),
                    "cuts": partition_documents(cut_takes(pool, np.random.default_rng([seed, a, 3])), fps, args.seconds,
                                                rng, args.blend)}
            for arm, model in (("cross_actor", cross), ("same_actor", same)):
                for kind, documents in docs.items():
                    preds = [annotate_positions(d.positions, model)[0] for d in documents]
                    rows.append({"seed": seed, "actor": styles, "arm": arm, "kind": kind, "documents": len(documents),
                                 "takes": len(pool), "frames": sum(len(d.labels) for d in documents),
                                 **pooled_scores(documents, preds)})
            print(f"seed {seed} actor {'/'.join(styles)}: R1 cross {rows[-4]['R1']:.3f}, same {rows[-2]['R1']:.3f}",
                  flush=True)
    return {"actors": actors, "rows": rows, "settings": {"seconds": args.seconds, "blend": args.blend,
                                                           "per_class": args.per_class},
            "splits": {"kind": "Bandai's take split (configs/data/bandai.yaml); actors by rest pose",
                       "documents": "the left-out actor's test takes", "templates": "train takes",
                       "parts": take_split_record(split, split_cfg["seed"], split_cfg["val_fraction"],
                                                  split_cfg["test_fraction"])}}


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    table = []
    summary = {}
    for styles in r["actors"]:
        for kind in KINDS:
            for arm, text in (("cross_actor", "other actors"), ("same_actor", "every actor")):
                rows = [x for x in r["rows"] if x["actor"] == styles and x["kind"] == kind and x["arm"] == arm]
                summary.setdefault((kind, arm), []).append(spread([x["R1"] for x in rows])["mean"])
                table.append(["/".join(styles), KINDS[kind], text,
                              *(fmt_spread(spread([x[s] for x in rows]), 3) for s in ("R1", "P1", "F1", "F2"))])
    met = {key: sum(v >= AIM for v in values) for key, values in summary.items()}
    n = len(r["actors"])
    text = (md_table(["left-out actor (styles)", "documents", "templates from",
                      "R1: take frames labelled right", "P1", "F1", "F2"], table)
            + f"\n\nPer seed and actor: the actor's test takes in documents of ≥ {fmt(r['settings']['seconds'], 0)} s "
            f"joined by {r['settings']['blend']} blend frames (and the same takes cut short), annotated with "
            f"`stylemotion-annotate`'s defaults by templates of {r['settings']['per_class']} train takes per content; "
            f"mean ± sd over {len(record.get('seeds') or [])} seeds. Issue 28 item 5's aim (≥ {AIM:.0%} of take "
            f"frames labelled right), actors meeting it on their mean: whole takes {met[('takes', 'cross_actor')]} of "
            f"{n} with templates from other actors ({met[('takes', 'same_actor')]} of {n} from every actor); short "
            f"cuts {met[('cuts', 'cross_actor')]} of {n} ({met[('cuts', 'same_actor')]} of {n}). "
            f"{provenance_line(record)}")
    return {"headline": text}
