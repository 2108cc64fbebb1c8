"""COLMAP models in and out: the imported camera and orientation project the model's 3D points
where COLMAP's own formulas (colmap.github.io, written out independently here) put them."""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
import pytest
from lidarphoto.core.errors import CrsError, InputError
from lidarphoto.core.geometry.collinearity import project
from lidarphoto.core.io.colmap import read_colmap_model, write_colmap_text
from lidarphoto.core.io.colmap_block import (
    block_from_colmap,
    colmap_from_block,
    frame_from_text,
    quaternion_to_matrix,
)

W, H = 1600, 1200
MODEL_IDS = {"SIMPLE_PINHOLE": 0, "PINHOLE": 1, "SIMPLE_RADIAL": 2, "RADIAL": 3, "OPENCV": 4,
             "OPENCV_FISHEYE": 5, "FULL_OPENCV": 6, "FOV": 7, "SIMPLE_RADIAL_FISHEYE": 8,
             "RADIAL_FISHEYE": 9, "THIN_PRISM_FISHEYE": 10}  # fmt: skip
PARAMS = {
    "SIMPLE_PINHOLE": [1180.0, 801.3, 597.2],
    "PINHOLE": [1180.0, 1187.5, 801.3, 597.2],
    "SIMPLE_RADIAL": [1180.0, 801.3, 597.2, -0.11],
    "RADIAL": [1180.0, 801.3, 597.2, -0.11, 0.04],
    "OPENCV": [1180.0, 1183.0, 801.3, 597.2, -0.21, 0.07, 1.1e-3, -7e-4],
    "FULL_OPENCV": [1180.0, 1176.0, 801.3, 597.2, 0.1, -0.02, -5e-4, 8e-4, 0.003, 0.3, -0.01,
                    0.002],
    "OPENCV_FISHEYE": [640.0, 641.5, 801.3, 597.2, 0.04, -0.012, 0.003, -4e-4],
    "SIMPLE_RADIAL_FISHEYE": [640.0, 801.3, 597.2, 0.05],
    "RADIAL_FISHEYE": [640.0, 801.3, 597.2, 0.05, -0.01],
    "THIN_PRISM_FISHEYE": [640.0, 642.0, 801.3, 597.2, 0.03, -0.01, 6e-4, -4e-4, 0.002, -3e-4,
                           5e-4, -3e-4],
}  # fmt: skip
FISHEYE = ("OPENCV_FISHEYE", "SIMPLE_RADIAL_FISHEYE", "RADIAL_FISHEYE", "THIN_PRISM_FISHEYE")


def colmap_pixel(model: str, p: list[float], xc: np.ndarray) -> np.ndarray:
    """COLMAP's ImgFromCam for a camera-frame point (x right, y down, z forward), documented
    formulas: u = x/z, v = y/z, distortion, then fx u + cx, fy v + cy."""
    u, v = xc[:, 0] / xc[:, 2], xc[:, 1] / xc[:, 2]
    if model in ("SIMPLE_PINHOLE", "SIMPLE_RADIAL", "RADIAL", "SIMPLE_RADIAL_FISHEYE",
                 "RADIAL_FISHEYE"):  # fmt: skip
        fx = fy = p[0]
        cx, cy, extra = p[1], p[2], p[3:]
    else:
        fx, fy, cx, cy, extra = p[0], p[1], p[2], p[3], p[4:]
    r2 = u * u + v * v
    if model in ("SIMPLE_RADIAL", "RADIAL"):
        k1, k2 = (extra + [0.0])[:2]
        radial = k1 * r2 + k2 * r2 * r2
        du, dv = u * radial, v * radial
    elif model in ("OPENCV", "FULL_OPENCV"):
        k1, k2, p1, p2 = extra[:4]
        k3, k4, k5, k6 = (extra[4:] + [0.0] * 4)[:4]
        radial = (1 + k1 * r2 + k2 * r2**2 + k3 * r2**3) / (1 + k4 * r2 + k5 * r2**2 + k6 * r2**3)
        du = u * radial + 2 * p1 * u * v + p2 * (r2 + 2 * u * u) - u
        dv = v * radial + 2 * p2 * u * v + p1 * (r2 + 2 * v * v) - v
    elif model == "THIN_PRISM_FISHEYE":
        # on the equidistant normalised point (length theta): radial, tangential, thin prism
        k1, k2, p1, p2, k3, k4, sx1, sy1 = extra
        r = np.sqrt(r2)
        uu, vv = u * np.arctan(r) / r, v * np.arctan(r) / r
        t2 = uu * uu + vv * vv
        rad = k1 * t2 + k2 * t2**2 + k3 * t2**3 + k4 * t2**4
        xu = uu + uu * rad + 2 * p1 * uu * vv + p2 * (t2 + 2 * uu * uu) + sx1 * t2
        yv = vv + vv * rad + 2 * p2 * uu * vv + p1 * (t2 + 2 * vv * vv) + sy1 * t2
        du, dv = xu - u, yv - v
    elif model in FISHEYE:
        k = (extra + [0.0] * 4)[:4]
        r = np.sqrt(r2)
        th = np.arctan(r)
        t2 = th * th
        thd = th * (1 + k[0] * t2 + k[1] * t2**2 + k[2] * t2**3 + k[3] * t2**4)
        du, dv = u * thd / r - u, v * thd / r - v
    else:
        du = dv = np.zeros_like(u)
    return np.column_stack([fx * (u + du) + cx, fy * (v + dv) + cy])


