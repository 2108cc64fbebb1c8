"""Bundle adjustment of real UltraCam Eagle images of IGN's Borea block (tests/data/borea_block,
MIT) against IGN's published aerotriangulation.

The western block (34 of its 37 images: three see fewer than six tie points) is adjusted from
its 8,800 tie-point measurements in two ways:

- with IGN's orientations as GNSS/INS-like observations (0.10 m, 0.005 deg), ground control
  point 1003 (measured in 12 images) kept out of our adjustment as a check point;
- as a free network (tie points only, inner constraints) from orientations perturbed by 2 m and
  0.05 deg, compared with IGN's after a similarity transformation.

IGN's Z are altitudes (NGF-IGN69), turned into ellipsoidal heights with the RAF20 grid; IGN's
heights also carry the Lambert-93 scale of their frame (the resection test derives the effect
on the flying height, about -0.50 m here), which the observed run corrects before use.
"""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import numpy as np
import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.geometry.frames import MappingFrame
from lidarphoto.core.photo.bundle import bundle_adjust
from lidarphoto.core.photo.bundle_setup import BundleOptions, GroundPoints
from lidarphoto.core.photo.observations import ImageObservations
from lidarphoto.core.photo.orientation import ExteriorOrientationTable
from pyproj import Proj, Transformer
from test_borea_resection import _camera as borea_camera  # the same IGN camera file

HERE = Path(__file__).resolve().parents[1] / "data"
DATA = HERE / "borea_block"
GEOID = HERE / "borea" / "fr_ign_RAF20.tif"


def _ellipsoidal(xyz: np.ndarray) -> np.ndarray:
    lon, lat = Transformer.from_crs("EPSG:2154", "EPSG:4171", always_xy=True).transform(
        xyz[:, 0], xyz[:, 1]
    )
    geoid = Transformer.from_pipeline(
        "+proj=pipeline +step +proj=unitconvert +xy_in=deg +xy_out=rad "
        f"+step +proj=vgridshift +grids={GEOID} +multiplier=1 "
        "+step +proj=unitconvert +xy_in=rad +xy_out=deg"
    )
    _, _, h = geoid.transform(lon, lat, xyz[:, 2])
    return np.column_stack([xyz[:, :2], h])


@pytest.fixture(scope="module")
def block():
    rows = [line.split() for line in (DATA / "liaisons_west_ne.mes").read_text().splitlines()]
    opk = {}
    for line in (DATA / "opk_west_ne.OPK").read_text().splitlines()[1:]:
        p = line.split()
        opk[p[0]] = np.array([float(v) for v in p[1:7]])
    per_image = Counter(r[1] for r in rows)
    west = sorted(k for k, v in opk.items() if v[0] < 820000 and per_image[k] >= 6)
    sel = [r for r in rows if r[1] in set(west)]
    rays = Counter(r[0] for r in sel)
    sel = [r for r in sel if rays[r[0]] >= 2]
    ter = [line.split() for line in (DATA / "terrain_west_ne.mes").read_text().splitlines()]
    ter = [[t[0].strip('"'), *t[1:]] for t in ter if t[1] in set(west)]
    obs = ImageObservations.from_arrays(
        [r[1] for r in sel] + [t[1] for t in ter],
        [r[0] for r in sel] + [t[0] for t in ter],
        np.array([[float(r[2]), float(r[3])] for r in sel + ter]),
        0.5,
        ["tie"] * len(sel) + ["check"] * len(ter),
        [""] * (len(sel) + len(ter)),
    )
    mapping = MappingFrame.from_user_input("EPSG:2154")
    xyz = _ellipsoidal(np.array([opk[i][:3] for i in west]))
    angles = np.radians(np.array([opk[i][3:] for i in west]))
    ign = ExteriorOrientationTable(
        tuple(west),
        np.full(len(west), np.nan),
        ("",) * len(west),
        xyz,
        angles,
        mapping.crs.to_wkt(),
    )
    g = [line.split() for line in (DATA / "23FD1305_Biais2.app").read_text().splitlines()]
    ground = GroundPoints(
        tuple(x[0].strip('"') for x in g),
        np.array([[float(v) for v in x[2:5]] for x in g]),
        np.array([[0.02, 0.02, 0.03]] * len(g)),
        ("check",) * len(g),
    )
    return {
        "obs": obs,
        "mapping": mapping,
        "ign": ign,
        "ground": ground,
        "camera": borea_camera(),
        "rows": rows,
        "opk": opk,
    }


def _scale_corrected(ign: ExteriorOrientationTable, ground_h: float = 55.0):
    """IGN's heights above the ground scaled back by the Lambert-93 scale k (their frame's)."""
    lon, lat = Transformer.from_crs("EPSG:2154", "EPSG:4171", always_xy=True).transform(
        *ign.xyz[:, :2].mean(axis=0)
    )
    k = Proj("EPSG:2154").get_factors(lon, lat).meridional_scale
    xyz = ign.xyz.copy()
    xyz[:, 2] = ground_h + (xyz[:, 2] - ground_h) / k
    return ExteriorOrientationTable(ign.image_id, ign.time, ign.group, xyz, ign.opk, ign.crs_wkt), k


