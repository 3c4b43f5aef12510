"""The window datamodule's ``exclude_styles``: the excluded style's takes leave every split after splitting (the
other takes keep the parts the full data gives them), the normalization statistics come from what is left, and a
style the data lacks is refused naming the key."""

from __future__ import annotations

import numpy as np
import pytest
from vae_fixtures import TINY_DATA, tiny_takeset

from stylemotion.datamodules.windows import MotionWindowDataModule, UnknownStyleError


def names(takes) -> list[str]:
    return sorted(t.name for t in takes)


def test_an_excluded_style_leaves_every_split_and_the_statistics() -> None:
    takeset = tiny_takeset()
    full = MotionWindowDataModule(takeset=takeset, split=TINY_DATA["split"], window_frames=30, stride=15)
    without = MotionWindowDataModule(takeset=takeset, split=TINY_DATA["split"], window_frames=30, stride=15,
                                     exclude_styles=["elderly"])
    full.setup("fit")
    without.setup("fit")
    reference = takeset.split(**TINY_DATA["split"])  # the full data's split, filtered here by hand
    for part in ("train", "val", "test"):
        kept = [t for t in reference[part] if t.labels["style"] != "elderly"]
        assert names(without.split_takes[part]) == names(kept) and len(kept) < len(reference[part])
        assert names(full.split_takes[part]) == names(reference[part])
    train = np.concatenate([t.frames for t in reference["train"] if t.labels["style"] != "elderly"])
    mean, std = without.normalization
    np.testing.assert_allclose(mean, train.mean(0), rtol=1e-4, atol=1e-5)
    np.testing.assert_allclose(std, np.maximum(train.std(0), 1e-3), rtol=1e-4, atol=1e-5)
    assert not np.allclose(mean, full.normalization[0], rtol=1e-3, atol=1e-4)
    assert without.hparams["exclude_styles"] == ["elderly"]  # what the checkpoint records


def test_an_unknown_excluded_style_is_refused_naming_the_key() -> None:
    dm = MotionWindowDataModule(takeset=tiny_takeset(), split=TINY_DATA["split"], exclude_styles=["feminine"])
    with pytest.raises(UnknownStyleError, match=r"datamodule.exclude_styles: style\(s\) \['feminine'\] are not in"):
        dm.setup("fit")
    with pytest.raises(UnknownStyleError, match=r"got the string 'elderly' \(write \[elderly\]\)"):
        MotionWindowDataModule(takeset=tiny_takeset(), exclude_styles="elderly")
    every = MotionWindowDataModule(takeset=tiny_takeset(), exclude_styles=["normal", "elderly", "youthful"])
    with pytest.raises(UnknownStyleError, match="leaves no style"):
        every.setup("fit")