def _random_rotation(rng: np.random.Generator) -> np.ndarray:
    q = rng.normal(size=4)
    return q / np.linalg.norm(q) * np.sign(q[0])


def build_model(models: list[str], n_images: int = 6, n_points: int = 80, seed: int = 1,
                offset: np.ndarray | None = None, in_front: float = 0.7,
                half_width_m: float = 20.0) -> dict:
    """Cameras, images looking at a cloud of points, and COLMAP's projections of them."""
    rng = np.random.default_rng(seed)
    off = np.zeros(3) if offset is None else offset
    pts = rng.uniform(-1, 1, size=(n_points, 3)) * np.array([1, 1, 0.04]) * half_width_m + off
    cams = {k + 1: (m, PARAMS[m]) for k, m in enumerate(models)}
    images = {}
    for i in range(n_images):
        cam_id = 1 + i % len(models)
        # a camera 60 m above, looking down (COLMAP z forward = world -z), tilted a little
        tilt = rng.normal(scale=0.08, size=3)
        rv = quaternion_to_matrix([1.0, *(0.5 * tilt)]) @ np.diag([1.0, -1.0, -1.0])
        centre = off + np.array([rng.uniform(-8, 8), rng.uniform(-8, 8), 60.0])
        t = -rv @ centre
        q = _rot_to_quat(rv)
        xc = (pts - centre) @ rv.T
        px = colmap_pixel(*cams[cam_id], xc)
        ok = (xc[:, 2] > 0) & np.all((px > 0) & (px < [W, H]), axis=1)
        ok &= rng.uniform(size=n_points) < in_front
        images[i + 1] = (q, t, cam_id, f"img_{i:03d}.jpg", px[ok], np.flatnonzero(ok) + 1)
    return {"cameras": cams, "images": images, "points": pts}


def _rot_to_quat(r: np.ndarray) -> list[float]:
    w = np.sqrt(max(0.0, 1 + np.trace(r))) / 2
    return [w, (r[2, 1] - r[1, 2]) / (4 * w), (r[0, 2] - r[2, 0]) / (4 * w),
            (r[1, 0] - r[0, 1]) / (4 * w)]  # fmt: skip


def _tracks(m: dict) -> dict[int, list[tuple[int, int]]]:
    tr: dict[int, list[tuple[int, int]]] = {k + 1: [] for k in range(len(m["points"]))}
    for iid, (_, _, _, _, _, pid) in m["images"].items():
        for j, p in enumerate(pid):
            tr[int(p)].append((iid, j))
    return tr


def write_text(folder: Path, m: dict) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    lines = ["# Camera list", *(f"{k} {name} {W} {H} " + " ".join(repr(v) for v in p)
                                for k, (name, p) in m["cameras"].items())]  # fmt: skip
    (folder / "cameras.txt").write_text("\n".join(lines) + "\n")
    lines = ["# Image list"]
    for iid, (q, t, cam, name, px, pid) in m["images"].items():
        lines.append(" ".join([str(iid), *(repr(float(v)) for v in (*q, *t)), str(cam), name]))
        kp = [f"{x!r} {y!r} {p}" for (x, y), p in zip(px.tolist(), pid.tolist())]
        kp.append("10.5 20.5 -1")  # a keypoint without a 3D point
        lines.append(" ".join(kp))
    (folder / "images.txt").write_text("\n".join(lines) + "\n")
    tr = _tracks(m)
    lines = ["# 3D point list"]
    for k, x in enumerate(m["points"]):
        track = " ".join(f"{i} {j}" for i, j in tr[k + 1])
        xs = " ".join(repr(float(v)) for v in x)
        lines.append(f"{k + 1} {xs} 200 100 50 0.4 {track}")
    (folder / "points3D.txt").write_text("\n".join(lines) + "\n")


