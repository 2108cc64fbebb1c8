"""OpenSfM import against a reconstruction OpenSfM wrote (tests/data/opensfm: OpenSfM's own
Berlin example, 3 iPhone 4S photos, BSD-2-Clause; 400 of its points and their tracks).

- The imported camera + EO (``importopensfm`` on the command line) project OpenSfM's points
  where OpenSfM's documented perspective equations, applied to the file's numbers (written out
  here), put them: the reading of a real file, to rounding.
- Against OpenSfM's own measurements (``tracks.csv``, the features its bundle adjustment
  fitted): the residuals are the adjustment's (median 0.95 px of the 3264 px photos, which
  OpenSfM matched at 1024 px), centred on zero. A half-pixel shift of the principal point
  against the observations, a flipped k1 or k2 and dropping the distortion are each shown to
  fail these checks.
- Into UTM through the file's ``reference_lla``: the same projections within 1e-3 px.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
from lidarphoto.core.cli import main as cli_main
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.collinearity import project
from lidarphoto.core.geometry.forward_lens import OpenCVLens
from lidarphoto.core.io.camera import read_cameras_json
from lidarphoto.core.io.ground_points import read_ground_points_csv
from lidarphoto.core.io.observations import read_observations_csv
from lidarphoto.core.io.orientation import read_eo_csv_full

DATA = Path(__file__).resolve().parents[1] / "data" / "opensfm"
REC = json.loads((DATA / "reconstruction.json").read_text())[0]
(CAM_JSON,) = REC["cameras"].values()
W, H = CAM_JSON["width"], CAM_JSON["height"]
#: The iPhone 4S pixel (1.4 um): it sets the camera's millimetres only, never a pixel.
PIXEL_MM = 0.0014
#: OpenSfM matched at ``feature_process_size: 1024`` (the example's config): one matching
#: pixel is 3264 / 1024 = 3.2 px here. A median residual of 0.4 matching pixels bounds a
#: keypoint precision of a few tenths of a pixel, the detector's.
MEDIAN_BOUND_PX = 0.4 * max(W, H) / 1024


@dataclasses.dataclass
class Imported:
    camera: Camera
    eo: dict
    points: dict
    obs: object


def run_import(tmp_path: Path, *extra: str) -> Imported:
    tmp_path.mkdir(parents=True, exist_ok=True)
    files = {k: tmp_path / f"{k}.{'json' if k == 'camera' else 'csv'}"
             for k in ("camera", "eo", "observations", "points")}  # fmt: skip
    rc = cli_main(["importopensfm", "--input", str(DATA / "reconstruction.json"),
                   "--pixel-size", repr(PIXEL_MM), *extra,
                   *(a for k, p in files.items() for a in (f"--output-{k}", str(p)))])  # fmt: skip
    assert rc == 0
    (cam,) = read_cameras_json(files["camera"])
    eo = read_eo_csv_full(files["eo"]).eo
    pts = read_ground_points_csv(files["points"])
    return Imported(
        cam,
        {n: np.r_[eo.xyz[k], eo.opk[k]] for k, n in enumerate(eo.image_id)},
        dict(zip(pts.point_id, pts.xyz)),
        read_observations_csv(files["observations"]),
    )


def rotation(v: list) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    th = np.linalg.norm(v)
    k = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]]) / th
    return np.eye(3) + np.sin(th) * k + (1 - np.cos(th)) * k @ k


def opensfm_pixels(shot: str, xyz: np.ndarray) -> np.ndarray:
    """OpenSfM's perspective camera on the file's numbers: X_c = R X + t; (x, y) = X_c / Z_c;
    d = 1 + k1 r^2 + k2 r^4; normalised focal d (x, y); OpenSfM's pixel (size = max(w, h),
    centres at integers) + 0.5 for the project's (the first pixel's centre at 0.5)."""
    s = REC["shots"][shot]
    xc = xyz @ rotation(s["rotation"]).T + np.asarray(s["translation"])
    x, y = xc[:, 0] / xc[:, 2], xc[:, 1] / xc[:, 2]
    r2 = x * x + y * y
    d = 1 + CAM_JSON["k1"] * r2 + CAM_JSON["k2"] * r2 * r2
    xn, yn = CAM_JSON["focal"] * d * x, CAM_JSON["focal"] * d * y
    size = max(W, H)
    return np.column_stack([xn * size - 0.5 + W / 2, yn * size - 0.5 + H / 2]) + 0.5


def residuals(imp: Imported, camera: Camera | None = None) -> np.ndarray:
    """Our projection of each tracked point minus its observation (N, 2), px."""
    cam = camera or imp.camera
    o = imp.obs
    out = np.empty((len(o.image_id), 2))
    for i, (img, pid) in enumerate(zip(o.image_id, o.point_id)):
        out[i] = project(imp.points[pid][None], imp.eo[img], cam)[0] - o.pixels[i]
    return out


def fits_opensfm(res: np.ndarray) -> tuple[bool, str]:
    """The residuals of OpenSfM's adjustment: a small median, centred on zero within five
    standard errors of a median (1.2533 MAD-sigma / sqrt(n))."""
    dist = np.hypot(*res.T)
    centre = np.median(res, axis=0)
    sigma = 1.4826 * np.median(np.abs(res - centre), axis=0)
    se = 1.2533 * sigma / np.sqrt(len(res))
    ok = np.median(dist) < MEDIAN_BOUND_PX and bool(np.all(np.abs(centre) < 5 * se))
    return ok, f"median {np.median(dist):.3f} px, centre {centre.round(3)}, 5 se {5 * se}"


def test_file_is_opensfms() -> None:
    assert len(REC["shots"]) == 3 and len(REC["points"]) == 400
    assert CAM_JSON["projection_type"] == "perspective" and (W, H) == (3264, 2448)
    tracks = (DATA / "tracks.csv").read_text().splitlines()
    assert tracks[0] == "OPENSFM_TRACKS_VERSION_v2" and len(tracks) == 1 + 1022


def test_import_projects_like_opensfm_equations(tmp_path: Path) -> None:
    imp = run_import(tmp_path)
    ids = sorted(imp.points)
    local = np.array([REC["points"][k]["coordinates"] for k in ids])
    np.testing.assert_allclose(np.array([imp.points[k] for k in ids]), local, atol=1e-9)
    for shot in REC["shots"]:
        ours = project(local, imp.eo[shot], imp.camera)
        theirs = opensfm_pixels(shot, local)
        front = np.isfinite(ours[:, 0])
        assert front.sum() > 300
        np.testing.assert_allclose(ours[front], theirs[front], atol=1e-6)


def test_residuals_against_opensfm_observations(tmp_path: Path) -> None:
    imp = run_import(tmp_path)
    assert len(imp.obs.image_id) == 1022
    ok, msg = fits_opensfm(residuals(imp))
    print(msg)
    assert ok, msg
    cam = imp.camera
    k1, k2 = CAM_JSON["k1"], CAM_JSON["k2"]

    def lens(a: float, b: float) -> OpenCVLens:
        return OpenCVLens(k1=a, k2=b, scale_mm=cam.focal_mm, aspect=1.0)

    half = 0.5 * cam.pixel_size_mm
    broken = {
        "principal point + 0.5 px in x": dataclasses.replace(cam, x0_mm=cam.x0_mm + half),
        "principal point + 0.5 px in y": dataclasses.replace(cam, y0_mm=cam.y0_mm - half),
        "k1 flipped": dataclasses.replace(cam, distortion=lens(-k1, k2)),
        "k2 flipped": dataclasses.replace(cam, distortion=lens(k1, -k2)),
        "no distortion": dataclasses.replace(cam, distortion=lens(0.0, 0.0)),
    }
    for what, wrong in broken.items():
        ok, msg = fits_opensfm(residuals(imp, wrong))
        print(what, msg)
        assert not ok, f"{what} was not caught: {msg}"


def test_into_utm_through_reference_lla(tmp_path: Path) -> None:
    """Imported into UTM 33N (Berlin), taken into a local ENU frame of the map rigorously (the
    adjustments' frame, DESIGN.md), the images project OpenSfM's points as in LOCAL."""
    from lidarphoto.core.geometry.frames import LocalFrame, MappingFrame
    from lidarphoto.core.photo.orientation import eo_map_to_local

    local = run_import(tmp_path / "local")
    utm = run_import(tmp_path / "utm", "--crs", "EPSG:32633")
    names = sorted(utm.eo)
    xyz = np.array([utm.eo[n][:3] for n in names])
    assert np.all(np.abs(xyz[:, 0] - 391_700) < 1_000) and np.all(
        np.abs(xyz[:, 1] - 5_820_000) < 5_000
    )
    frame = LocalFrame.at_map_point(MappingFrame.from_user_input("EPSG:32633"), xyz.mean(axis=0))
    centres, mloc = eo_map_to_local(xyz, np.array([utm.eo[n][3:] for n in names]), frame)
    cam = utm.camera
    o = utm.obs
    got = np.empty((len(o.image_id), 2))
    for i, (img, pid) in enumerate(zip(o.image_id, o.point_id)):
        k = names.index(img)
        q = (frame.map_to_enu(utm.points[pid][None]) - centres[k]) @ mloc[k].T
        got[i] = cam.pixel_from_ideal(-cam.focal_mm * q[:, :2] / q[:, 2:])[0] - o.pixels[i]
    np.testing.assert_allclose(o.pixels, local.obs.pixels, atol=1e-9)
    worst = float(np.max(np.abs(got - residuals(local))))
    print(f"UTM vs LOCAL: {worst:.2e} px")
    assert worst < 1e-3, worst  # px; limited by the CRS round trips
