"""The split-sample check of point matches (core/photo/match_accuracy.py) against a known
truth: exact matches of a plane under a known homography plus known noise (and wrong matches,
and a smooth departure from the homography) must give back the known match error."""

from __future__ import annotations

import numpy as np
import pytest
from lidarphoto.core.photo.match_accuracy import (
    apply_homography,
    checkerboard_halves,
    fit_homography,
    homography_difference,
    split_sample_residuals,
)

#: the published boat 1->2 homography (zoom 0.885, rotation 14 degrees, slight perspective)
H = np.array([[0.85828552, 0.21564369, 9.9101418], [-0.2115844, 0.8587636, 130.47838],
              [2.0702435e-06, 1.2886110e-06, 1.0]])  # fmt: skip
SHAPE = (680, 850)  # rows, columns of image 1


def _grid(step=12.0, margin=30.0):
    rr, cc = np.mgrid[margin : SHAPE[0] - margin : step, margin : SHAPE[1] - margin : step]
    return np.column_stack([cc.ravel(), rr.ravel()]).astype(np.float64)


def _rayleigh_median_se(n):
    """Relative standard error of the sample median of n Rayleigh distances: 0.72 / sqrt(n)."""
    return 0.72 / np.sqrt(n)


@pytest.mark.parametrize("sigma", [0.02, 0.05, 0.2])
def test_split_sample_recovers_a_known_match_error(sigma):
    """Exact matches + N(0, sigma) per axis, 5 % wrong by 2-10 px: the split-sample median is
    the true median error of the same points within 3 of its standard errors plus what the
    fit's own noise adds (8 parameters from ~1,500 points: under 1 %), and both equal the
    Rayleigh median 1.1774 sigma within the sampling error."""
    rng = np.random.default_rng(7)
    src = _grid()
    err = rng.normal(0, sigma, src.shape)
    wrong = rng.random(len(src)) < 0.05
    err[wrong] = rng.uniform(2, 10, (wrong.sum(), 1)) * rng.choice([-1, 1], (wrong.sum(), 2))
    dst = apply_homography(H, src) + err
    res = split_sample_residuals(src, dst, block=64.0)
    split_med = np.median(np.hypot(*res.T))
    true_med = np.median(np.hypot(*err.T))
    tol = 3 * _rayleigh_median_se(len(src)) + 0.01
    assert abs(split_med / true_med - 1) < tol, (split_med, true_med, tol)
    good = np.median(np.hypot(*err[~wrong].T))
    assert abs(good / (1.1774 * sigma) - 1) < 3 * _rayleigh_median_se((~wrong).sum())
    # the robust fit itself: the wrong matches left out, H recovered to sigma / sqrt(n) scale
    h, kept = fit_homography(src, dst)
    assert not kept[wrong].any() and kept[~wrong].mean() > 0.97
    _, diff = homography_difference(h, H, SHAPE, 20.0)
    assert np.hypot(*diff.T).max() < 10 * sigma / np.sqrt(len(src)) * 3


def test_a_wrong_model_only_inflates_the_split_sample_median():
    """A smooth departure from the homography (a radial term reaching 2 px at the corners,
    as lens distortion would) with 0.05 px of match noise: the split-sample median with a
    homography lies above the true median (the upper bound), the one with the cubic
    correction comes back to it within the sampling error."""
    rng = np.random.default_rng(11)
    src = _grid(10.0)
    err = rng.normal(0, 0.05, src.shape)
    q = apply_homography(H, src)
    centre = np.array([425.0, 340.0])
    rad = (q - centre) / 550.0
    distortion = 2.0 * rad * (rad**2).sum(axis=1, keepdims=True)
    dst = q + distortion + err
    true_med = np.median(np.hypot(*err.T))
    plain = np.median(np.hypot(*split_sample_residuals(src, dst, 64.0).T))
    cubic = np.median(np.hypot(*split_sample_residuals(src, dst, 64.0, degree=3).T))
    assert plain > 1.2 * true_med, (plain, true_med)
    assert abs(cubic / true_med - 1) < 3 * _rayleigh_median_se(len(src)) + 0.02, (cubic, true_med)


def test_checkerboard_halves_are_balanced_and_blockwise():
    src = _grid(8.0)
    black = checkerboard_halves(src, 64.0)
    assert 0.45 < black.mean() < 0.55
    # every 64 px block is one colour
    blocks = np.floor(src / 64.0).astype(int)
    for key in {tuple(b) for b in blocks[:50]}:
        inside = (blocks == key).all(axis=1)
        assert black[inside].all() or not black[inside].any()


def test_too_few_matches_agreeing_is_an_error_not_a_homography():
    """Three of five matches exact, two far off: the start's median residual is 0, so fewer
    than 4 matches are kept; the fit refuses instead of returning a homography."""
    src = np.array([[10.0, 10.0], [300.0, 20.0], [40.0, 400.0], [350.0, 380.0], [200.0, 200.0]])
    dst = apply_homography(H, src)
    dst[3:] += 25.0
    with pytest.raises(ValueError, match="3 of 5 matches agree"):
        fit_homography(src, dst, start=H)