def write_bin(folder: Path, m: dict) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    b = struct.pack("<Q", len(m["cameras"]))
    for k, (name, p) in m["cameras"].items():
        b += struct.pack("<iiQQ", k, MODEL_IDS[name], W, H) + struct.pack(f"<{len(p)}d", *p)
    (folder / "cameras.bin").write_bytes(b)
    b = struct.pack("<Q", len(m["images"]))
    for iid, (q, t, cam, name, px, pid) in m["images"].items():
        b += struct.pack("<I7dI", iid, *q, *t, cam) + name.encode() + b"\0"
        b += struct.pack("<Q", len(pid) + 1)
        for (x, y), p in zip(px.tolist(), pid.tolist()):
            b += struct.pack("<ddq", x, y, p)
        b += struct.pack("<ddq", 10.5, 20.5, -1)
    (folder / "images.bin").write_bytes(b)
    tr = _tracks(m)
    b = struct.pack("<Q", len(m["points"]))
    for k, x in enumerate(m["points"]):
        b += struct.pack("<Q3d3BdQ", k + 1, *x, 200, 100, 50, 0.4, len(tr[k + 1]))
        for i, j in tr[k + 1]:
            b += struct.pack("<ii", i, j)
    (folder / "points3D.bin").write_bytes(b)


def _residuals(block, m: dict) -> np.ndarray:
    """Pixels of the imported block's projections minus COLMAP's, every observation."""
    cams = {c.name: c for c in block.cameras}
    pts = dict(zip(block.points.point_id, block.points.xyz))
    out = []
    for k, name in enumerate(block.eo.image_id):
        sel = [j for j, i in enumerate(block.observations.image_id) if i == name]
        xyz = np.array([pts[block.observations.point_id[j]] for j in sel])
        eo = np.concatenate([block.eo.xyz[k], block.eo.opk[k]])
        ours = project(xyz, eo, cams[block.camera[k]])
        out.append(ours - block.observations.pixels[sel])
    return np.vstack(out)


@pytest.mark.parametrize("fmt", ["txt", "bin"])
@pytest.mark.parametrize("model", list(PARAMS))
def test_imported_block_projects_like_colmap(tmp_path: Path, fmt: str, model: str) -> None:
    # fisheyes: points up to about 70 degrees off the axis (60 m below, 160 m across)
    m = build_model([model], n_points=160, half_width_m=160.0 if model in FISHEYE else 20.0)
    (write_text if fmt == "txt" else write_bin)(tmp_path / "sparse", m)
    colmap = read_colmap_model(tmp_path / "sparse")
    block = block_from_colmap(colmap, frame_from_text("LOCAL"), pixel_size_mm=0.004)
    n_obs = sum(len(im[5]) for im in m["images"].values())
    assert len(block.observations.image_id) == n_obs > 150
    res = np.hypot(*_residuals(block, m).T)
    assert np.median(res) <= 0.01 and np.max(res) <= 0.05
    assert np.max(res) < 1e-6  # exact in fact
    assert block.cameras[0].projection == ("equidistant" if model in FISHEYE else "perspective")
    if model in FISHEYE:  # the wide field is covered, not only its centre
        cam, pts = block.cameras[0], block.points.xyz
        k = 0
        eo = np.concatenate([block.eo.xyz[k], block.eo.opk[k]])
        px = project(pts, eo, cam)
        ok = cam.in_frame(px)
        off_axis = np.degrees(np.arctan2(np.hypot(*(pts[ok, :2] - block.eo.xyz[k, :2]).T),
                                         block.eo.xyz[k, 2] - pts[ok, 2]))  # fmt: skip
        assert off_axis.max() > 60.0


