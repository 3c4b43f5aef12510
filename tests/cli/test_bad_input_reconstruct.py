"""``stylemotion-reconstruct markers=<take>:a-b`` (issue 26): a take's frame range is read like a file's, and a bad
range is named as a frame range (not as a file that must end in .bvh/.npz/.csv)."""

from __future__ import annotations

import pytest

from stylemotion.datasets.registry import load_dataset
from stylemotion.io.errors import UserInputError
from stylemotion.reconstruct.command import load_tracks

TAKE = "synthetic_walk_normal_000"


@pytest.fixture(scope="module")
def takeset():
    return load_dataset("synthetic", takes_per_pair=1)


def test_a_take_with_a_frame_range_gives_those_frames(takeset):
    tracks, take = load_tracks(f"{TAKE}:10-40", takeset, None)
    whole, _ = load_tracks(TAKE, takeset, None)
    assert take == TAKE and len(tracks.positions) == 30
    assert (tracks.positions == whole.positions[10:40]).all()


@pytest.mark.parametrize("suffix, message", [
    (":a-b", "the frame range 'a-b' must be START-END"),
    (":40-10", "the frame range 40-10 is empty"),
    (":0-99999", "runs past the take's"),
    (":abc", "after a take's name give a frame range START-END"),
])
def test_a_bad_range_of_a_take_is_named(takeset, suffix, message):
    with pytest.raises(UserInputError, match=f"markers={TAKE}{suffix}: .*{message}"):
        load_tracks(f"{TAKE}{suffix}", takeset, None)


def test_texture_reads_a_take_with_a_frame_range_and_names_a_bad_one(takeset):
    from stylemotion.reconstruct.texture import LEG_JOINTS
    from stylemotion.reconstruct.texture_command import load_motion

    motion, truth, take = load_motion(f"{TAKE}:10-40", takeset, LEG_JOINTS)
    whole = next(t for t in takeset.takes if t.name == TAKE).positions
    assert take == TAKE and motion.shape == (30, *whole.shape[1:]) and (motion == whole[10:40]).all()
    assert (truth == motion).all()
    for suffix, message in [(":40-10", "empty"), (":0-99999", "runs past the take's"), (":abc", "START-END")]:
        with pytest.raises(UserInputError, match=f"motion={TAKE}{suffix}: .*{message}"):
            load_motion(f"{TAKE}{suffix}", takeset, LEG_JOINTS)
