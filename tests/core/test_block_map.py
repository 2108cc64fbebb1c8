"""The block map of the bundle report: footprints and overlap against the geometry."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.collinearity import project
from lidarphoto.core.geometry.distortion import BrownConrady
from lidarphoto.core.quality.block_map import BlockMap, block_map_svg, footprints, overlap_counts

CAM = Camera("c", 8.8, 0.0024, 4000, 3000, 0.03, -0.02, BrownConrady(k1=-1e-3))


def test_footprint_corners_project_back_to_the_frame_corners():
    eo = np.array([[1000.0, 2000.0, 150.0, 0.05, -0.08, 0.7],
                   [1050.0, 2010.0, 160.0, -0.2, 0.1, -2.0]])  # fmt: skip
    corners = np.array([[0.0, 0.0], [4000, 0], [4000, 3000], [0, 3000]])
    for row, fp in zip(eo, footprints([CAM, CAM], eo, 20.0)):
        ground = np.column_stack([fp, np.full(4, 20.0)])
        assert np.allclose(project(ground, row, CAM), corners, atol=1e-6)


def test_a_view_above_the_horizon_or_below_the_plane_has_no_footprint():
    oblique = np.array([[0.0, 0.0, 100.0, np.radians(80.0), 0.0, 0.0]])  # top edge looks up
    assert footprints([CAM], oblique, 0.0) == [None]
    below = np.array([[0.0, 0.0, 10.0, 0.0, 0.0, 0.0]])
    assert footprints([CAM], below, 20.0) == [None]


def test_overlap_counts_the_footprints_over_each_point():
    eo = np.array([[x, 0.0, 100.0, 0.0, 0.0, 0.0] for x in (0.0, 40.0, 80.0)])
    prints = [p for p in footprints([CAM] * 3, eo, 0.0) if p is not None]
    # nadir 4000 px x 0.0024 mm at 1:11,364 is 109.1 m wide: 0 is under images 1 and 2,
    # 40 under all three, 110 under image 3 only, 200 under none
    e = np.array([0.0, 40.0, 110.0, 200.0])
    assert overlap_counts(prints, e, np.zeros(4)).tolist() == [2, 3, 1, 0]
    svg = block_map_svg(BlockMap(eo[:, :2], prints, np.zeros((0, 2)), np.zeros((0, 2)),
                                 np.zeros((0, 2))), title="m")  # fmt: skip
    ET.fromstring(svg)
    assert "#6baed6" in svg  # the three-image strip
