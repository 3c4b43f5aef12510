import numpy as np
import pytest
from dtaidistance import dtw_ndim

from stylemotion.multilinear.warping import (
    banded_dtw,
    cosine_cost,
    full_dtw,
    multiscale_dtw,
    path_to_warp,
    warp_positions,
)


def unit(x):
    return x / np.linalg.norm(x, axis=1, keepdims=True)


@pytest.mark.parametrize("n,m", [(30, 41), (57, 33), (120, 100)])
def test_one_scale_is_plain_dtw(n, m):
    """On unit vectors the cosine cost is half the squared distance: dtaidistance's path is the reference."""
    rng = np.random.default_rng(n)
    v, w = rng.normal(size=(n, 5)), rng.normal(size=(m, 5))
    want = np.asarray(dtw_ndim.warping_path(unit(v), unit(w)))
    got = full_dtw(v, w)
    assert np.array_equal(got.path, want)
    assert got.cost == pytest.approx(dtw_ndim.distance(unit(v), unit(w)) ** 2 / 2, rel=1e-9)
    one = multiscale_dtw(v, w, levels=1)
    assert np.array_equal(one.path, want) and one.cells == n * m
    wide = multiscale_dtw(v, w, levels=3, radius=max(n, m))     # a band that holds every cell
    assert np.array_equal(wide.path, want)


def test_multiscale_evaluates_fewer_cells_and_finds_a_near_optimal_path():
    rng = np.random.default_rng(5)
    base = np.cumsum(rng.normal(size=(400, 4)), axis=0)          # smooth, so coarse levels mean something
    warp = np.linspace(0, 1, 330) ** 1.3 * 399
    other = np.stack([np.interp(warp, np.arange(400), base[:, c]) for c in range(4)], axis=1)
    full, multi = full_dtw(base, other), multiscale_dtw(base, other, levels=4, radius=2)
    assert multi.cells < full.cells / 4
    assert full.cost - 1e-9 <= multi.cost <= full.cost * 1.05 + 1e-9
    assert tuple(multi.path[0]) == (0, 0) and tuple(multi.path[-1]) == (399, 329)
    assert np.all(np.diff(multi.path, axis=0) >= 0)


def test_a_known_time_stretch_is_recovered():
    """The example is the reference played on a known clock; the warping function follows that clock."""
    t = np.linspace(0, 4 * np.pi, 200)
    ref = np.stack([np.sin(t), np.cos(t), np.sin(2 * t) + 0.1], axis=1)
    clock = np.linspace(0, 1, 150) ** 0.8 * 199                   # example frame j shows reference time clock[j]
    example = np.stack([np.interp(clock, np.arange(200), ref[:, c]) for c in range(3)], axis=1)
    alignment = multiscale_dtw(ref, example, levels=3, radius=2)
    w = path_to_warp(alignment.path, 200, 150)
    truth = np.interp(np.arange(200), clock, np.arange(150))      # the inverse clock
    assert np.abs(w - truth).mean() < 1.0


def test_cost_band_and_positions():
    assert np.allclose(cosine_cost(np.array([[1.0, 0], [0, 0]]), np.array([[1.0, 0], [-1, 0]])),
                       [[0, 2], [0, 0]])
    with pytest.raises(ValueError, match="band"):
        banded_dtw(lambda i, a, b: np.zeros(b - a), 3, 3, lo=np.array([1, 1, 1]), hi=np.array([3, 3, 3]))
    p = np.arange(3 * 21 * 3, dtype=float).reshape(3, 21, 3)
    assert np.allclose(warp_positions(p, np.array([0.0, 0.5, 2.0])), np.stack([p[0], (p[0] + p[1]) / 2, p[2]]))
