"""The automatic AP selection of the bundle adjustment (core/photo/bundle_selection.py):
a correlation alone never drops a parameter; an AP is dropped only when insignificant alone
and, with the insignificant APs it correlates with, jointly.

Simulated close-range networks: a 3D target field of 2 x 2 x 0.6 m seen by convergent images
of one camera (12 x 8 mm sensor, f = 8 mm) from 2.2 m, Brown-Conrady distortion inserted,
0.1 px image noise, control points at 0.05 mm. The strong network has 24 images from twelve
directions, each at two roll angles; the weak one 6 images from one side at one roll.
Tolerances follow from the noise: recovered APs within 3 a-posteriori sigmas.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.collinearity import project_with_status
from lidarphoto.core.geometry.distortion import BrownConrady
from lidarphoto.core.geometry.frames import LocalFrame, MappingFrame
from lidarphoto.core.geometry.rotations import matrix_to_opk
from lidarphoto.core.photo.bundle import bundle_adjust
from lidarphoto.core.photo.bundle_selection import ap_decisions
from lidarphoto.core.photo.bundle_setup import BundleOptions, GroundPoints
from lidarphoto.core.photo.observations import ImageObservations
from lidarphoto.core.photo.orientation import ExteriorOrientationTable, eo_local_to_map

#: the inserted lens (mm units): in the image corner (r = 7.2 mm) k1 28 px, k2 -10 px, k3 7 px
#: and 0.3 px of decentring
LENS = {"k1": 3.0e-4, "k2": -2.0e-6, "k3": 3.0e-8, "p1": 2.0e-5, "p2": -1.5e-5}
SIGMA_PX = 0.1


def _look_at(centre: np.ndarray, target: np.ndarray, roll: float) -> np.ndarray:
    """World-to-camera rotation ``M`` (as ``opk_to_matrix``) of a camera at ``centre`` looking
    at ``target`` (camera z axis pointing back from the scene, x right, y up), turned by
    ``roll`` about its axis."""
    z = centre - target
    z /= np.linalg.norm(z)
    x = np.cross([0.0, 0.0, 1.0], z)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    c, s = math.cos(roll), math.sin(roll)
    return np.column_stack([c * x + s * y, -s * x + c * y, z]).T


def _network(azimuths_deg, rolls_deg, lens: dict, seed: int, sigma_px: float = SIGMA_PX):
    rng = np.random.default_rng(seed)
    mapping = MappingFrame.from_user_input("EPSG:25832")
    local = LocalFrame.at_map_point(mapping, np.array([500000.0, 5600000.0, 100.0]))
    nominal = Camera("cam", 8.0, 0.004, 3000, 2000)
    true_cam = Camera("cam", 8.03, 0.004, 3000, 2000, x0_mm=0.021, y0_mm=-0.015,
                      distortion=BrownConrady(**lens))  # fmt: skip
    n_pts = 250
    pts = np.column_stack([rng.uniform(-1, 1, n_pts), rng.uniform(-1, 1, n_pts),
                           rng.uniform(-0.3, 0.3, n_pts)])  # fmt: skip
    poses = []
    for az in azimuths_deg:
        a = math.radians(az)
        centre = 2.2 * np.array([math.cos(a) * math.cos(0.6), math.sin(a) * math.cos(0.6),
                                 math.sin(0.6)])  # fmt: skip
        for roll in rolls_deg:
            poses.append((centre, _look_at(centre, np.zeros(3), math.radians(roll))))
    names = tuple(f"IMG{k:02d}" for k in range(len(poses)))
    img, pid, px = [], [], []
    for k, (centre, M) in enumerate(poses):
        eo = np.concatenate([centre, matrix_to_opk(M)])
        u, front, conv = project_with_status(pts, eo, true_cam)
        ok = front & conv & true_cam.in_frame(u, 20.0)
        img += [names[k]] * int(ok.sum())
        pid += [f"P{p:03d}" for p in np.flatnonzero(ok)]
        px.append(u[ok])
    px = np.vstack(px) + rng.normal(0, sigma_px, (len(img), 2))
    n = len(img)
    obs = ImageObservations(tuple(img), tuple(pid), px, np.full(n, sigma_px), ("tie",) * n,
                            ("",) * n)  # fmt: skip
    ctrl = np.arange(0, n_pts, 16)  # 10 control points at 0.05 mm
    sig = np.full((ctrl.size, 3), 5e-5)
    ground = GroundPoints(tuple(f"P{p:03d}" for p in ctrl),
                          local.enu_to_map(pts[ctrl] + rng.normal(0, 5e-5, (ctrl.size, 3))),
                          sig, ("control",) * ctrl.size)  # fmt: skip
    centres = np.array([c for c, _ in poses]) + rng.normal(0, 0.01, (len(poses), 3))
    rot = np.array([R for _, R in poses])
    xyz, opk = eo_local_to_map(centres, rot, local)
    opk = opk + np.radians(rng.normal(0, 0.3, opk.shape))
    eo = ExteriorOrientationTable(names, np.arange(len(poses), dtype=float),
                                  ("",) * len(poses), xyz, opk, mapping.crs.to_wkt())  # fmt: skip
    return nominal, obs, ground, mapping, eo


def _adjust(net, **kw):
    cam, obs, ground, mapping, eo = net
    opts = BundleOptions(ap_model="conrady_brown", robust="none", snooping=False, **kw)
    return bundle_adjust([cam], obs, ground, mapping, eo, options=opts)


@pytest.fixture(scope="module")
def strong():
    return _network(range(0, 360, 30), (0, 90), LENS, seed=2)


def test_strong_network_keeps_correlated_significant_aps(strong):
    """24 convergent images with two rolls: k1, k2, k3 correlate above 0.9 and all five
    terms are significant: none is dropped (the former rule dropped the less significant of
    every pair above 0.9), and each is recovered within 3 sigmas."""
    res = _adjust(strong)
    assert res.adjustment.converged
    assert res.dropped == []
    aps = {p.name: p for p in res.interior if p.is_ap}
    assert set(aps) == set(LENS) and all(p.status == "estimated" for p in aps.values())
    z = {n: (aps[n].value - LENS[n]) / aps[n].std for n in LENS}
    assert all(abs(v) < 3.0 for v in z.values()), z
    # the case the old rule got wrong: correlations of about 0.9 and more among them
    names, corr = res.interior_correlation["cam"]
    radial = [names.index(n) for n in ("k1", "k2", "k3")]
    assert np.abs(corr[np.ix_(radial, radial)][np.triu_indices(3, 1)]).max() > 0.9
    # every decision is reported with its statistic
    assert all(aps[n].significant and "t = " in aps[n].reason for n in LENS), aps


def test_weak_network_drops_the_truly_insignificant_aps():
    """Six images from one side at one roll, 0.5 px noise and a lens with k1 only: k2, k3,
    p1 and p2 (truly zero) are dropped with their t (and joint F) statistics; k1 is kept and
    recovered."""
    lens = {"k1": 1.0e-4, "k2": 0.0, "k3": 0.0, "p1": 0.0, "p2": 0.0}
    net = _network((0, 20, 40, 60, 80, 100), (0,), lens, seed=5, sigma_px=0.5)
    res = _adjust(net)
    dropped = {n: why for _, n, why in res.dropped}
    assert {"k2", "k3", "p1", "p2"} <= set(dropped), dropped
    assert all("insignificant (t = " in why for why in dropped.values()), dropped
    k1 = next(p for p in res.interior if p.name == "k1")
    assert k1.status == "estimated" and abs(k1.value - lens["k1"]) < 3 * k1.std


def test_joint_test_keeps_a_group_that_is_significant_only_together():
    """Two APs each insignificant alone (t < 1.96) but correlated at 0.99 and jointly far
    from zero: the joint F test keeps both; uncorrelated, the weaker is dropped."""

    class _Result:
        redundancy = 1000
        x = np.array([1.0, 1.0])
        std = np.array([1.0, 1.0])

        def __init__(self, r: float) -> None:
            self.cov = np.array([[1.0, r], [r, 1.0]])

        def covariance_of(self, idx):
            return self.cov[np.ix_(idx, idx)]

        def correlation_of(self, idx):
            return self.cov[np.ix_(idx, idx)]

    class _Cam:
        interior_names = ("f", "x0", "y0", "a", "b")

    # x = (1, 1) against anti-correlated errors: x' C^-1 x = 2 / (1 - 0.99) -> F = 100
    kept = ap_decisions(_Result(-0.99), [np.array([0, 1])], [np.array([3, 4])], [_Cam()],
                        0.05, 0.9)  # fmt: skip
    assert [d.drop for d in kept] == [False, False]
    assert all(d.F > d.F_critical and "jointly significant" in d.reason for d in kept)
    alone = ap_decisions(_Result(0.0), [np.array([0, 1])], [np.array([3, 4])], [_Cam()],
                         0.05, 0.9)  # fmt: skip
    assert [d.drop for d in alone] == [True, True] and all(d.group == () for d in alone)
