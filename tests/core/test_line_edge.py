"""core.photo.line_edge: a click refined onto a straight edge of the image.

Truth: edges rendered analytically (a blurred step: the normal CDF of the signed distance from
a known line at each pixel centre) at random angles and sub-pixel positions, with noise."""

from __future__ import annotations

import math

import numpy as np
from lidarphoto.core.photo.line_edge import refine_edge_point
from scipy.special import ndtr


def _edge_image(angle: float, c: np.ndarray, blur: float, noise: float, rng) -> np.ndarray:
    """60 x 60 image: 50 grey on one side of the line through ``c`` (image pixels) at
    ``angle``, 150 on the other, blurred by a Gaussian of ``blur`` px, plus noise."""
    rows, cols = np.mgrid[0:60, 0:60] + 0.5  # pixel centres
    n = np.array([-math.sin(angle), math.cos(angle)])
    dist = (cols - c[0]) * n[0] + (rows - c[1]) * n[1]
    return 50.0 + 100.0 * ndtr(dist / blur) + rng.normal(0, noise, dist.shape)


def test_refined_click_lies_on_the_edge_within_a_tenth_of_a_pixel():
    rng = np.random.default_rng(3)
    errors = []
    for _ in range(50):
        angle = rng.uniform(0, math.pi)
        c = rng.uniform(25, 35, 2)
        img = _edge_image(angle, c, blur=0.8, noise=2.0, rng=rng)
        d = np.array([math.cos(angle), math.sin(angle)])
        n = np.array([-d[1], d[0]])
        click = c + rng.uniform(-2.5, 2.5) * n + rng.uniform(-3, 3) * d
        # the direction given is the predicted line's: a few degrees off the edge's
        off = math.radians(rng.uniform(-3, 3))
        guess = np.array([math.cos(angle + off), math.sin(angle + off)])
        p = refine_edge_point(img, (0, 0), click, guess)
        assert p is not None
        errors.append(abs((p - c) @ n))
        # it moved across the predicted direction only
        assert abs((p - click) @ guess) < 1e-9
    errors = np.array(errors)
    # the click was up to 2.5 px off; the edge's position comes back within 0.1 px (a 3 deg
    # direction error at up to 3 px along adds up to 0.16 px across: the RMS stays below 0.1)
    assert np.sqrt(np.mean(errors**2)) < 0.1 and errors.max() < 0.25, errors


def test_no_edge_or_outside_the_window_gives_none():
    rng = np.random.default_rng(4)
    flat = np.full((60, 60), 100.0)
    assert refine_edge_point(flat, (0, 0), (30, 30), (1, 0)) is None
    img = _edge_image(0.0, np.array([30.0, 30.0]), 0.8, 0.0, rng)
    # the edge 10 px away: beyond the 4 px search
    assert refine_edge_point(img, (0, 0), (30, 40), (1, 0)) is None
    assert refine_edge_point(img, (0, 0), (1.0, 30.0), (0, 1)) is None  # off the window
    assert refine_edge_point(img, (0, 0), (30, 30), (0, 0)) is None
    # the window's origin: the same edge in a window cut at (10, 20) gives the same point
    full = refine_edge_point(img, (0, 0), (30, 31.2), (1, 0))
    cut = refine_edge_point(img[20:, 10:], (10, 20), (30, 31.2), (1, 0))
    np.testing.assert_allclose(cut, full, atol=1e-12)
    assert abs(full[1] - 30.0) < 0.02
