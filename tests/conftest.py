"""Shared test helpers: where the real motion capture lives, and a tiny hand-written BVH.

Real data (``../shared/data`` beside the repository, see its README) is found through the
environment variable ``STYLEMOTION_DATA``, falling back to ``<repo>/../shared/data``. When it is
missing, tests that need it are skipped on a workstation but FAIL under ``CI=true``, so that a CI
run can never pass by silently skipping them. Such tests carry the ``realdata`` marker.

The data is read in place (never copied into the repository).
"""

from __future__ import annotations

import os
import zipfile
from pathlib import Path

import pytest

REPO_ROOT = Path(__file__).resolve().parents[1]
DATA_ENV_VAR = "STYLEMOTION_DATA"

OTHER_SKELETONS = {
    # name → (file under other-skeletons/, built-in joint map, fps)
    "cmu21_walk": ("walk_21joint_60fps.bvh", "cmu21", 60.0),
    "cmu21_female_walk": ("female-walk_21joint_60fps.bvh", "cmu21", 60.0),
    "xia_cmu31": ("xia_neutral_01_000_31joint_120fps.bvh", "cmu31", 120.0),
}
BANDAI_ZIP = Path("bandai-namco-motion-2") / "data.zip"
#: Three Bandai members of different contents and styles (short ones, to keep tests fast).
BANDAI_MEMBERS = (
    "dataset-2_walk_normal_001.bvh",
    "dataset-2_run_feminine_021.bvh",
    "dataset-2_raise-up-left-hand_active_090.bvh",
)


def running_in_ci() -> bool:
    return os.environ.get("CI", "").strip().lower() in ("1", "true", "yes", "on")


def candidate_data_dir() -> Path:
    """The configured data folder (it may not exist)."""
    env = os.environ.get(DATA_ENV_VAR)
    return Path(env).expanduser() if env else (REPO_ROOT.parent / "shared" / "data")


def shared_data_dir(*required: str | os.PathLike) -> Path:
    """The real-data folder; skip the test (fail it under ``CI=true``) when it or a file is missing.

    Args:
        required: paths relative to the data folder that the test needs.
    """
    root = candidate_data_dir()
    missing = [root] if not root.is_dir() else [root / r for r in required if not (root / r).exists()]
    if missing:
        message = (
            f"real motion data not found: {', '.join(str(m) for m in missing)}. Set {DATA_ENV_VAR} to "
            "the folder holding bandai-namco-motion-2/ and other-skeletons/ (default: <repo>/../shared/data)."
        )
        if running_in_ci():
            pytest.fail(message + " (CI=true: real-data tests must not be skipped)", pytrace=False)
        pytest.skip(message)
    return root


@pytest.fixture(name="shared_data_dir", scope="session")
def _shared_data_dir_fixture() -> Path:
    return shared_data_dir()


@pytest.fixture(scope="session")
def other_skeleton_paths() -> dict[str, Path]:
    """name → path of the three non-Bandai BVH files."""
    root = shared_data_dir(*(Path("other-skeletons") / f for f, _, _ in OTHER_SKELETONS.values()))
    return {name: root / "other-skeletons" / f for name, (f, _, _) in OTHER_SKELETONS.items()}


@pytest.fixture(scope="session")
def bandai_zip_path() -> Path:
    return shared_data_dir(BANDAI_ZIP) / BANDAI_ZIP


@pytest.fixture(scope="session")
def bandai_zip(bandai_zip_path: Path):
    with zipfile.ZipFile(bandai_zip_path) as zf:
        yield zf


# ---------------------------------------------------------------------------------------------
# A tiny valid BVH, for bad-input tests and synthetic checks.

TINY_BVH_FRAMES = (
    (1.0, 90.0, -2.0, 10.0, 20.0, 30.0, 5.0, -5.0, 15.0, 0.0, 0.0, 0.0, -20.0, 10.0, 5.0),
    (1.5, 90.5, -1.0, 12.0, 18.0, 33.0, 6.0, -4.0, 14.0, 1.0, 2.0, 3.0, -25.0, 11.0, 4.0),
    (2.0, 91.0, 0.0, 14.0, 16.0, 36.0, 7.0, -3.0, 13.0, 2.0, 4.0, 6.0, -30.0, 12.0, 3.0),
)


def tiny_bvh_text(frames=TINY_BVH_FRAMES, frame_time: str = "0.0333333") -> str:
    """A valid 4-joint BVH (cm, Y up): Hips (6 channels, ZXY) → Spine → Head, and Hips → LeftLeg.

    15 channels per frame row. Tests locate lines by content, not by fixed numbers.
    """
    rows = "\n".join(" ".join(f"{v:.4f}" for v in row) for row in frames)
    return (
        "HIERARCHY\n"
        "ROOT Hips\n"
        "{\n"
        "\tOFFSET 0.0 0.0 0.0\n"
        "\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
        "\tJOINT Spine\n"
        "\t{\n"
        "\t\tOFFSET 0.0 20.0 1.0\n"
        "\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n"
        "\t\tJOINT Head\n"
        "\t\t{\n"
        "\t\t\tOFFSET 0.0 45.0 0.0\n"
        "\t\t\tCHANNELS 3 Zrotation Yrotation Xrotation\n"
        "\t\t\tEnd Site\n"
        "\t\t\t{\n"
        "\t\t\t\tOFFSET 0.0 15.0 0.0\n"
        "\t\t\t}\n"
        "\t\t}\n"
        "\t}\n"
        "\tJOINT LeftLeg\n"
        "\t{\n"
        "\t\tOFFSET 10.0 -5.0 0.0\n"
        "\t\tCHANNELS 3 Xrotation Yrotation Zrotation\n"
        "\t\tEnd Site\n"
        "\t\t{\n"
        "\t\t\tOFFSET 0.0 -80.0 0.0\n"
        "\t\t}\n"
        "\t}\n"
        "}\n"
        "MOTION\n"
        f"Frames: {len(frames)}\n"
        f"Frame Time: {frame_time}\n"
        f"{rows}\n"
    )


@pytest.fixture
def tiny_bvh() -> str:
    return tiny_bvh_text()


@pytest.fixture
def write_text(tmp_path: Path):
    """``write_text(text, name="bad.bvh") -> Path``: write a (possibly malformed) file to tmp_path."""

    def write(text: str | bytes, name: str = "bad.bvh") -> Path:
        path = tmp_path / name
        if isinstance(text, bytes):
            path.write_bytes(text)
        else:
            path.write_text(text)
        return path

    return write


def line_of(text: str, needle: str, occurrence: int = 0) -> int:
    """1-based number of the ``occurrence``-th line of ``text`` containing ``needle``."""
    hits = [i for i, line in enumerate(text.split("\n"), start=1) if needle in line]
    if len(hits) <= occurrence:
        raise AssertionError(f"{needle!r} occurs on {len(hits)} lines, wanted occurrence {occurrence}")
    return hits[occurrence]


# ---------------------------------------------------------------------------------------------
# One tiny finished stylemotion-reproduce run, trained once per test run (tests/reproduce_fixtures.py).


@pytest.fixture(scope="session")
def tiny_run(tmp_path_factory):
    """The shared tiny reproduce run (:class:`reproduce_fixtures.TinyRun`); tests that change a run copy it first
    (:func:`reproduce_fixtures.copy_run`)."""
    from reproduce_fixtures import train_tiny_run

    return train_tiny_run(tmp_path_factory.getbasetemp())
