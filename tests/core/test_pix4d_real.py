"""Pix4D import against files PIX4Dmapper wrote (tests/data/pix4d: the params of a real
168-image DJI block, from EasyIDP's test data, GPL-3.0; its README says what each file proves).

- ``_pmatrix.txt`` is Pix4D's own linear projection of every image (pixels of a point given
  relative to the offset): the imported camera (lens off) and EO must project like it, to the
  rounding of the matrix's six decimals. This checks our reading of K, R, t, the offset and
  the sign conventions of the EO on a real file, not on one written here.
- ``_pix4d_calibrated_internal_camera_parameters.cam`` (Pix4D's Inpho-format camera) states the
  focal length in mm and the principal point's offset from the sensor centre (the fiducials'
  centre) in mm and pixels: the imported camera must state the same, and does only with
  PIXEL_ORIGIN = corner (K's (W/2, H/2) is the sensor centre); the other origin is shown off
  by half a pixel.
- The tangential sign is NOT established by these files (the README says why); the test of
  the distortion below checks only that the real coefficients reach the lens in the assumed
  reading (p1 = T1, p2 = T2 in K's y-down frame).
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from lidarphoto.core.cli import main as cli_main
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.collinearity import project
from lidarphoto.core.geometry.distortion import NoDistortion
from lidarphoto.core.io.camera import read_cameras_json
from lidarphoto.core.io.orientation import read_eo_csv_full
from lidarphoto.core.io.pix4d import block_from_pix4d, read_offset, read_pix4d

DATA = Path(__file__).resolve().parents[1] / "data" / "pix4d"
STEM = "pix4d.origin"
CCP = DATA / f"{STEM}_calibrated_camera_parameters.txt"
#: The sensor of the .cam file: 12.825 mm over 5472 px.
PIXEL_MM = 12.825 / 5472
#: The P-matrices are written with six decimals: each element carries up to 5e-7 of rounding.
P_ROUND = 5e-7


def read_pmatrix(path: Path) -> dict[str, np.ndarray]:
    out = {}
    for line in path.read_text().splitlines():
        tok = line.split()
        if tok:
            assert len(tok) == 13, line
            out[tok[0]] = np.array([float(t) for t in tok[1:]]).reshape(3, 4)
    return out


def read_inpho_cam(path: Path) -> dict[str, list[float]]:
    """Key -> numbers of the .cam; the three principal-point lines in order as XPOFF_1..3."""
    out: dict[str, list[float]] = {}
    n = {"XPOFF": 0, "YPOFF": 0}
    for line in path.read_text().splitlines():
        tok = line.split()
        if not tok or line.startswith("#"):
            continue
        key = tok[0]
        if key in n:
            n[key] += 1
            key = f"{key}_{n[key]}"
        try:
            out[key] = [float(t) for t in tok[1:]]
        except ValueError:
            continue
    return out


def run_import(tmp_path: Path, *extra: str) -> tuple[Camera, dict[str, np.ndarray]]:
    """``importpix4d`` on the command line (LOCAL: the file has no CRS beside it)."""
    out = {"camera": tmp_path / "cam.json", "eo": tmp_path / "eo.csv"}
    rc = cli_main(["importpix4d", "--input", str(CCP), "--pixel-size", repr(PIXEL_MM), *extra,
                   *(a for k, p in out.items() for a in (f"--output-{k}", str(p)))])  # fmt: skip
    assert rc == 0
    (cam,) = read_cameras_json(out["camera"])
    eo = read_eo_csv_full(out["eo"]).eo
    return cam, {n: np.r_[eo.xyz[k], eo.opk[k]] for k, n in enumerate(eo.image_id)}


def sample_points(k: np.ndarray, rot: np.ndarray, pos: np.ndarray, w: int, h: int,
                  rng: np.random.Generator, n: int = 25) -> np.ndarray:  # fmt: skip
    """Points (relative to the offset) 5-40 m along the rays of random pixels of the frame."""
    uv1 = np.column_stack([rng.uniform(0, w, n), rng.uniform(0, h, n), np.ones(n)])
    d = np.linalg.solve(k @ rot, uv1.T).T
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return pos + d * rng.uniform(5.0, 40.0, (n, 1))


def test_files_are_what_pix4d_wrote() -> None:
    images = read_pix4d(CCP)
    pmat = read_pmatrix(DATA / f"{STEM}_pmatrix.txt")
    assert len(images) == 168 and {i.name for i in images} == set(pmat)
    assert {(i.width, i.height) for i in images} == {(5472, 3648)}
    np.testing.assert_array_equal(read_offset(DATA / f"{STEM}_offset.xyz"),
                                  [368109.0, 3956043.0, 96.0])  # fmt: skip
    # Pix4D's matrices are its K [R | -R t] of the same numbers (to their six decimals)
    for img in images:
        p = pmat[img.name]
        mine = img.k @ np.hstack([img.rotation, -img.rotation @ img.position[:, None]])
        assert np.max(np.abs(mine - p)) <= P_ROUND * 1.0001, img.name


def test_imported_block_projects_like_pix4d_pmatrix(tmp_path: Path) -> None:
    """The imported camera (lens off) + EO against Pix4D's own P-matrix of every image."""
    cam, eo = run_import(tmp_path)
    linear = dataclasses.replace(cam, distortion=NoDistortion())
    offset = read_offset(DATA / f"{STEM}_offset.xyz")
    pmat = read_pmatrix(DATA / f"{STEM}_pmatrix.txt")
    rng = np.random.default_rng(0)
    worst, n = 0.0, 0
    for img in read_pix4d(CCP):
        xyz = sample_points(img.k, img.rotation, img.position, img.width, img.height, rng)
        hom = np.column_stack([xyz, np.ones(len(xyz))])
        uvw = hom @ pmat[img.name].T
        theirs = uvw[:, :2] / uvw[:, 2:]
        # the bound of the matrix's rounding at each point: |dP| <= 5e-7 per element
        slack = P_ROUND * np.abs(hom).sum(1)
        bound = slack * (1 + np.abs(theirs).max(1)) / np.abs(uvw[:, 2])
        ours = project(xyz + offset, eo[img.name], linear)
        err = np.abs(ours - theirs).max(1)
        assert np.all(err <= bound + 1e-9), (img.name, err.max(), bound.min())
        worst, n = max(worst, float(err.max())), n + len(err)
    assert n == 168 * 25
    assert worst < 0.05, worst  # the max; the rounding bound above is the real test


