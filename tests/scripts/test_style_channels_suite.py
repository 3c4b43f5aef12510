"""Suite ``style_channels`` (scripts/suites/style_channels.py): the figures a case reads from a report, the rule
(eligibility against the default, then aims met, then capped variation), the shared stages and the block (hand-made
reports, no training)."""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import style_channels  # noqa: E402


def report(rows: list[str], share: float, v: float, step: float, div: float) -> dict:
    """A report of one stance with styles a and b, both with the same figures; ``rows``: rows on the diagonal."""
    styles = ("a", "b")
    return {"table_5_1": {"p": {"diagonal": {"rows": rows}}},
            "style_recognition": {"per_model_detail": {"p": {s: {"share": share} for s in styles}}},
            "variation_vs_style": {"p": {s: {"v_sd": v, "step_sd": step, "diversity": div} for s in styles}},
            "foot_skating_detail": {"p": {s: {"samples": {"ratio": 0.3}, "real": {"ratio": 0.1}} for s in styles}}}


def test_a_case_meets_the_aims_only_with_every_figure_and_its_row() -> None:
    good = style_channels.case_figures(report(["a"], 0.95, 0.9, 0.85, 0.75), ["a", "b"])
    assert good["p/a"]["meets_aims"] and not good["p/b"]["meets_aims"]  # b's row is off the diagonal
    assert good["p/a"]["skating_samples"] == 0.3 and good["p/a"]["skating_real"] == 0.1
    for low in ({"share": 0.89}, {"v": 0.79}, {"step": 0.79}, {"div": 0.69}):
        figures = {"share": 0.95, "v": 0.9, "step": 0.85, "div": 0.75} | low
        case = style_channels.case_figures(report(["a", "b"], figures["share"], figures["v"], figures["step"],
                                                  figures["div"]), ["a"])["p/a"]
        assert not case["meets_aims"], low


def summaries(**candidates: tuple[list[str], float, float]) -> dict:
    return {name: style_channels.candidate_summary(list(style_channels.case_figures(
        report(rows, share, v, 0.5, 0.5), ["a", "b"]).values())) for name, (rows, share, v) in candidates.items()}


def test_the_rule_keeps_the_default_unless_an_eligible_candidate_varies_more() -> None:
    # more variation but a row lost: not eligible, the default stays
    got = style_channels.choose(summaries(all=(["a", "b"], 0.95, 0.2), pose=(["a"], 0.95, 0.6)))
    assert got["eligible"] == {"all": True, "pose": False} and got["chosen"] == "all"
    # more variation, the rows kept, recognition above 0.9 though below the default's: chosen
    got = style_channels.choose(summaries(all=(["a", "b"], 0.99, 0.2), pose=(["a", "b"], 0.91, 0.6)))
    assert got["recognition_floor"] == 0.9 and got["chosen"] == "pose"
    # recognition below both 0.9 and the default's: not eligible
    got = style_channels.choose(summaries(all=(["a", "b"], 0.85, 0.2), pose=(["a", "b"], 0.80, 0.6)))
    assert got["eligible"]["pose"] is False and got["chosen"] == "all"
    # variation capped at the real clips' own: 1.5 is no better than 1.0, so the default (first) is kept on a tie
    got = style_channels.choose(summaries(all=(["a", "b"], 0.95, 1.0), pose=(["a", "b"], 0.95, 1.5)))
    assert got["chosen"] == "all"


def test_shared_stages_are_copied_once_and_never_over_a_folder(tmp_path: Path) -> None:
    first, out = tmp_path / "all", tmp_path / "pose"
    (first / "autoencoder").mkdir(parents=True)
    (first / "autoencoder" / "done.json").write_text("{}")
    (first / "cvae").mkdir()
    out.mkdir()
    assert style_channels.share_stages(first, out) == ["autoencoder"]
    assert (out / "autoencoder" / "done.json").read_text() == "{}" and not (out / "cvae").exists()
    (out / "autoencoder" / "done.json").write_text("mine")
    assert style_channels.share_stages(first, out) == []
    assert (out / "autoencoder" / "done.json").read_text() == "mine"


def test_the_block_marks_the_choice_and_the_protocol() -> None:
    cases = {name: {"cases": {f"p/{s}": c for s, c in zip("ab", style_channels.case_figures(
        report(["a", "b"], 0.95, v, 0.5, 0.5), ["a", "b"]).values())}} for name, v in (("all", 0.2), ("pose", 0.6))}
    results = {"data": "bandai", "candidates": style_channels.CANDIDATES, "aims": style_channels.AIMS,
               "overrides": [], "per_seed": {"100": cases},
               "summary": summaries(all=(["a", "b"], 0.95, 0.2), pose=(["a", "b"], 0.95, 0.6))}
    results["choice"] = style_channels.choose(results["summary"])
    record = {"suite": "style_channels", "command": "c", "commit": "0" * 40, "started": "2026-12-07T03:00:00",
              "machine": {"cpu": "x", "cores": 2}, "seeds": [100], "seconds": 1.0, "results": results}
    blocks = style_channels.render(record)
    assert "Chosen: **pose**: pose is chosen over the config's all." in blocks["headline"]
    assert "| **pose** | model.style_channels=pose | 2/2 | 0/2 |" in blocks["headline"]
    assert "`evaluation.heldout_splits=[val]`" in blocks["headline"] and "Not the full budget" not in \
        blocks["headline"]
    assert "| p/a | ✓ 0.95 0.20 0.50 0.50 | ✓ 0.95 0.60 0.50 0.50 |" in blocks["cases"]
    assert "pose V_SD 0.60 / step_SD 0.50 / diversity 0.50 of the style's clips, recognized 95 %, rows on the " \
           "diagonal 2/2" in blocks["line"] and "Chosen: **pose**." in blocks["line"]


def test_a_tie_in_variation_goes_to_the_cheaper_candidate() -> None:
    both = summaries(all=(["a", "b"], 0.95, 0.2), pose=(["a", "b"], 0.95, 0.6), cheap=(["a", "b"], 0.95, 0.58))
    both["all"]["cvae_minutes"], both["pose"]["cvae_minutes"], both["cheap"]["cvae_minutes"] = 10.0, 25.0, 12.0
    got = style_channels.choose(both)  # log 0.58 is within TIE of log 0.6 (mean over three ratios, two fixed)
    assert got["tied"] == ["pose", "cheap"] and got["chosen"] == "cheap"
    both["cheap"] = summaries(cheap=(["a", "b"], 0.95, 0.3))["cheap"] | {"cvae_minutes": 12.0}
    assert style_channels.choose(both)["chosen"] == "pose"  # outside the tie band the variation decides