def test_several_cameras_and_a_similarity(tmp_path: Path) -> None:
    m = build_model(["OPENCV", "PINHOLE", "RADIAL_FISHEYE"], n_images=9)
    write_text(tmp_path / "m", m)
    colmap = read_colmap_model(tmp_path / "m")
    s, q, t = 2.5, [0.9, 0.1, -0.3, 0.2], np.array([1000.0, -500.0, 20.0])
    sim = " ".join(str(v) for v in (s, *q, *t))
    block = block_from_colmap(colmap, frame_from_text("LOCAL", similarity=sim), 0.004)
    assert sorted(set(block.camera)) == ["colmap_1", "colmap_2", "colmap_3"]
    res = np.hypot(*_residuals(block, m).T)
    assert np.max(res) < 1e-6
    # the centres moved by the similarity (not a no-op)
    plain = block_from_colmap(colmap, frame_from_text("LOCAL"), 0.004)
    rq = quaternion_to_matrix(q)
    np.testing.assert_allclose(block.eo.xyz, s * plain.eo.xyz @ rq.T + t, atol=1e-9)


def test_camera_frame_sign_convention(tmp_path: Path) -> None:
    """A COLMAP camera looking straight down with image y along world -Y has omega = phi =
    kappa = 0 in the project (its camera looks along -z, image y up = world +Y)."""
    m = build_model(["SIMPLE_PINHOLE"], n_images=1)
    rv = np.diag([1.0, -1.0, -1.0])
    centre = np.array([3.0, 4.0, 60.0])
    m["images"][1] = ([0.0, 1.0, 0.0, 0.0], -rv @ centre, 1, "a.jpg", np.zeros((0, 2)),
                      np.zeros(0, dtype=int))  # fmt: skip
    write_text(tmp_path / "m", m)
    block = block_from_colmap(read_colmap_model(tmp_path / "m"), frame_from_text("LOCAL"), 0.004)
    np.testing.assert_allclose(block.eo.xyz[0], centre, atol=1e-12)
    np.testing.assert_allclose(block.eo.opk[0], 0.0, atol=1e-12)


def test_ecef_frame_projects_in_the_local_frame(tmp_path: Path) -> None:
    pytest.importorskip("pyproj")
    from lidarphoto.core.geometry.frames import LocalFrame, MappingFrame
    from lidarphoto.core.photo.orientation import eo_map_to_local

    mapping = MappingFrame.from_user_input("EPSG:32723")
    ecef0 = mapping.map_to_ecef(np.array([[500000.0, 7400000.0, 800.0]]))[0]
    m = build_model(["OPENCV"], offset=ecef0)  # a block in ECEF axes near the origin point
    write_text(tmp_path / "m", m)
    block = block_from_colmap(read_colmap_model(tmp_path / "m"),
                              frame_from_text("ECEF", crs="EPSG:32723"), 0.004)  # fmt: skip
    assert abs(block.eo.xyz[0, 0] - 500000) < 100 and "32723" in block.eo.crs_wkt
    local = LocalFrame.at_map_point(mapping, block.eo.xyz.mean(axis=0))
    centres, mloc = eo_map_to_local(block.eo.xyz, block.eo.opk, local)
    pts_local = local.map_to_enu(block.points.xyz)
    pid = {p: k for k, p in enumerate(block.points.point_id)}
    cam = block.cameras[0]
    worst = 0.0
    for k, name in enumerate(block.eo.image_id):
        sel = [j for j, i in enumerate(block.observations.image_id) if i == name]
        x = pts_local[[pid[block.observations.point_id[j]] for j in sel]]
        q = (x - centres[k]) @ mloc[k].T
        ideal = -cam.focal_mm * q[:, :2] / q[:, 2:]
        px = cam.pixel_from_ideal(ideal)
        worst = max(worst, float(np.max(np.abs(px - block.observations.pixels[sel]))))
    assert worst < 1e-3  # px; limited by the CRS round trips (mm-level in ECEF)


def test_export_then_import_is_exact(tmp_path: Path) -> None:
    m = build_model(["FULL_OPENCV", "OPENCV_FISHEYE", "THIN_PRISM_FISHEYE"], n_images=6)
    write_text(tmp_path / "a", m)
    block = block_from_colmap(read_colmap_model(tmp_path / "a"), frame_from_text("LOCAL"), 0.004)
    out = colmap_from_block(block.cameras, block.eo, block.camera, block.observations,
                            block.points)  # fmt: skip
    write_colmap_text(tmp_path / "b", out)
    again = read_colmap_model(tmp_path / "b")
    assert [c.model for c in again.cameras.values()] == ["FULL_OPENCV", "OPENCV_FISHEYE",
                                                         "THIN_PRISM_FISHEYE"]  # fmt: skip
    for c_in, c_out in zip(read_colmap_model(tmp_path / "a").cameras.values(),
                           again.cameras.values()):  # fmt: skip
        np.testing.assert_allclose(c_out.params, c_in.params, rtol=1e-12, atol=1e-15)
    block2 = block_from_colmap(again, frame_from_text("LOCAL"), 0.004)
    assert np.max(np.hypot(*_residuals(block2, m).T)) < 1e-6
    np.testing.assert_allclose(block2.eo.xyz, block.eo.xyz, atol=1e-9)


