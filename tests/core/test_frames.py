"""Frames: pyproj chains, ENU against PROJ's topocentric conversion, convergence, curvature."""

from __future__ import annotations

import numpy as np
import pytest
from lidarphoto.core.errors import CrsError
from lidarphoto.core.geometry.frames import NED_TO_ENU, LocalFrame, MappingFrame
from pyproj import Proj, Transformer

RNG = np.random.default_rng(11)
UTM23S = "EPSG:31983"  # SIRGAS 2000 / UTM zone 23S (GRS80), the paper's area


@pytest.fixture(scope="module")
def frame() -> MappingFrame:
    return MappingFrame.from_user_input(UTM23S)


def _points(n: int = 200) -> np.ndarray:
    return np.column_stack(
        [
            RNG.uniform(380e3, 420e3, n),
            RNG.uniform(7.52e6, 7.56e6, n),
            RNG.uniform(500, 3000, n),
        ]
    )


def test_round_trips(frame):
    p = _points()
    np.testing.assert_allclose(
        frame.geodetic_to_map(frame.map_to_geodetic(p)), p, atol=1e-8, rtol=0
    )
    # PROJ's geocentric inverse iterates: 1e-7 m absolute is ~1e-14 of the ECEF magnitudes
    ecef = frame.map_to_ecef(p)
    np.testing.assert_allclose(frame.ecef_to_map(ecef), p, atol=1e-7, rtol=0)
    local = LocalFrame.at_map_point(frame, p.mean(axis=0))
    enu = local.map_to_enu(p)
    np.testing.assert_allclose(local.enu_to_map(enu), p, atol=1e-7, rtol=0)
    np.testing.assert_allclose(local.ecef_to_enu(local.enu_to_ecef(enu)), enu, atol=1e-8, rtol=0)


def test_enu_matches_proj_topocentric(frame):
    p = _points()
    local = LocalFrame.at_map_point(frame, p[0])
    lat0, lon0, h0 = local.origin_llh
    peer = Transformer.from_pipeline(
        "+proj=pipeline +step +proj=unitconvert +xy_in=deg +xy_out=rad "
        "+step +proj=cart +ellps=GRS80 "
        f"+step +proj=topocentric +ellps=GRS80 +lat_0={lat0!r} +lon_0={lon0!r} +h_0={h0!r}"
    )
    llh = frame.map_to_geodetic(p)
    e, n, u = peer.transform(llh[:, 1], llh[:, 0], llh[:, 2])
    np.testing.assert_allclose(local.map_to_enu(p), np.column_stack([e, n, u]), atol=1e-6, rtol=0)
    np.testing.assert_allclose(local.map_to_enu(p[:1]), 0.0, atol=1e-8)


def test_grid_north_azimuth_matches_proj_factors(frame):
    llh = frame.map_to_geodetic(_points(20))
    ours = np.degrees(frame.grid_north_azimuth(llh))
    proj = Proj(frame.crs)
    factors = proj.get_factors(llh[:, 1], llh[:, 0])
    # PROJ's meridian_convergence has the opposite sign to our clockwise grid azimuth.
    np.testing.assert_allclose(ours, -np.asarray(factors.meridian_convergence), atol=1e-8)
    # textbook approximation for transverse Mercator: gamma ~ (lon - lon0) sin(lat)
    approx = -(llh[:, 1] - (-45.0)) * np.sin(np.radians(llh[:, 0]))
    np.testing.assert_allclose(ours, approx, atol=2e-3)


def test_map_enu_jacobians_are_inverse_and_carry_the_scale_factor(frame):
    p = _points(20)
    local = LocalFrame.at_map_point(frame, p[0])
    enu, j = local.map_to_enu_jacobian(p)
    np.testing.assert_allclose(enu, local.map_to_enu(p), atol=1e-9, rtol=0)
    back, jinv = local.enu_to_map_jacobian(enu)
    np.testing.assert_allclose(back, p, atol=1e-7, rtol=0)
    np.testing.assert_allclose(j @ jinv, np.broadcast_to(np.eye(3), j.shape), atol=1e-8)
    # a map metre is 1/k ground metres at the point (k: PROJ's point scale factor); the
    # ellipsoidal height maps 1:1 to the vertical up to the local tilt
    llh = frame.map_to_geodetic(p)
    k = np.asarray(Proj(frame.crs).get_factors(llh[:, 1], llh[:, 0]).meridional_scale)
    ground = np.linalg.svd(j[:, :, :2], compute_uv=False)  # stretch of map E and N, (20, 2)
    want = (1.0 + llh[:, 2] / 6.371e6) / k  # at height h a map metre spans (R + h) / R more
    np.testing.assert_allclose(ground, np.column_stack([want, want]), rtol=2e-5)
    assert local.map_to_enu_jacobian(np.empty((0, 3)))[1].shape == (0, 3, 3)