def test_observed_block_reproduces_ign_and_the_control_point(block, record_property):
    cam, ign = block["camera"], block["ign"]
    observed, k = _scale_corrected(ign)
    sigma = np.tile([0.10] * 3 + [np.radians(0.005)] * 3, (len(ign), 1))
    res = bundle_adjust(
        [cam],
        block["obs"],
        block["ground"],
        block["mapping"],
        observed,
        sigma,
        options=BundleOptions(ap_model="none", estimate_interior=False),
    )
    assert res.adjustment.converged and res.adjustment.global_test.dof > 10000
    # the tie points fit IGN's images at their measurement level (0.15 px RMS, sigma0 ~ 0.37
    # with 0.5 px a priori), and few are rejected
    rms = np.array(list(res.image_rms.values()))
    assert np.all(rms < 0.35) and res.sigma0 < 0.5
    assert res.rejected.sum() < 0.01 * len(block["obs"])
    # our orientations against IGN's (scale-corrected): a few cm and 0.002 deg
    d = res.eo.xyz - observed.xyz
    da = np.degrees(res.eo.opk - observed.opk)
    assert np.all(np.sqrt(np.mean(d**2, axis=0)) < [0.06, 0.06, 0.03])
    assert np.all(np.abs(d) < 0.15) and np.all(np.sqrt(np.mean(da**2, axis=0)) < 0.002)
    # the surveyed control point, never in the adjustment, within a few cm
    c = res.check
    assert c.point_id == ("1003",) and c.n_images[0] == 12
    assert np.all(np.abs(c.discrepancy[0]) < [0.05, 0.05, 0.08]), c.discrepancy
    text = (
        f"observed EO (0.10 m, 0.005 deg), {len(ign)} images, {len(block['obs'])} measurements: "
        f"sigma0 {res.sigma0:.3f}; EO - IGN RMS X/Y/Z "
        + " / ".join(f"{v:.3f}" for v in np.sqrt(np.mean(d**2, axis=0)))
        + " m, omega/phi/kappa "
        + " / ".join(f"{v:.4f}" for v in np.sqrt(np.mean(da**2, axis=0)))
        + " deg; check point 1003 dE/dN/dH "
        + " / ".join(f"{v:+.3f}" for v in c.discrepancy[0])
        + f" m (Lambert-93 scale k = {k:.7f})"
    )
    print("\n" + text)
    record_property("borea_bundle_observed", text)


def test_free_network_of_tie_points_reproduces_ign_up_to_a_similarity(block, record_property):
    cam, ign = block["camera"], block["ign"]
    rng = np.random.default_rng(0)
    start = ExteriorOrientationTable(
        ign.image_id,
        ign.time,
        ign.group,
        ign.xyz + rng.normal(0, 2.0, ign.xyz.shape),
        ign.opk + np.radians(rng.normal(0, 0.05, ign.opk.shape)),
        ign.crs_wkt,
    )
    res = bundle_adjust(
        [cam],
        block["obs"],
        block["ground"],
        block["mapping"],
        start,
        options=BundleOptions(ap_model="none", estimate_interior=False, datum="inner"),
    )
    assert res.adjustment.converged and res.adjustment.n_constraints == 7
    A = res.local.map_to_enu(res.eo.xyz)
    B = res.local.map_to_enu(ign.xyz)
    ca, cb = A.mean(axis=0), B.mean(axis=0)
    U, S, Vt = np.linalg.svd((A - ca).T @ (B - cb))
    R = (U @ Vt).T
    s = S.sum() / np.sum((A - ca) ** 2)
    res_xyz = B - (cb + s * (A - ca) @ R.T)
    rms = np.sqrt(np.mean(res_xyz**2, axis=0))
    # 3 km of strips without any control or GNSS: the tie points alone keep the block's shape
    # to a few decimetres
    assert np.all(rms < [0.25, 0.25, 0.12]) and np.abs(res_xyz).max() < 0.5
    assert abs(s - 1) < 2e-3
    text = (
        f"free network (tie points only, inner constraints), start 2 m / 0.05 deg off: "
        f"similarity to IGN's centres scale {s:.6f}, residual RMS X/Y/Z "
        + " / ".join(f"{v:.3f}" for v in rms)
        + f" m, max {np.abs(res_xyz).max():.3f} m"
    )
    print("\n" + text)
    record_property("borea_bundle_free", text)


def test_the_measured_images_fall_into_unconnected_parts(block):
    """The 42 images of the folder: the 5 north-eastern ones share no tie point with the
    western block, and the bundle says which they are."""
    rows = block["rows"]
    rays = Counter(r[0] for r in rows)
    rows = [r for r in rows if rays[r[0]] >= 2]
    obs = ImageObservations.from_arrays(
        [r[1] for r in rows],
        [r[0] for r in rows],
        np.array([[float(r[2]), float(r[3])] for r in rows]),
        0.5,
        ["tie"] * len(rows),
        [""] * len(rows),
    )
    opk = block["opk"]
    ids = sorted({r[1] for r in rows})
    xyz = _ellipsoidal(np.array([opk[i][:3] for i in ids]))
    eo = ExteriorOrientationTable(
        tuple(ids),
        np.full(len(ids), np.nan),
        ("",) * len(ids),
        xyz,
        np.radians(np.array([opk[i][3:] for i in ids])),
        block["mapping"].crs.to_wkt(),
    )
    ne = sorted(i for i in ids if opk[i][0] > 820000)
    assert len(ne) == 5
    with pytest.raises(InputError, match="unconnected parts.*" + ", ".join(ne)):
        bundle_adjust(
            [block["camera"]],
            obs,
            GroundPoints.empty(),
            block["mapping"],
            eo,
            options=BundleOptions(datum="inner"),
        )