def test_internal_cam_file_fixes_the_pixel_origin(tmp_path: Path) -> None:
    """The .cam's focal length and principal-point offset are the imported camera's with
    PIXEL_ORIGIN = corner (the default); with 'centre' they are half a pixel off."""
    cam_file = read_inpho_cam(DATA / f"{STEM}_pix4d_calibrated_internal_camera_parameters.cam")
    cam, _ = run_import(tmp_path)
    assert cam.focal_mm == pytest.approx(cam_file["FOCAL"][0], abs=1e-12)
    # Inpho's line: x right, y up, mm from the sensor centre = the project's (x0, y0)
    x0, y0 = cam_file["XPOFF_1"][0], cam_file["YPOFF_1"][0]
    assert cam.x0_mm == pytest.approx(x0, abs=1e-12)
    assert cam.y0_mm == pytest.approx(y0, abs=1e-12)
    # the pixel line: (W/2 - cx, H/2 - cy) in K's pixels
    (img, *_) = read_pix4d(CCP)
    assert cam_file["XPOFF_3"][0] == pytest.approx(img.width / 2 - img.k[0, 2], abs=1e-9)
    assert cam_file["YPOFF_3"][0] == pytest.approx(img.height / 2 - img.k[1, 2], abs=1e-9)
    centred, _ = run_import(tmp_path, "--pixel-origin", "centre")
    assert (centred.x0_mm - x0) / PIXEL_MM == pytest.approx(0.5, abs=1e-9)
    assert (centred.y0_mm - y0) / PIXEL_MM == pytest.approx(-0.5, abs=1e-9)


def test_real_coefficients_reach_the_lens(tmp_path: Path) -> None:
    """The real R1-R3, T1, T2 through the import land where Pix4D's formula, read with the
    tangential terms in K's y-down frame (the assumption the README states), puts them."""
    cam, eo = run_import(tmp_path)
    offset = read_offset(DATA / f"{STEM}_offset.xyz")
    rng = np.random.default_rng(1)
    for img in read_pix4d(CCP)[::20]:
        xyz = sample_points(img.k, img.rotation, img.position, img.width, img.height, rng)
        xc = (xyz - img.position) @ img.rotation.T
        x, y = xc[:, 0] / xc[:, 2], xc[:, 1] / xc[:, 2]
        (r1, r2, r3), (t1, t2) = img.radial, img.tangential
        rr = x * x + y * y
        rad = 1 + r1 * rr + r2 * rr**2 + r3 * rr**3
        xd = x * rad + 2 * t1 * x * y + t2 * (rr + 2 * x * x)
        yd = y * rad + 2 * t2 * x * y + t1 * (rr + 2 * y * y)
        theirs = np.column_stack([img.k[0, 0] * xd + img.k[0, 2], img.k[1, 1] * yd + img.k[1, 2]])
        ours = project(xyz + offset, eo[img.name], cam)
        np.testing.assert_allclose(ours, theirs, atol=1e-6)


def test_block_function_matches_the_command(tmp_path: Path) -> None:
    cam, eo = run_import(tmp_path)
    block = block_from_pix4d(read_pix4d(CCP), read_offset(DATA / f"{STEM}_offset.xyz"), "",
                             PIXEL_MM)  # fmt: skip
    assert [c.name for c in block.cameras] == ["pix4d_1"] and cam.name == "pix4d_1"
    for k, name in enumerate(block.eo.image_id):
        np.testing.assert_allclose(eo[name][:3], block.eo.xyz[k], atol=1e-4)
        np.testing.assert_allclose(eo[name][3:], block.eo.opk[k], atol=1e-9)
