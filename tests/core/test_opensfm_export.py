"""OpenSfM export: a block written as reconstruction.json projects, through OpenSfM's own
equations (written out here from its documentation: normalisation by max(width, height) from
the image centre, Brown / fisheye distortion of X/Z, Y/Z, world -> camera axis-angle), where
the project's camera and orientation project the same ground points (rigorously, in the
east-north-up frame at each centre); re-imported with importopensfm, the block is the same;
a lens without an exact OpenSfM camera is refused by name."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.collinearity import project
from lidarphoto.core.geometry.distortion import BrownConrady, NoDistortion
from lidarphoto.core.geometry.forward_lens import OpenCVFisheyeLens, OpenCVFullLens, OpenCVLens
from lidarphoto.core.geometry.rotations import matrix_to_opk
from lidarphoto.core.io.colmap_block import ColmapBlock
from lidarphoto.core.io.opensfm import block_from_opensfm, read_opensfm
from lidarphoto.core.io.opensfm_export import camera_to_opensfm, opensfm_from_block, write_opensfm
from lidarphoto.core.photo.bundle_setup import GroundPoints
from lidarphoto.core.photo.observations import ImageObservations
from lidarphoto.core.photo.orientation import ExteriorOrientationTable
from pyproj import CRS, Transformer
from test_metashape import enu_axes, project_enu

Rotation = pytest.importorskip("scipy.spatial.transform").Rotation

UTM = "EPSG:32723"
PS = 0.0024


def cameras() -> list[Camera]:
    """brown (offset principal point, fy != fx), perspective (centred, k1 k2), fisheye_opencv
    (offset, k1..k4) and fisheye (centred, k1 k2)."""
    f = 3650.0 * PS
    return [
        Camera("brown", f, PS, 5472, 3648, 0.06, -0.045,
               OpenCVLens(k1=-0.11, k2=0.09, k3=-0.02, p1=-8e-4, p2=1.3e-3, scale_mm=f * 1.01,
                          aspect=1.0009)),
        Camera("persp", f, PS, 5472, 3648, 0.0, 0.0,
               OpenCVLens(k1=-0.05, k2=0.01, scale_mm=f, aspect=1.0)),
        Camera("fish", 1750 * PS, PS, 4000, 3000, -0.0144, 0.0108,
               OpenCVFisheyeLens(k1=0.03, k2=-0.008, k3=0.001, k4=-2e-4, scale_mm=1750 * PS,
                                 aspect=1.0)),
        Camera("fish0", 1750 * PS, PS, 4000, 3000, 0.0, 0.0, NoDistortion(), "equidistant"),
    ]  # fmt: skip


def _proj(name: str) -> str:
    return {"fish": "equidistant", "fish0": "equidistant"}.get(name, "perspective")


def block(seed: int = 5) -> tuple[ColmapBlock, np.ndarray]:
    """Eight images (two per camera) over a ground near 800 m in UTM 23S, and ground points
    (ECEF) seen by each."""
    rng = np.random.default_rng(seed)
    cams = [Camera(c.name, c.focal_mm, c.pixel_size_mm, c.width_px, c.height_px, c.x0_mm,
                   c.y0_mm, c.distortion, _proj(c.name)) for c in cameras()]  # fmt: skip
    xyz, opk, names, per = [], [], [], []
    for i in range(8):
        xyz.append([331200.0 + 90 * i, 7432500.0 + 40 * (i % 3), 1000.0 + 10 * i])
        m = Rotation.from_euler("xyz", [rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1),
                                        rng.uniform(0, 6.28)]).as_matrix()  # fmt: skip
        opk.append(np.ravel(matrix_to_opk(m)))
        names.append(f"img_{i}.jpg")
        per.append(cams[i % 4].name)
    n = len(names)
    eo = ExteriorOrientationTable(tuple(names), np.full(n, np.nan), ("",) * n, np.array(xyz),
                                  np.array(opk), CRS(UTM).to_wkt())  # fmt: skip
    ground = np.column_stack(
        [
            rng.uniform(331100, 332100, 3000),
            rng.uniform(7432400, 7432700, 3000),
            rng.uniform(790, 830, 3000),
        ]
    )
    ids = tuple(f"p{j}" for j in range(len(ground)))
    pts = GroundPoints(ids, ground, np.full((len(ids), 3), 0.05), ("check",) * len(ids))
    obs = ImageObservations((), (), np.zeros((0, 2)), np.zeros(0), (), ())
    lon, lat = Transformer.from_crs(UTM, "EPSG:4326", always_xy=True).transform(
        ground[:, 0], ground[:, 1])  # fmt: skip
    ecef = np.column_stack(Transformer.from_crs("EPSG:4979", "EPSG:4978", always_xy=True)
                           .transform(lon, lat, ground[:, 2]))  # fmt: skip
    return ColmapBlock(tuple(cams), eo, tuple(per), obs, pts), ecef


def opensfm_pixels(cam: dict, shot: dict, x: np.ndarray) -> np.ndarray:
    """OpenSfM's projection of topocentric points to the project's pixels (u from the image's
    top-left corner: OpenSfM's normalised x = (u - w/2) / max(w, h))."""
    from lidarphoto.core.io.opensfm import rotation_from_axis_angle

    xc = x @ rotation_from_axis_angle(shot["rotation"]).T + np.array(shot["translation"])
    a, b = xc[:, 0] / xc[:, 2], xc[:, 1] / xc[:, 2]
    kind = cam["projection_type"]
    g = lambda k: cam.get(k, 0.0)  # noqa: E731
    if kind.startswith("fisheye"):
        r = np.hypot(a, b)
        th = np.arctan(r)
        td = th * (1 + g("k1") * th**2 + g("k2") * th**4 + g("k3") * th**6 + g("k4") * th**8)
        xd, yd = a * td / r, b * td / r
    else:
        r2 = a * a + b * b
        rad = 1 + g("k1") * r2 + g("k2") * r2**2 + g("k3") * r2**3
        xd = a * rad + 2 * g("p1") * a * b + g("p2") * (r2 + 2 * a * a)
        yd = b * rad + g("p1") * (r2 + 2 * b * b) + 2 * g("p2") * a * b
    fx = cam.get("focal_x", cam.get("focal"))
    fy = cam.get("focal_y", fx * cam.get("aspect_ratio", 1.0))
    size = max(cam["width"], cam["height"])
    u = size * (fx * xd + g("c_x")) + cam["width"] / 2
    v = size * (fy * yd + g("c_y")) + cam["height"] / 2
    return np.column_stack([u, v])


def _visible(blk, k: int, ecef: np.ndarray) -> np.ndarray:
    px = project_enu(blk, k, ecef)
    c = {c.name: c for c in blk.cameras}[blk.camera[k]]
    ok = np.isfinite(px).all(axis=1)
    ok &= (px[:, 0] > 0) & (px[:, 0] < c.width_px) & (px[:, 1] > 0) & (px[:, 1] < c.height_px)
    return ok


def test_exported_block_projects_as_opensfm_documents(tmp_path: Path) -> None:
    blk, ecef = block()
    rec, tracks = opensfm_from_block(blk.cameras, blk.eo, blk.camera, None, blk.points)
    assert tracks == ""
    types = {k: c["projection_type"] for k, c in rec[0]["cameras"].items()}
    assert types == {"brown": "brown", "persp": "perspective", "fish": "fisheye_opencv",
                     "fish0": "fisheye"}  # fmt: skip
    ref = rec[0]["reference_lla"]
    x0 = np.array(Transformer.from_crs("EPSG:4979", "EPSG:4978", always_xy=True).transform(
        ref["longitude"], ref["latitude"], ref["altitude"]))  # fmt: skip
    topo = (ecef - x0) @ enu_axes(ref["latitude"], ref["longitude"]).T
    np.testing.assert_allclose(np.array([p["coordinates"] for p in rec[0]["points"].values()]),
                               topo, atol=1e-6)  # fmt: skip
    res = []
    for k, name in enumerate(blk.eo.image_id):
        ok = _visible(blk, k, ecef)
        assert ok.sum() > 100, name
        shot = rec[0]["shots"][name]
        theirs = opensfm_pixels(rec[0]["cameras"][shot["camera"]], shot, topo[ok])
        res.append(np.hypot(*(theirs - project_enu(blk, k, ecef[ok])).T))
    res = np.concatenate(res)
    # the issue asks a median <= 0.01 px and a max <= 0.05 px
    assert np.median(res) < 0.01 and np.max(res) < 0.05, (np.median(res), np.max(res))
    assert np.max(res) < 1e-5, np.max(res)  # exact: rounding of the frame conversions only


def test_reimported_block_is_the_same(tmp_path: Path) -> None:
    blk, ecef = block()
    ids = [f"p{j}" for j in range(0, 3000, 7)]
    sel = [int(p[1:]) for p in ids]
    img, pid, px = [], [], []
    for k, name in enumerate(blk.eo.image_id):
        ok = np.flatnonzero(_visible(blk, k, ecef[sel]))
        img += [name] * len(ok)
        pid += [ids[j] for j in ok]
        px.append(
            project(
                blk.points.xyz[[sel[j] for j in ok]],
                np.r_[blk.eo.xyz[k], blk.eo.opk[k]],
                {c.name: c for c in blk.cameras}[blk.camera[k]],
            )
        )
    obs = ImageObservations(tuple(img), tuple(pid), np.vstack(px), np.full(len(img), 0.5),
                            ("tie",) * len(img), ("",) * len(img))  # fmt: skip
    rec, tracks = opensfm_from_block(blk.cameras, blk.eo, blk.camera, obs, blk.points)
    write_opensfm(tmp_path, rec, tracks)
    back = block_from_opensfm(read_opensfm(tmp_path), UTM, PS)
    assert back.eo.image_id == blk.eo.image_id
    np.testing.assert_allclose(back.eo.xyz, blk.eo.xyz, atol=1e-6)
    np.testing.assert_allclose(back.eo.opk, blk.eo.opk, atol=1e-10)
    order = [blk.points.point_id.index(p) for p in back.points.point_id]
    np.testing.assert_allclose(back.points.xyz, blk.points.xyz[order], atol=1e-6)
    assert len(back.observations.image_id) == len(img)
    np.testing.assert_allclose(back.observations.pixels, obs.pixels, atol=1e-9)
    orig = {c.name: c for c in blk.cameras}
    new = {c.name: c for c in back.cameras}
    res = []
    for k in range(len(blk.eo)):
        ok = _visible(blk, k, ecef)
        eo = np.r_[blk.eo.xyz[k], blk.eo.opk[k]]
        a = project(blk.points.xyz[ok], eo, orig[blk.camera[k]])
        b = project(blk.points.xyz[ok], np.r_[back.eo.xyz[k], back.eo.opk[k]],
                    new[back.camera[k]])  # fmt: skip
        res.append(np.hypot(*(a - b).T))
    assert np.max(np.concatenate(res)) < 1e-5


def test_lens_without_an_opensfm_camera_is_refused_by_name() -> None:
    f = 3650 * PS
    bc = BrownConrady(k1=1e-5)
    with pytest.raises(InputError, match=r"'brown_conrady'.*no exact OpenSfM camera type"):
        camera_to_opensfm(Camera("c", f, PS, 100, 80, 0, 0, bc))
    full = OpenCVFullLens(k1=0.1, k4=0.05, scale_mm=f, aspect=1.0)
    with pytest.raises(InputError, match=r"'c2'.*opencv_full.*k4..k6"):
        camera_to_opensfm(Camera("c2", f, PS, 100, 80, 0, 0, full))
    with pytest.raises(InputError, match=r"'c3'.*'opencv'.*equidistant"):
        camera_to_opensfm(Camera("c3", f, PS, 100, 80, 0, 0, OpenCVLens(k1=0.1, scale_mm=f,
                                                                       aspect=1.0),
                                 "equidistant"))  # fmt: skip


def test_command_line_pix4d_to_opensfm(tmp_path: Path, capsys) -> None:
    """importpix4d -> exportopensfm -> importopensfm: the same EO."""
    from lidarphoto.core.cli import main as cli_main
    from lidarphoto.core.io.orientation import read_eo_csv_full
    from test_pix4d import build

    path = tmp_path / "proj_calibrated_camera_parameters.txt"
    build(path, n=4)
    cam, eo = tmp_path / "cam.json", tmp_path / "eo.csv"
    assert cli_main(["importpix4d", "--input", str(path), "--crs", UTM, "--output-camera",
                     str(cam), "--output-eo", str(eo)]) == 0  # fmt: skip
    out = tmp_path / "osfm"
    rc = cli_main(["exportopensfm", "--camera", str(cam), "--eo", str(eo), "--crs", UTM,
                   "--output-folder", str(out)])  # fmt: skip
    assert rc == 0, capsys.readouterr().err
    data = json.loads((out / "reconstruction.json").read_text(encoding="utf-8"))
    assert {c["projection_type"] for c in data[0]["cameras"].values()} == {"brown"}
    back = block_from_opensfm(read_opensfm(out), UTM, 0.004)
    first = read_eo_csv_full(eo).eo
    np.testing.assert_allclose(back.eo.xyz, first.xyz, atol=1e-6)
    np.testing.assert_allclose(back.eo.opk, first.opk, atol=1e-10)