def test_bad_input_is_named(tmp_path: Path) -> None:
    with pytest.raises(CrsError, match="no coordinate reference system"):
        frame_from_text("")
    with pytest.raises(CrsError, match="ECEF"):
        frame_from_text("ECEF")
    m = build_model(["OPENCV"], n_images=2)
    write_text(tmp_path / "u", m)
    text = (tmp_path / "u" / "cameras.txt").read_text().replace("OPENCV", "WEIRD_MODEL")
    (tmp_path / "u" / "cameras.txt").write_text(text)
    with pytest.raises(InputError, match="unknown COLMAP camera model 'WEIRD_MODEL'"):
        read_colmap_model(tmp_path / "u")
    m["cameras"][1] = ("FOV", [1000.0, 1000.0, 800.0, 600.0, 0.9])
    write_text(tmp_path / "f", m)
    with pytest.raises(InputError, match="FOV is not supported"):
        block_from_colmap(read_colmap_model(tmp_path / "f"), frame_from_text("LOCAL"), 0.004)
    write_bin(tmp_path / "t", build_model(["OPENCV"], n_images=2))
    data = (tmp_path / "t" / "images.bin").read_bytes()
    (tmp_path / "t" / "images.bin").write_bytes(data[:-5])
    with pytest.raises(InputError, match="truncated"):
        read_colmap_model(tmp_path / "t")


def test_command_line_import_then_export(tmp_path: Path, capsys) -> None:
    from lidarphoto.core.cli import main as cli_main
    from lidarphoto.core.io.camera import read_cameras_json
    from lidarphoto.core.io.orientation import read_eo_csv_full

    m = build_model(["OPENCV", "OPENCV_FISHEYE"], n_images=6)
    write_bin(tmp_path / "sparse", m)
    cams = tmp_path / "sparse" / "cameras.bin"
    rc = cli_main(["importcolmap", "--input", str(cams), "--pixel-size", "0.004"])
    err = capsys.readouterr().err
    assert rc == 2 and "FRAME: a COLMAP model has no coordinate reference system" in err
    assert not list(tmp_path.glob("*.csv"))
    names = (("camera", "cam.json"), ("eo", "eo.csv"), ("observations", "obs.csv"),
             ("points", "pts.csv"))  # fmt: skip
    out = {k: tmp_path / f for k, f in names}
    rc = cli_main(["importcolmap", "--input", str(cams), "--frame", "LOCAL",
                   *(a for k, p in out.items() for a in (f"--output-{k}", str(p)))])  # fmt: skip
    assert rc == 0, capsys.readouterr().err
    eo = read_eo_csv_full(out["eo"])
    assert eo.camera is not None and len(eo.eo) == 6
    assert [c.projection for c in read_cameras_json(out["camera"], ("perspective",
            "equidistant"))] == ["perspective", "equidistant"]  # fmt: skip
    rc = cli_main(["exportcolmap", "--camera", str(out["camera"]), "--eo", str(out["eo"]),
                   "--observations", str(out["observations"]), "--points", str(out["points"]),
                   "--output-folder", str(tmp_path / "back")])  # fmt: skip
    assert rc == 0, capsys.readouterr().err
    again = read_colmap_model(tmp_path / "back")
    block = block_from_colmap(again, frame_from_text("LOCAL"), 0.004)
    res = np.hypot(*_residuals(block, m).T)
    assert np.max(res) < 1e-6 and len(block.observations.image_id) > 150


def test_export_refuses_a_correction_lens(tmp_path: Path) -> None:
    from lidarphoto.core.geometry.camera import Camera
    from lidarphoto.core.geometry.distortion import BrownConrady

    m = build_model(["PINHOLE"], n_images=2)
    write_text(tmp_path / "a", m)
    block = block_from_colmap(read_colmap_model(tmp_path / "a"), frame_from_text("LOCAL"), 0.004)
    cam = Camera("bc", 4.0, 0.004, W, H, distortion=BrownConrady(k1=-1e-3))
    with pytest.raises(InputError, match=r"'brown_conrady'.*no exact COLMAP camera model"):
        colmap_from_block([cam], block.eo)
