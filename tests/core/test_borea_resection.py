"""Space resection of real UltraCam Eagle images of IGN's Borea block against IGN's published
aerotriangulated orientation (tests/data/borea, MIT, see its MANIFEST).

Each image is resected from its tie-point measurements and IGN's object coordinates of the tie
points, in two ways:

- rigorously, in a local ENU frame (Lambert-93 + ellipsoidal heights -> ECEF -> ENU), the EO
  then reported back in Lambert-93 with omega-phi-kappa relative to the grid frame;
- directly in Lambert-93 coordinates, which is how IGN's OPK values behave (the shared
  MANIFEST reprojects them in Lambert-93 with sub-pixel residuals).

IGN's Z is an altitude (NGF-IGN69); it is turned into an ellipsoidal height with the bundled
RAF20 geoid grid through pyproj before comparing.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from lidarphoto.core.geometry.camera import camera_from_dict
from lidarphoto.core.geometry.collinearity import project
from lidarphoto.core.geometry.frames import LocalFrame, MappingFrame
from lidarphoto.core.geometry.rotations import opk_to_matrix
from lidarphoto.core.photo.orientation import eo_local_to_map
from lidarphoto.core.photo.resection import initial_pose_pnp, space_resection
from pyproj import Proj, Transformer

DATA = Path(__file__).resolve().parents[1] / "data" / "borea"
PIXEL_MM = 0.004  # UltraCam Eagle M3 pixel; any value works, the camera is given in pixels


def _camera():
    info = dict(
        line.split("=", 1)
        for line in (DATA / "Camera1.txt").read_text().splitlines()
        if "=" in line
    )
    info = {k.strip(): v.strip() for k, v in info.items()}
    return camera_from_dict(
        {
            "name": info["Name"],
            "focal_px": float(info["focal"]),
            "ppx_px": float(info["PPAx"]),
            "ppy_px": float(info["PPAy"]),
            "pixel_size_mm": PIXEL_MM,
            "width_px": int(info["width"]),
            "height_px": int(info["height"]),
        }
    )


def _opk():
    rows = {}
    for line in (DATA / "opk_subset.OPK").read_text().splitlines()[1:]:
        p = line.split()
        rows[p[0]] = np.array([float(v) for v in p[1:7]])
    return rows


def _measurements():
    world = {}
    for line in (DATA / "liaisons_subset_world.mes").read_text().splitlines():
        p = line.split()
        world[p[0]] = np.array([float(v) for v in p[1:4]])
    per_image: dict[str, tuple[list, list]] = {}
    for line in (DATA / "liaisons_subset.mes").read_text().splitlines():
        p = line.split()
        px, pts = per_image.setdefault(p[1], ([], []))
        px.append([float(p[2]), float(p[3])])
        pts.append(world[p[0]])
    return {k: (np.array(v[0]), np.array(v[1])) for k, v in per_image.items()}


def _altitude_to_ellipsoidal(xyz_l93: np.ndarray) -> np.ndarray:
    to_geo = Transformer.from_crs("EPSG:2154", "EPSG:4171", always_xy=True)  # RGF93
    lon, lat = to_geo.transform(xyz_l93[:, 0], xyz_l93[:, 1])
    geoid = Transformer.from_pipeline(
        "+proj=pipeline +step +proj=unitconvert +xy_in=deg +xy_out=rad "
        f"+step +proj=vgridshift +grids={DATA / 'fr_ign_RAF20.tif'} +multiplier=1 "
        "+step +proj=unitconvert +xy_in=rad +xy_out=deg"
    )
    _, _, h = geoid.transform(lon, lat, xyz_l93[:, 2])
    return np.column_stack([xyz_l93[:, :2], h])


@pytest.fixture(scope="module")
def borea():
    return _camera(), _opk(), _measurements()


def _angle_diff_deg(a, b):
    return (np.asarray(a) - np.asarray(b) + 180.0) % 360.0 - 180.0


def test_ign_orientation_reprojects_subpixel(borea):
    """IGN's OPK + our collinearity reproduce IGN's own measurements (checks the conventions)."""
    camera, opk, meas = borea
    for image, (px, pts) in meas.items():
        ign = opk[image]
        centre = _altitude_to_ellipsoidal(ign[None, :3])[0]
        eo = np.array([*centre, *np.radians(ign[3:])])
        res = project(pts, eo, camera) - px
        rms = np.sqrt(np.mean(res**2, axis=0))
        assert np.all(rms < 1.0), (image, rms)


def test_resection_reproduces_ign(borea, record_property):
    camera, opk, meas = borea
    mapping = MappingFrame.from_user_input("EPSG:2154")
    report = []
    for image, (px, pts) in meas.items():
        ign = opk[image]
        ign_centre = _altitude_to_ellipsoidal(ign[None, :3])[0]

        # (a) directly in Lambert-93 (the frame IGN's OPK lives in)
        origin = pts.mean(axis=0)
        direct = space_resection(px, pts - origin, camera, sigma_px=0.5)
        d_xyz = direct.eo[:3] + origin - ign_centre
        d_ang = _angle_diff_deg(np.degrees(direct.eo[3:]), ign[3:])
        assert np.all(direct.rms_px < 1.0), direct.rms_px
        assert len(direct.rejected) < 0.05 * len(px)

        # (b) rigorously in a local ENU frame, reported back in Lambert-93
        local = LocalFrame.at_map_point(mapping, origin)
        enu = local.map_to_enu(pts)
        rig = space_resection(px, enu, camera, sigma_px=0.5)
        m_local = opk_to_matrix(*rig.eo[3:])[None]
        xyz_map, opk_map = eo_local_to_map(rig.eo[None, :3], m_local, local)
        r_xyz = xyz_map[0] - ign_centre
        r_ang = _angle_diff_deg(np.degrees(opk_map[0]), ign[3:])
        assert np.all(rig.rms_px < 1.0), rig.rms_px

        # IGN's heights live in the conformal Lambert-93 frame, whose horizontal scale k
        # (> 1 south of the 44 deg standard parallel) the flying height takes on; the rigorous
        # ENU height is lower by (Z - ground) (1 - 1/k) (IGN's "linear alteration")
        lon, lat = Transformer.from_crs("EPSG:2154", "EPSG:4171", always_xy=True).transform(
            *origin[:2]
        )
        k = Proj("EPSG:2154").get_factors(lon, lat).meridional_scale
        scale_dz = (ign_centre[2] - origin[2]) * (1.0 / k - 1.0)
        sig_r = rig.std
        assert np.all(np.abs(r_xyz[:2]) < 5 * sig_r[:2] + 0.08), (image, r_xyz, sig_r[:3])
        assert abs(r_xyz[2] - scale_dz) < 5 * sig_r[2] + 0.05, (image, r_xyz[2], scale_dz)
        assert np.all(np.abs(np.radians(r_ang)) < 5 * sig_r[3:] + 2e-5), (image, r_ang)

        # an independent peer: OpenCV's solvePnP (SQPnP + Levenberg-Marquardt) on the same points
        cv = initial_pose_pnp(px, pts - origin, camera)

        report.append((image, len(px), direct, d_xyz, d_ang, rig, r_xyz, r_ang, scale_dz))

        # the Lambert-93 resection reproduces IGN's pose: within 5 sigma of our own estimate
        # plus 5 cm (IGN's bundle used all images and tie points, ours one image)
        sig = direct.std
        assert np.all(np.abs(d_xyz) < 5 * sig[:3] + 0.05), (image, d_xyz, sig[:3])
        assert np.all(np.abs(np.radians(d_ang)) < 5 * sig[3:] + 2e-5), (image, d_ang, sig[3:])
        # OpenCV agrees with our Lambert-93 solution to well inside its precision
        assert np.all(np.abs(cv[:3] - direct.eo[:3]) < 0.5 * sig[:3] + 1e-3)

    lines = [
        "image                 n  rms col/row px | L93 dX dY dZ m       dO dP dK 1e-4 deg"
        " | ENU->L93 dX dY dZ m   dO dP dK 1e-4 deg | scale dZ m | sigma XYZ m, OPK 1e-4 deg"
    ]
    for image, n, direct, d_xyz, d_ang, _rig, r_xyz, r_ang, scale_dz in report:
        lines.append(
            f"{image} {n:4d} {direct.rms_px[0]:.2f}/{direct.rms_px[1]:.2f} | "
            + " ".join(f"{v:+.3f}" for v in d_xyz)
            + " "
            + " ".join(f"{v * 1e4:+.1f}" for v in d_ang)
            + " | "
            + " ".join(f"{v:+.3f}" for v in r_xyz)
            + " "
            + " ".join(f"{v * 1e4:+.1f}" for v in r_ang)
            + f" | {scale_dz:+.3f} | "
            + " ".join(f"{v:.3f}" for v in direct.std[:3])
            + " "
            + " ".join(f"{np.degrees(v) * 1e4:.1f}" for v in direct.std[3:])
        )
    text = "\n".join(lines)
    print("\n" + text)
    record_property("borea_report", text)