def test_grid_frame_axes_follow_the_grid(frame):
    p = np.array([[385000.0, 7530000.0, 900.0]])
    llh = frame.map_to_geodetic(p)
    local = LocalFrame(frame, tuple(llh[0]))
    # 50 m along grid north, seen in the ENU frame at p, is the grid frame's y axis.
    step = local.map_to_enu(p + [0.0, 50.0, 0.0])[0]
    predicted = local.grid_to_local(llh)[0] @ np.array([0.0, 1.0, 0.0])
    angle = np.arccos(np.dot(step[:2], predicted[:2]) / np.linalg.norm(step[:2]))
    assert angle < 1e-6
    assert abs(np.degrees(np.arctan2(predicted[0], predicted[1]))) > 0.1  # convergence is real


def test_local_vertical_tilts_with_distance(frame):
    centre = np.array([400000.0, 7540000.0, 900.0])
    local = LocalFrame.at_map_point(frame, centre)
    far = centre + [2000.0, 0.0, 0.0]
    llh = frame.map_to_geodetic(np.vstack([centre, far]))
    r = local.ned_to_local(llh)
    np.testing.assert_allclose(r[0], NED_TO_ENU, atol=1e-12)
    down_far = r[1] @ np.array([0.0, 0.0, 1.0])
    tilt = np.arctan2(-down_far[0], -down_far[2])
    # 2 km on a sphere of radius ~6.38e6 m: ~3.1e-4 rad (about 1 arc-minute)
    assert tilt == pytest.approx(2000.0 / 6.38e6, rel=0.01)
    # Earth curvature: a point 2 km away at the same height is ~0.31 m below the tangent plane
    assert local.map_to_enu(far[None])[0, 2] == pytest.approx(-(2000.0**2) / (2 * 6.38e6), rel=0.02)


@pytest.mark.parametrize(
    ("crs", "words"),
    [
        ("EPSG:4326", "must be projected"),
        ("EPSG:2994", "metres"),  # NAD83(CSRS) / Oregon Lambert (ft), the Autzen CRS
        ("EPSG:2154+5720", "grid"),  # Lambert-93 + NGF-IGN69: geoid grid not installed
        ("not a crs", "not a valid CRS"),
        ("", "missing"),
    ],
)
def test_bad_crs_is_explained(crs, words):
    with pytest.raises(CrsError, match=words):
        MappingFrame.from_user_input(crs)


def test_eo_map_local_round_trip(frame):
    from lidarphoto.core.geometry.rotations import matrix_to_opk
    from lidarphoto.core.photo.orientation import eo_local_to_map, eo_map_to_local

    xyz = _points(30)
    opk = np.column_stack(
        [RNG.uniform(-0.1, 0.1, 30), RNG.uniform(-0.1, 0.1, 30), RNG.uniform(-3, 3, 30)]
    )
    local = LocalFrame.at_map_point(frame, xyz.mean(axis=0))
    centres, m_local = eo_map_to_local(xyz, opk, local)
    xyz2, opk2 = eo_local_to_map(centres, m_local, local)
    np.testing.assert_allclose(xyz2, xyz, atol=1e-7)
    np.testing.assert_allclose(opk2, opk, atol=1e-12)
    # at the origin of the local frame, a level camera differs only by grid convergence:
    # grid azimuth = true azimuth + theta, so kappa in ENU = kappa in the grid frame + theta
    level = np.array([[0.0, 0.0, 0.7]])
    _, m0 = eo_map_to_local(local.enu_to_map(np.zeros((1, 3))), level, local)
    theta = frame.grid_north_azimuth(np.array([local.origin_llh]))[0]
    assert abs(theta) > 1e-3
    w, p, k = matrix_to_opk(m0[0])
    np.testing.assert_allclose([w, p, k], [0.0, 0.0, 0.7 + theta], atol=1e-12)


@pytest.mark.parametrize("code", ["EPSG:28992", "EPSG:2154", "EPSG:32633", "EPSG:3857",
                                  "ESRI:53004"])  # the last on a sphere
def test_ecef_conversions_equal_proj_search(code):
    """The geodetic <-> ECEF pipelines written directly give PROJ's own transformation (found
    by its search of the database) to the last bit."""
    from pyproj.transformer import TransformerGroup

    frame = MappingFrame.from_user_input(code)
    rng = np.random.default_rng(4)
    llh = np.column_stack([rng.uniform(-89, 89, 500), rng.uniform(-180, 180, 500),
                           rng.uniform(-500, 9000, 500)])  # fmt: skip
    to_ecef = TransformerGroup(frame.geodetic, frame.geocentric, always_xy=True)
    assert to_ecef.best_available
    want = np.column_stack(to_ecef.transformers[0].transform(llh[:, 1], llh[:, 0], llh[:, 2]))
    got = frame.geodetic_to_ecef(llh)
    np.testing.assert_array_equal(got, want)
    back = TransformerGroup(frame.geocentric, frame.geodetic, always_xy=True).transformers[0]
    lon, lat, h = back.transform(want[:, 0], want[:, 1], want[:, 2])
    np.testing.assert_array_equal(frame.ecef_to_geodetic(want), np.column_stack([lat, lon, h]))
