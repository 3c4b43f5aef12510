"""Keyframe solves scored as the σ_c choice scores them (stylemotion.morphable.heldout): a target the model can
reach is met without failure; a hand 3 m up is either missed (a large σ_c) or met by a code far off the mixture
(a small σ_c), and both count as failures."""

from __future__ import annotations

import numpy as np

from stylemotion.morphable.heldout import choose_constraint_scale, keyframe_errors, off_model_threshold
from stylemotion.skeleton import CANONICAL_JOINTS


def test_far_targets_fail_either_way_and_reachable_ones_do_not(left_model):
    j = CANONICAL_JOINTS.index("Hand_L")
    reachable = left_model.poses_at(left_model.gmm.sample(3, 7), [left_model.length - 1])[:, 0, j]
    limit = off_model_threshold(left_model)
    ok = keyframe_errors(left_model, reachable, "Hand_L", 0.005, off_model=limit)
    assert ok["failures"] == 0 and max(ok["errors_m"]) < 0.02 and max(ok["neg_log_prior"]) <= limit
    far = np.array([[0.0, 3.0, 0.5]])
    tight = keyframe_errors(left_model, far, "Hand_L", 0.002, off_model=limit, max_evaluations=50)
    loose = keyframe_errors(left_model, far, "Hand_L", 0.2, off_model=limit, max_evaluations=50)
    assert tight["failures"] == loose["failures"] == 1
    assert loose["missed"] == 1 and tight["neg_log_prior"][0] > loose["neg_log_prior"][0]
    if tight["missed"] == 0:
        assert tight["off_model"] == 1 and tight["neg_log_prior"][0] > limit
    choice = choose_constraint_scale(left_model, np.concatenate([reachable, far]), [0.002, 0.2], "Hand_L")
    assert {c["scale_m"] for c in choice["candidates"]} == {0.002, 0.2} and choice["chosen_m"] in (0.002, 0.2)
    assert all(c["failures"] == c["missed"] + c["off_model"] >= 1 for c in choice["candidates"])
