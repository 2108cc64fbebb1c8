"""OpenSfM / ODM reconstructions in: the imported camera and orientation project the points
where OpenSfM's own formulas (opensfm.org camera models, written out independently here) put
them."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from lidarphoto.core.errors import CrsError, InputError
from lidarphoto.core.geometry.collinearity import project
from lidarphoto.core.io.opensfm import block_from_opensfm, read_opensfm

Rotation = pytest.importorskip("scipy.spatial.transform").Rotation

W, H = 1600, 1200
CAMERAS = {
    "perspective": {"focal": 0.74, "k1": -0.12, "k2": 0.03},
    "simple_radial": {"focal_x": 0.74, "focal_y": 0.742, "c_x": 0.004, "c_y": -0.003,
                      "k1": -0.09},
    "radial": {"focal_x": 0.74, "focal_y": 0.737, "c_x": -0.006, "c_y": 0.002, "k1": -0.09,
               "k2": 0.02},
    "brown": {"focal_x": 0.74, "focal_y": 0.745, "c_x": 0.005, "c_y": -0.004, "k1": -0.2,
              "k2": 0.06, "k3": -0.01, "p1": 1.2e-3, "p2": -8e-4},
    "fisheye": {"focal": 0.40, "k1": 0.03, "k2": -0.01},
    "fisheye_opencv": {"focal": 0.40, "aspect_ratio": 1.003, "c_x": 0.003, "c_y": -0.002,
                       "k1": 0.04, "k2": -0.012, "k3": 0.003, "k4": -4e-4},
}  # fmt: skip


def opensfm_normalised(kind: str, p: dict, xc: np.ndarray) -> np.ndarray:
    """OpenSfM's projection of camera-frame points (x right, y down, z forward) to its
    normalised image coordinates (units of max(width, height), origin at the centre)."""
    x, y = xc[:, 0] / xc[:, 2], xc[:, 1] / xc[:, 2]
    r2 = x * x + y * y
    fx = p.get("focal", p.get("focal_x"))
    fy = p.get("focal_y", fx * p.get("aspect_ratio", 1.0))
    cx, cy = p.get("c_x", 0.0), p.get("c_y", 0.0)
    if kind.startswith("fisheye"):
        r = np.sqrt(r2)
        th = np.arctan(r)
        k = [p.get(f"k{i}", 0.0) for i in (1, 2, 3, 4)]
        thd = th * (1 + k[0] * th**2 + k[1] * th**4 + k[2] * th**6 + k[3] * th**8)
        xd, yd = x * thd / r, y * thd / r
    else:
        k1, k2, k3 = (p.get(k, 0.0) for k in ("k1", "k2", "k3"))
        p1, p2 = p.get("p1", 0.0), p.get("p2", 0.0)
        d = 1 + k1 * r2 + k2 * r2**2 + k3 * r2**3
        xd = x * d + 2 * p1 * x * y + p2 * (r2 + 2 * x * x)
        yd = y * d + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y
    return np.column_stack([fx * xd + cx, fy * yd + cy])


def project_pixel(xn: np.ndarray) -> np.ndarray:
    """OpenSfM's denormalisation (its pixel centres at integers: u = x size - 0.5 + w / 2),
    then + 0.5 for the project's convention (first pixel's centre at 0.5)."""
    size = max(W, H)
    return np.column_stack([xn[:, 0] * size - 0.5 + W / 2, xn[:, 1] * size - 0.5 + H / 2]) + 0.5


def build(folder: Path, kinds: list[str], n_shots: int = 6, n_points: int = 160, seed: int = 2,
          half_width_m: float = 20.0, lla: tuple | None = (-23.2, -45.1, 812.0)) -> dict:
    """A reconstruction.json and tracks.csv of shots 60 m above a cloud of points; returns
    the expected pixels per (shot, point)."""
    rng = np.random.default_rng(seed)
    pts = rng.uniform(-1, 1, size=(n_points, 3)) * np.array([1, 1, 0.04]) * half_width_m
    cams = {f"cam {k}": {"projection_type": kind, "width": W, "height": H, **CAMERAS[kind]}
            for k, kind in enumerate(kinds)}  # fmt: skip
    shots, lines, expected = {}, ["OPENSFM_TRACKS_VERSION_v2"], {}
    for i in range(n_shots):
        cid = f"cam {i % len(kinds)}"
        tilt = rng.normal(scale=0.08, size=3)
        rv = Rotation.from_rotvec(tilt).as_matrix() @ np.diag([1.0, -1.0, -1.0])
        centre = np.array([rng.uniform(-8, 8), rng.uniform(-8, 8), 60.0])
        t = -rv @ centre
        name = f"IMG_{i:04d}.JPG"
        shots[name] = {"camera": cid, "rotation": Rotation.from_matrix(rv).as_rotvec().tolist(),
                       "translation": t.tolist(), "gps_position": centre.tolist()}  # fmt: skip
        xc = (pts - centre) @ rv.T
        xn = opensfm_normalised(cams[cid]["projection_type"], cams[cid], xc)
        px = project_pixel(xn)
        ok = (xc[:, 2] > 0) & np.all((px > 0) & (px < [W, H]), axis=1)
        ok &= rng.uniform(size=n_points) < 0.7
        for j in np.flatnonzero(ok):
            xy = "\t".join(repr(float(v)) for v in xn[j])
            lines.append(f"{name}\t{j}\t{100 + j}\t{xy}\t0.004\t200\t100\t50\t-1\t-1")
            expected[(name, str(j))] = px[j]
    points = {str(j): {"coordinates": pts[j].tolist(), "color": [200, 100, 50]}
              for j in range(n_points)}  # fmt: skip
    rec: dict = {"cameras": cams, "shots": shots, "points": points}
    if lla is not None:
        rec["reference_lla"] = dict(zip(("latitude", "longitude", "altitude"), lla))
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "reconstruction.json").write_text(json.dumps([rec, {"cameras": {}, "shots": {}}]))
    (folder / "tracks.csv").write_text("\n".join(lines) + "\n")
    return {"expected": expected, "points": pts, "rec": rec}


def _residuals(block, expected: dict) -> np.ndarray:
    cams = {c.name: c for c in block.cameras}
    pts = dict(zip(block.points.point_id, block.points.xyz))
    out = []
    for k, name in enumerate(block.eo.image_id):
        sel = [j for j, i in enumerate(block.observations.image_id) if i == name]
        xyz = np.array([pts[block.observations.point_id[j]] for j in sel])
        eo = np.concatenate([block.eo.xyz[k], block.eo.opk[k]])
        ours = project(xyz, eo, cams[block.camera[k]])
        want = np.array([expected[(name, block.observations.point_id[j])] for j in sel])
        np.testing.assert_allclose(block.observations.pixels[sel], want, atol=1e-9)
        out.append(ours - want)
    return np.vstack(out)


@pytest.mark.parametrize("kind", list(CAMERAS))
def test_imported_block_projects_like_opensfm(tmp_path: Path, kind: str) -> None:
    fisheye = kind.startswith("fisheye")
    m = build(tmp_path, [kind], half_width_m=160.0 if fisheye else 20.0)
    block = block_from_opensfm(read_opensfm(tmp_path / "reconstruction.json"), "", 0.004)
    assert len(block.observations.image_id) == len(m["expected"]) > 150
    assert block.eo.crs_wkt == "" and len(block.eo) == 6
    res = np.hypot(*_residuals(block, m["expected"]).T)
    assert np.median(res) <= 0.01 and np.max(res) <= 0.05
    assert np.max(res) < 1e-6  # exact in fact
    assert block.cameras[0].projection == ("equidistant" if fisheye else "perspective")
    got = dict(zip(block.points.point_id, block.points.xyz))
    np.testing.assert_allclose([got[str(j)] for j in range(len(m["points"]))], m["points"],
                               atol=1e-12)  # fmt: skip


def test_several_cameras_and_the_folder(tmp_path: Path) -> None:
    m = build(tmp_path, ["brown", "perspective", "fisheye"], n_shots=9)
    block = block_from_opensfm(read_opensfm(tmp_path), "", 0.004)
    assert sorted(set(block.camera)) == ["opensfm_cam 0", "opensfm_cam 1", "opensfm_cam 2"]
    assert np.max(np.hypot(*_residuals(block, m["expected"]).T)) < 1e-6
    with pytest.raises(InputError, match="no shot"):
        block_from_opensfm(read_opensfm(tmp_path, 1), "", 0.004)


def test_camera_frame_sign_convention(tmp_path: Path) -> None:
    """A shot looking straight down with image y along world -Y has omega = phi = kappa = 0."""
    m = build(tmp_path, ["perspective"], n_shots=1)
    rec = m["rec"]
    name = next(iter(rec["shots"]))
    rec["shots"][name]["rotation"] = [np.pi, 0.0, 0.0]  # diag(1, -1, -1)
    rec["shots"][name]["translation"] = [-3.0, 4.0, 60.0]  # t = -R C, C = (3, 4, 60)
    (tmp_path / "reconstruction.json").write_text(json.dumps([rec]))
    (tmp_path / "tracks.csv").unlink()
    block = block_from_opensfm(read_opensfm(tmp_path), "", 0.004)
    np.testing.assert_allclose(block.eo.xyz[0], [3.0, 4.0, 60.0], atol=1e-12)
    np.testing.assert_allclose(block.eo.opk[0], 0.0, atol=1e-12)


def test_reference_lla_into_utm(tmp_path: Path) -> None:
    pyproj = pytest.importorskip("pyproj")
    from lidarphoto.core.geometry.frames import LocalFrame, MappingFrame
    from lidarphoto.core.photo.orientation import eo_map_to_local

    lla = (-23.2, -45.1, 812.0)
    m = build(tmp_path, ["brown"], lla=lla)
    rec = m["rec"]
    del rec["reference_lla"]  # ODM's way: reference_lla.json beside the reconstruction
    (tmp_path / "reconstruction.json").write_text(json.dumps([rec]))
    (tmp_path / "reference_lla.json").write_text(json.dumps(
        dict(zip(("latitude", "longitude", "altitude"), lla))))  # fmt: skip
    block = block_from_opensfm(read_opensfm(tmp_path), "EPSG:32723", 0.004)
    assert "32723" in block.eo.crs_wkt
    # independent peer: ENU -> ECEF by the textbook rotation, then PROJ's ECEF -> UTM
    lat, lon = np.radians(lla[:2])
    to_ecef = pyproj.Transformer.from_crs("EPSG:4979", "EPSG:4978", always_xy=True)
    x0 = np.array(to_ecef.transform(lla[1], lla[0], lla[2]))
    e = [-np.sin(lon), np.cos(lon), 0.0]
    n = [-np.sin(lat) * np.cos(lon), -np.sin(lat) * np.sin(lon), np.cos(lat)]
    u = [np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)]
    ecef = x0 + m["points"] @ np.array([e, n, u])
    to_utm = pyproj.Transformer.from_crs("EPSG:4978", "EPSG:32723", always_xy=True)
    utm = np.column_stack(to_utm.transform(*ecef.T))
    pid = {p: k for k, p in enumerate(block.points.point_id)}
    got = block.points.xyz[[pid[str(j)] for j in range(len(m["points"]))]]
    np.testing.assert_allclose(got, utm, atol=1e-6)
    # the images still project onto OpenSfM's pixels, in a local frame of the map
    mapping = MappingFrame.from_user_input("EPSG:32723")
    local = LocalFrame.at_map_point(mapping, block.eo.xyz.mean(axis=0))
    centres, mloc = eo_map_to_local(block.eo.xyz, block.eo.opk, local)
    pts_local = local.map_to_enu(block.points.xyz)
    cam = block.cameras[0]
    worst = 0.0
    for k, name in enumerate(block.eo.image_id):
        sel = [j for j, i in enumerate(block.observations.image_id) if i == name]
        x = pts_local[[pid[block.observations.point_id[j]] for j in sel]]
        q = (x - centres[k]) @ mloc[k].T
        px = cam.pixel_from_ideal(-cam.focal_mm * q[:, :2] / q[:, 2:])
        want = np.array([m["expected"][(name, block.observations.point_id[j])] for j in sel])
        worst = max(worst, float(np.max(np.abs(px - want))))
    assert worst < 1e-3  # px; limited by the CRS round trips


def test_bad_input_is_named(tmp_path: Path) -> None:
    m = build(tmp_path, ["brown"], n_shots=2)
    rec = m["rec"]
    path = tmp_path / "reconstruction.json"

    def rewrite(change) -> None:
        r = json.loads(json.dumps(rec))
        change(r)
        path.write_text(json.dumps([r]))

    rewrite(lambda r: r["cameras"]["cam 0"].update(projection_type="weird"))
    with pytest.raises(InputError, match="camera 'cam 0': unknown OpenSfM projection type 'weird'"):
        read_opensfm(path)
    rewrite(lambda r: r["cameras"]["cam 0"].update(projection_type="spherical"))
    with pytest.raises(InputError, match="'spherical' is not supported"):
        read_opensfm(path)
    rewrite(lambda r: r["cameras"]["cam 0"].pop("p2"))
    with pytest.raises(InputError, match="camera 'cam 0': key 'p2' is missing"):
        read_opensfm(path)
    rewrite(lambda r: r["shots"]["IMG_0001.JPG"].pop("translation"))
    with pytest.raises(InputError, match=r"reconstruction.json.*shot 'IMG_0001.JPG': key "
                                         "'translation' must be three numbers"):  # fmt: skip
        read_opensfm(path)
    rewrite(lambda r: r.pop("shots"))
    with pytest.raises(InputError, match="key 'shots' is missing"):
        read_opensfm(path)
    rewrite(lambda r: r.pop("reference_lla"))
    with pytest.raises(InputError, match="no reference_lla"):
        block_from_opensfm(read_opensfm(path), "EPSG:32723", 0.004)
    rewrite(lambda r: None)
    with pytest.raises(CrsError):
        block_from_opensfm(read_opensfm(path), "EPSG:4326", 0.004)  # not projected
    path.write_text("{not json")
    with pytest.raises(InputError, match="not a JSON file"):
        read_opensfm(path)


def test_command_line(tmp_path: Path, capsys) -> None:
    from lidarphoto.core.cli import main as cli_main
    from lidarphoto.core.io.camera import read_cameras_json
    from lidarphoto.core.io.orientation import read_eo_csv_full

    build(tmp_path / "opensfm", ["brown", "fisheye"], n_shots=4)
    out = {k: tmp_path / f for k, f in (("camera", "cam.json"), ("eo", "eo.csv"),
                                        ("observations", "obs.csv"))}  # fmt: skip
    rc = cli_main(["importopensfm", "--input", str(tmp_path / "opensfm" / "reconstruction.json"),
                   "--crs", "EPSG:32723",
                   *(a for k, p in out.items() for a in (f"--output-{k}", str(p)))])  # fmt: skip
    assert rc == 0, capsys.readouterr().err
    eo = read_eo_csv_full(out["eo"])
    assert eo.camera is not None and len(eo.eo) == 4
    assert abs(eo.eo.xyz[0, 0] - 500000) < 50000
    assert [c.projection for c in read_cameras_json(out["camera"], ("perspective",
            "equidistant"))] == ["perspective", "equidistant"]  # fmt: skip
