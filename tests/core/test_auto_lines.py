"""Automatic line observations (core.photo.auto_lines) on images rendered with the project's
renderer, whose ridges and hips are the projections of the LiDAR lines to a fraction of a px."""

from __future__ import annotations

import numpy as np
import pytest
from lidarphoto.core.photo.auto_lines import AutoLineOptions, line_observations
from lidarphoto.core.photo.picking import PickingScene
from test_render import _table, hip  # noqa: F401  (hip: the rendered hip-roof fixture)


@pytest.fixture(scope="module")
def house(hip):  # noqa: F811
    """The rendered hip roof of test_render: camera, EO, image, LiDAR lines."""
    _, cam, table, img, _, lines, _ = hip
    return cam, table, img, lines


def _distance_to_truth(obs, table, cam, lines):
    """Perpendicular distance (px) of each observation from its line's TRUE projection."""
    sc = PickingScene(table, cam)
    by_id = {str(ln.id): ln for ln in lines}
    out = []
    for tid, p in zip(obs.target_id, obs.pixels):
        ln = by_id[tid]
        t = np.linspace(0, 1, 2001)[:, None]
        proj = sc.project("img", ln.start + t * (ln.end - ln.start))
        out.append(np.min(np.linalg.norm(proj - p, axis=1)))
    return np.array(out)


def test_exact_orientation_points_on_the_projected_lines(house):
    cam, table, img, lines = house
    obs = line_observations(img.rgb, "img", cam, table, lines)
    assert set(obs.type) == {"line"} and len(set(obs.point_id)) == len(obs)
    assert set(obs.target_id) == {str(ln.id) for ln in lines}
    d = _distance_to_truth(obs, table, cam, lines)
    assert len(obs) >= 50
    assert np.median(d) < 0.25, np.median(d)
    assert np.percentile(d, 95) < 3 * np.median(obs.sigma_px) + 0.25


def test_perturbed_orientation_still_finds_the_true_edges(house):
    cam, table, img, lines = house
    wrong = _table(table.xyz[0], np.degrees(table.opk[0]) + [0.03, -0.03, 0.02])  # ~4 px
    obs = line_observations(img.rgb, "img", cam, wrong, lines, AutoLineOptions(search_px=8.0))
    assert len(obs) >= 30
    d = _distance_to_truth(obs, table, cam, lines)  # distance to the TRUE projection
    assert np.median(d) < 0.5, np.median(d)


def test_absent_line_gives_nothing(house):
    cam, table, img, lines = house
    flat = np.full(img.rgb.shape[:2], 100.0)  # no edge anywhere
    assert len(line_observations(flat, "img", cam, table, lines)) == 0
