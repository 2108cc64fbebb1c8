"""Automatic boresight calibration (core.photo.auto_boresight, auto_ties) on a block of four
images rendered by the project's renderer over three hip-roof houses, with a known boresight,
INS noise of the POS AV 310 grade and an initial boresight that is 0.3 and 1 degree off."""

from __future__ import annotations

import csv
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.frames import MappingFrame
from lidarphoto.core.geometry.planes import fit_plane
from lidarphoto.core.geometry.surface import Dsm
from lidarphoto.core.lidar.control import ControlLine
from lidarphoto.core.lidar.dsm import dsm_from_points
from lidarphoto.core.photo.auto_boresight import (
    AutoBoresightOptions,
    SceneNotObservable,
    auto_calibrate,
    scene_refusal,
)
from lidarphoto.core.photo.auto_ties import associate_ties
from lidarphoto.core.photo.boresight import calibrate
from lidarphoto.core.photo.boresight_options import BoresightOptions
from lidarphoto.core.photo.georeference import Trajectory, direct_georeference
from lidarphoto.core.photo.ins import ins_grade
from lidarphoto.core.photo.mount import Mount
from lidarphoto.core.photo.observations import ImageObservations
from lidarphoto.core.photo.picking import PickingScene
from lidarphoto.core.simulation.render import render_image
from lidarphoto.core.simulation.render_scene import RenderOptions, RenderScene

CRS = "EPSG:28992"
X0, Y0 = 85000.0, 447000.0
TRUTH_DEG = np.array([0.3, -0.2, 0.25])
HOUSES = (((-8.0, 7.0), 25.0), ((7.0, 9.0), -40.0), ((0.0, -8.0), 70.0))
DIMS = (10.0, 7.0, 5.0, 0.8)  # length, width, eave height (m), roof slope (rise / run)


def _house(k: int, centre, turn_deg: float, dims=DIMS):
    """Roof points (N, 3) and face labels of one hip roof, its four planes' outlines (house
    frame u along, v across) and its ridge and hip lines (end points), mapping CRS."""
    LENGTH, WIDTH, EAVE, SLOPE = dims
    c, s = math.cos(math.radians(turn_deg)), math.sin(math.radians(turn_deg))
    rot = np.array([[c, -s], [s, c]])
    r = LENGTH / 2 - WIDTH / 2
    top = EAVE + SLOPE * WIDTH / 2

    def m(u, v, h):
        return np.r_[np.asarray(centre) + rot @ [u, v], h]

    L2, W2 = LENGTH / 2, WIDTH / 2
    outlines = [
        [m(-L2, W2, EAVE), m(L2, W2, EAVE), m(r, 0, top), m(-r, 0, top)],
        [m(-L2, -W2, EAVE), m(L2, -W2, EAVE), m(r, 0, top), m(-r, 0, top)],
        [m(L2, W2, EAVE), m(L2, -W2, EAVE), m(r, 0, top)],
        [m(-L2, W2, EAVE), m(-L2, -W2, EAVE), m(-r, 0, top)],
    ]
    segs = {(0, 1): (m(-r, 0, top), m(r, 0, top)), (0, 2): (m(r, 0, top), m(L2, W2, EAVE)),
            (1, 2): (m(r, 0, top), m(L2, -W2, EAVE)), (0, 3): (m(-r, 0, top), m(-L2, W2, EAVE)),
            (1, 3): (m(-r, 0, top), m(-L2, -W2, EAVE))}  # fmt: skip
    lines = []
    for j, ((a, b), (p, q)) in enumerate(segs.items()):
        u = (q - p) / np.linalg.norm(q - p)
        lines.append(ControlLine(10 * k + j + 1, (10 * k + a, 10 * k + b), "hip" if j else "ridge",
                                 p, q, p, u, np.eye(6) * 1e-6, 90.0))  # fmt: skip
    return rot, outlines, lines


def _scene(houses=HOUSES, dims=DIMS, seed=7):
    LENGTH, WIDTH, EAVE, SLOPE = dims
    rng = np.random.default_rng(seed)
    n = 12 * 50 * 50
    xy = rng.uniform(-25, 25, (n, 2))
    z = np.zeros(n)
    cls = np.full(n, 2)
    pid = np.full(n, -1)
    lines, outlines = [], {}
    for k, (centre, turn) in enumerate(houses):
        rot, rings, house_lines = _house(k, centre, turn, dims)
        lines += house_lines
        uv = (xy - centre) @ rot  # house frame
        on = (np.abs(uv[:, 0]) < LENGTH / 2) & (np.abs(uv[:, 1]) < WIDTH / 2)
        a = WIDTH / 2 - np.abs(uv[:, 1])
        b = LENGTH / 2 - np.abs(uv[:, 0])
        face = np.where(a <= b, np.where(uv[:, 1] >= 0, 0, 1), np.where(uv[:, 0] >= 0, 2, 3))
        z = np.where(on, EAVE + SLOPE * np.minimum(a, b), z)
        cls = np.where(on, 6, cls)
        pid = np.where(on, 10 * k + face, pid)
        for j, ring in enumerate(rings):
            outlines[10 * k + j] = np.array(ring)
    pts = np.column_stack([xy + [X0, Y0], z])
    for ln in lines:
        for name in ("start", "end", "point"):
            object.__setattr__(ln, name, getattr(ln, name) + [X0, Y0, 0.0])
    planes = [fit_plane(pts[pid == i], plane_id=i).with_outline(outlines[i] + [X0, Y0, 0.0])
              for i in sorted(outlines)]  # fmt: skip
    heights, grid = dsm_from_points(pts[:, 0], pts[:, 1], pts[:, 2], 0.5)
    dsm = Dsm(heights, grid, MappingFrame.from_user_input(CRS).crs)
    scene = RenderScene.build(dsm, pts, cls, pid, planes, lines, crs=CRS)
    return scene, dsm, planes, lines, pts, pid


def _trajectory(rng, noise: bool) -> Trajectory:
    pos = np.array([[-4, 2, 150], [4, 2, 150], [4, -2, 150], [-4, -2, 150.0]]) + [X0, Y0, 0]
    rph = np.radians([[0.4, -0.3, 90], [-0.2, 0.5, 90], [0.3, 0.2, 270], [-0.5, -0.1, 270.0]])
    if noise:  # POS AV 310: 0.02 m, 0.05 m, 0.015 deg, 0.035 deg
        pos = pos + rng.normal(0, 1, (4, 3)) * [0.02, 0.02, 0.05]
        rph = rph + np.radians(rng.normal(0, 1, (4, 3)) * [0.015, 0.015, 0.035])
    return Trajectory(("a", "b", "c", "d"), np.arange(4.0), ("E", "E", "W", "W"), pos, False, rph)


@pytest.fixture(scope="module")
def lidar():
    """The scene: render scene, DSM, planes (with outlines), lines, points and plane ids."""
    return _scene()


@pytest.fixture(scope="module")
def block(lidar):
    scene, dsm, planes, lines, _pts, _pid = lidar
    cam = Camera("c", focal_mm=35.0, pixel_size_mm=0.012, width_px=800, height_px=600)
    frame = MappingFrame.from_user_input(CRS)
    rng = np.random.default_rng(11)
    true_mount = Mount.from_parameters(boresight_deg=TRUTH_DEG)
    true_eo = direct_georeference(_trajectory(rng, False), true_mount, frame)
    images = [(iid, render_image(scene, cam, true_eo.xyz[k], true_eo.opk[k],
                                 RenderOptions(step_px=4, seed=k)).rgb)
              for k, iid in enumerate(true_eo.image_id)]  # fmt: skip
    return cam, frame, true_eo, _trajectory(rng, True), images, planes, lines, dsm


def _ties(cam, true_eo, planes, rng):
    """Tie tracks as a matcher gives them (0.3 px noise) on roof points inside the faces, and
    planted wrong tracks: ground, a tree crown over a roof, a wall, a wrong match."""
    sc = PickingScene(true_eo, cam)
    good, xyz = [], []
    for p in planes:
        ring = p.outline
        centre = ring.mean(axis=0)
        for _ in range(6):
            w = rng.dirichlet(np.ones(len(ring)))
            q = 0.5 * centre + 0.5 * (w @ ring)  # well inside the face
            q[2] = -(p.normal[:2] @ (q[:2] - p.centroid[:2])) / p.normal[2] + p.centroid[2]
            good.append(p.id)
            xyz.append(q)
    a = planes[0]
    planted = {
        "ground": np.array([X0 + 14.0, Y0 - 2.0, 0.0]),
        "tree": np.r_[a.outline.mean(axis=0)[:2], a.outline.mean(axis=0)[2] + 2.0],
        "wall": np.r_[0.5 * (a.outline[0][:2] + a.outline[1][:2]), 2.5],
    }
    rows = {"img": [], "pid": [], "px": []}

    def add(name, points):
        for k, iid in enumerate(true_eo.image_id):
            px = sc.project(iid, points[k % len(points)][None])[0]
            if np.isfinite(px).all() and cam.in_frame(px[None], 5.0)[0]:
                rows["img"].append(iid)
                rows["pid"].append(name)
                rows["px"].append(px + rng.normal(0, 0.3, 2))

    for k, q in enumerate(xyz):
        add(f"t{k}", [q])
    for name, q in planted.items():
        add(name, [q])
    add("mismatch", [planes[1].outline.mean(axis=0), planes[5].outline.mean(axis=0)])
    n = len(rows["img"])
    obs = ImageObservations.from_arrays(rows["img"], rows["pid"], np.array(rows["px"]),
                                        np.full(n, 0.3), ["tie"] * n, [""] * n)  # fmt: skip
    return obs, {f"t{k}": g for k, g in enumerate(good)}


def test_ties_on_roofs_associated_and_planted_ones_refused(block):
    cam, _frame, true_eo, _traj, _images, planes, _lines, dsm = block
    ties, truth = _ties(cam, true_eo, planes, np.random.default_rng(2))
    got = associate_ties(ties, true_eo, cam, planes, 0.15, dsm=dsm)
    assert got.tracks == len(truth) + 4
    for name in ("ground", "tree", "wall", "mismatch"):
        assert name not in got.plane_of, name
    assert got.reasons["no roof plane"] >= 1 and got.reasons["off the plane"] >= 1
    assert got.reasons["rays apart"] >= 1
    assert sum(got.reasons.values()) + got.associated == got.tracks
    wrong = [p for p, g in got.plane_of.items() if truth[p] != g]
    assert not wrong and got.associated >= 0.9 * len(truth), got.reasons
    assert set(got.observations.target_id) <= {str(p.id) for p in planes}


def _check_recovered(out, label):
    res = out.result
    err = np.degrees(res.boresight[0]) - TRUTH_DEG
    std = np.degrees(res.std[0])
    print(
        label,
        "err arcsec",
        np.round(err * 3600, 1),
        "std arcsec",
        np.round(std * 3600, 1),
        "rounds",
        len(out.rounds),
        [r.line_points for r in out.rounds],
    )
    assert out.converged and len(out.rounds) >= 2
    assert np.all(np.abs(err) < 3 * std), (err * 3600, std * 3600)
    # the bound: the boresight is the mean camera-INS attitude difference, so the INS attitude
    # priors alone (POS AV 310: 0.015 deg roll/pitch, 0.035 deg heading, 4 images) bound it
    # even with errorless image measurements
    bound = np.array([0.015, 0.015, 0.035]) / np.sqrt(4)
    assert np.all(std >= 0.99 * bound) and np.all(std <= 1.5 * bound), std / bound
    return err, std


def test_point_three_degrees_off_recovered_without_hand_picks(block):
    cam, frame, true_eo, traj, images, planes, lines, dsm = block
    ties, _ = _ties(cam, true_eo, planes, np.random.default_rng(3))
    start = Mount.from_parameters()  # nominal mount, zero boresight: 0.3 degree off
    out = auto_calibrate(traj, cam, start, frame, images, planes, lines, ties, dsm,
                         AutoBoresightOptions(search_deg=0.6),
                         BoresightOptions(groups="single"))  # fmt: skip
    _check_recovered(out, "0.3 deg")
    assert out.result.residuals.rejected.sum() <= 0.05 * len(out.observations)
    last = out.rounds[-1]
    assert last.line_points >= 200 and last.ties_associated >= 40
    assert last.ties_refused["no roof plane"] >= 1 and last.ties_refused["rays apart"] >= 1
    # check points: other roof points, measured at 0.3 px in each image and cut with their
    # LiDAR plane through the calibrated orientation (monoplotting), within 1.5 GSD in plan
    rng = np.random.default_rng(9)
    truth_sc, cal_sc = PickingScene(true_eo, cam), PickingScene(out.result.eo, cam)
    errors = []
    for p in planes:
        w = rng.dirichlet(np.ones(len(p.outline)))
        q = 0.5 * p.outline.mean(axis=0) + 0.5 * (w @ p.outline)
        q[2] = p.centroid[2] - (p.normal[:2] @ (q[:2] - p.centroid[:2])) / p.normal[2]
        for iid in true_eo.image_id:
            px = truth_sc.project(iid, q[None])[0]
            if np.isfinite(px).all() and cam.in_frame(px[None], 5.0)[0]:
                got, _ = cal_sc.ray_plane(iid, px + rng.normal(0, 0.3, 2), p.normal[None],
                                          p.centroid[None])  # fmt: skip
                errors.append(np.hypot(*(got[0, :2] - q[:2])))
    gsd = 150.0 / cam.focal_px  # at ground; roofs are nearer: a smaller GSD there
    rms = float(np.sqrt(np.mean(np.square(errors))))
    print(f"check points {len(errors)}: plan RMS {rms:.3f} m, max {max(errors):.3f} m")
    assert len(errors) >= 30 and rms < 1.5 * gsd


@pytest.mark.parametrize("extra", ["estimate_interior", "estimate_lever_arm", "estimate_timing"])
def test_interior_lever_arm_or_timing_estimated_with_the_boresight(block, extra):
    """The rendered flight with one more group of unknowns (the truth: the camera as rendered,
    a zero lever arm, no timing offset; the trajectory has no velocities: they are differenced
    from the two exposures of each line): the rounds converge, the boresight and the extra
    unknowns lie within 3 of their sigmas of the truth, and the sigmas are finite."""
    cam, frame, true_eo, traj, images, planes, lines, dsm = block
    ties, _ = _ties(cam, true_eo, planes, np.random.default_rng(3))
    out = auto_calibrate(traj, cam, Mount.from_parameters(), frame, images, planes, lines, ties,
                         dsm, AutoBoresightOptions(search_deg=0.6),
                         BoresightOptions(groups="single", **{extra: True}))  # fmt: skip
    res = out.result
    err = np.degrees(res.boresight[0]) - TRUTH_DEG
    std = np.degrees(res.std[0])
    assert out.converged and np.all(np.abs(err) < 3 * std), (err * 3600, std * 3600)
    if extra == "estimate_interior":
        got, sig = res.interior, res.interior_std
        truth = np.array([cam.focal_mm, cam.x0_mm, cam.y0_mm])
        assert res.lever_arm is None and res.timing_offset is None
    elif extra == "estimate_lever_arm":
        got, sig, truth = res.lever_arm, res.lever_arm_std, np.zeros(3)
        assert res.interior is None and res.timing_offset is None
    else:
        got, sig, truth = np.array([res.timing_offset]), np.array([res.timing_offset_std]), 0.0
        assert res.interior is None and res.lever_arm is None
    print(extra, "error", got - truth, "sigma", sig, "boresight err arcsec",
          np.round(err * 3600, 1), "std", np.round(std * 3600, 1))  # fmt: skip
    assert np.all(np.isfinite(sig)) and np.all(sig > 0)
    assert np.all(np.abs(got - truth) < 3 * sig), (got - truth, sig)


def test_one_degree_off_converges_from_lines_alone(block):
    cam, frame, _true_eo, traj, images, planes, lines, _dsm = block
    start = Mount.from_parameters(boresight_deg=TRUTH_DEG + [-0.9, 0.8, -0.6])
    out = auto_calibrate(traj, cam, start, frame, images, planes, lines,
                         options=AutoBoresightOptions(search_deg=1.2),
                         calibration=BoresightOptions(groups="single"))  # fmt: skip
    _check_recovered(out, "1 deg")


def _hand_picks(cam, eo, lines, rng, per_image=30, sigma_px=0.5):
    """What an operator clicks in the dock: ``per_image`` points on the LiDAR lines of each
    image, at their true projections + ``sigma_px`` of noise (type line)."""
    sc = PickingScene(eo, cam)
    rows = {"img": [], "pid": [], "px": [], "tid": []}
    for iid in eo.image_id:
        k = 0
        while k < per_image:
            ln = lines[rng.integers(len(lines))]
            px = sc.project(iid, (ln.start + rng.uniform(0.1, 0.9) * (ln.end - ln.start))[None])
            if np.isfinite(px).all() and cam.in_frame(px, 10.0)[0]:
                rows["img"].append(iid)
                rows["pid"].append(f"{iid}:{k}")
                rows["px"].append(px[0] + rng.normal(0, sigma_px, 2))
                rows["tid"].append(ln.id)
                k += 1
    n = len(rows["img"])
    return ImageObservations.from_arrays(
        rows["img"], rows["pid"], np.array(rows["px"]), np.full(n, sigma_px), ["line"] * n,
        rows["tid"],
    )  # fmt: skip


def test_exact_ins_gives_the_image_limited_precision(block):
    """Without INS noise (and with tight priors) the boresight error is the automatic line
    measurements' own: a few arc-seconds, within 3 of its sigmas, and its sigmas no larger
    than those of 30 hand picks per image (0.5 px) on the same lines."""
    cam, frame, _true_eo, _traj, images, planes, lines, _dsm = block
    exact = _trajectory(np.random.default_rng(0), False)
    tight = ins_grade("custom", (0.002, 0.002, 0.0002, 0.0002))
    out = auto_calibrate(exact, cam, Mount.from_parameters(), frame, images, planes, lines,
                         options=AutoBoresightOptions(search_deg=0.6),
                         calibration=BoresightOptions(groups="single",
                                                      ins_grade=tight))  # fmt: skip
    err = np.degrees(out.result.boresight[0]) - TRUTH_DEG
    std = np.degrees(out.result.std[0])
    print("exact INS err arcsec", np.round(err * 3600, 2), "std", np.round(std * 3600, 2))
    assert out.converged and np.all(np.abs(err) < 3 * std), (err * 3600, std * 3600)
    # omega, phi from the image shifts; kappa only from the small turn of lines off the centre
    assert np.all(std * 3600 < [5.0, 5.0, 30.0])
    picks = _hand_picks(cam, _true_eo, lines, np.random.default_rng(5))
    hand = calibrate(exact, cam, Mount.from_parameters(), frame, picks, planes, lines,
                     options=BoresightOptions(groups="single", ins_grade=tight))  # fmt: skip
    hand_std = np.degrees(hand.std[0])
    print("hand picks std arcsec", np.round(hand_std * 3600, 2))
    assert np.all(std <= hand_std), (std * 3600, hand_std * 3600)


def test_a_second_scene_and_camera_one_degree_off():
    """Four larger, flatter roofs, a 40 mm camera with radial distortion at 250 m, four images
    on two north-south lines, another boresight; 1 degree off; INS noise."""
    from lidarphoto.core.geometry.camera import camera_from_dict

    houses = (((-12.0, 8.0), 10.0), ((11.0, 6.0), 55.0), ((-6.0, -9.0), -30.0),
              ((10.0, -10.0), 85.0))  # fmt: skip
    scene, _dsm, planes, lines, _pts, _pid = _scene(houses, (14.0, 9.0, 7.0, 0.6), seed=3)
    cam = camera_from_dict({"name": "k1", "focal_mm": 40.0, "pixel_size_mm": 0.0075,
                            "width_px": 1000, "height_px": 750,
                            "distortion": {"model": "brown_conrady", "k1": 8e-5}})  # fmt: skip
    frame = MappingFrame.from_user_input(CRS)
    truth = np.array([-0.25, 0.4, -0.15])
    pos = np.array([[-3, -5], [-3, 5], [3, 5], [3, -5.0]])
    pos = np.column_stack([pos + [X0, Y0], np.full(4, 250.0)])
    rng = np.random.default_rng(21)
    rph = np.radians(np.column_stack([rng.normal(0, 0.5, (4, 2)), [0, 0, 180, 180]]))
    ids = tuple(f"p{k}" for k in range(4))
    groups = ("N",) * 2 + ("S",) * 2
    true_traj = Trajectory(ids, np.arange(4.0), groups, pos, False, rph)
    eo = direct_georeference(true_traj, Mount.from_parameters(boresight_deg=truth), frame)
    images = [(iid, render_image(scene, cam, eo.xyz[k], eo.opk[k],
                                 RenderOptions(step_px=4, seed=10 + k)).rgb)
              for k, iid in enumerate(ids)]  # fmt: skip
    pos_noise = rng.normal(0, 1, (4, 3)) * [0.02, 0.02, 0.05]
    att_noise = np.radians(rng.normal(0, 1, (4, 3)) * [0.015, 0.015, 0.035])
    noisy = Trajectory(ids, np.arange(4.0), groups, pos + pos_noise, False, rph + att_noise)
    start = Mount.from_parameters(boresight_deg=truth + [0.8, -0.7, 0.5])
    out = auto_calibrate(noisy, cam, start, frame, images, planes, lines,
                         options=AutoBoresightOptions(search_deg=1.2),
                         calibration=BoresightOptions(groups="single"))  # fmt: skip
    err = np.degrees(out.result.boresight[0]) - truth
    std = np.degrees(out.result.std[0])
    print("second scene err arcsec", np.round(err * 3600, 1), "std", np.round(std * 3600, 1),
          "line points", [r.line_points for r in out.rounds])  # fmt: skip
    assert out.converged and np.all(np.abs(err) < 3 * std), (err * 3600, std * 3600)
    bound = np.array([0.015, 0.015, 0.035]) / np.sqrt(4)
    assert np.all(std >= 0.99 * bound) and np.all(std <= 1.5 * bound), std / bound
    assert out.result.residuals.rejected.sum() <= 0.05 * len(out.observations)


def test_flat_scene_is_refused_with_the_reason(block):
    *_, planes, lines, _dsm = block
    flat = [replace(p, normal=np.array([0.0, 0.0, 1.0]), slope_deg=0.0) for p in planes]
    why = scene_refusal(flat, [])
    assert "not" in why and "flat" in why and "0 LiDAR line direction" in why
    with pytest.raises(SceneNotObservable, match="cannot determine the boresight"):
        cam, frame, _t, traj, images, *_ = block
        auto_calibrate(traj, cam, Mount.from_parameters(), frame, images, flat, [])
    assert scene_refusal(planes, []) == "" and scene_refusal(flat, lines) == ""
    assert "1 LiDAR line direction" in scene_refusal(flat, lines[:1])


@pytest.fixture(scope="module")
def files(block, lidar, tmp_path_factory):
    """The block as files: images (PNG), camera JSON, trajectory CSV, line and plane tables,
    a LAS with plane_id (the outlines) and a tie-point CSV."""
    import cv2
    import laspy
    from lidarphoto.core.io.camera import write_camera_json
    from lidarphoto.core.io.control import write_lines_csv
    from lidarphoto.core.io.observations import write_observations_csv
    from lidarphoto.core.io.planes import write_planes_csv
    from lidarphoto.core.io.trajectory import write_trajectory_csv

    tmp_path = tmp_path_factory.mktemp("autoboresight")
    cam, _frame, true_eo, traj, images, planes, lines, _dsm = block
    *_, pts, pid = lidar
    folder = tmp_path / "images"
    folder.mkdir()
    for iid, rgb in images:
        cv2.imwrite(str(folder / f"{iid}.png"), cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR))
    write_camera_json(tmp_path / "camera.json", cam)
    write_trajectory_csv(tmp_path / "traj.csv", traj)
    write_lines_csv(tmp_path / "lines.csv", lines)
    write_planes_csv(tmp_path / "planes.csv", planes)
    header = laspy.LasHeader(point_format=3, version="1.2")
    header.offsets, header.scales = pts.min(axis=0), np.full(3, 0.001)
    header.add_extra_dim(laspy.ExtraBytesParams(name="plane_id", type=np.int32))
    las = laspy.LasData(header)
    las.x, las.y, las.z = pts.T
    las.plane_id = pid.astype(np.int32)
    las.write(tmp_path / "cloud.las")
    ties, _ = _ties(cam, true_eo, planes, np.random.default_rng(3))
    write_observations_csv(tmp_path / "ties.csv", ties)
    write_observations_csv(tmp_path / "picks.csv",
                           _hand_picks(cam, true_eo, lines, np.random.default_rng(8)))  # fmt: skip
    return tmp_path, {
        "IMAGES": [str(folder)], "CAMERA": str(tmp_path / "camera.json"),
        "TRAJECTORY": str(tmp_path / "traj.csv"), "CRS": CRS, "LINES": str(tmp_path / "lines.csv"),
        "PLANES": str(tmp_path / "planes.csv"), "CLOUD": str(tmp_path / "cloud.las"),
        "TIE_POINTS": str(tmp_path / "ties.csv"), "SEARCH": 0.6, "GROUPING": "single",
    }  # fmt: skip


def test_the_job_runs_from_files(block, files):
    """``autoboresight`` from the files: outputs, counts and the boresight within 3 sigma."""
    from lidarphoto.core.io.observations import read_observations_csv
    from lidarphoto.core.jobs import auto_boresight as job
    from lidarphoto.core.jobs.runner import run_job

    cam = block[0]
    tmp_path, inputs = files
    out = {k: str(tmp_path / f) for k, f in (("OUTPUT_TABLE", "bore.csv"), ("OUTPUT_EO", "eo.csv"),
           ("OUTPUT_OBSERVATIONS", "obs.csv"), ("OUTPUT_ROUNDS", "rounds.csv"),
           ("OUTPUT_HTML", "report.html"))}  # fmt: skip
    res = run_job(job, {**inputs, "HAND_PICKS": str(tmp_path / "picks.csv"), **out})
    assert res.results["ROUNDS"] >= 2 and res.results["TIES_ASSOCIATED"] >= 40
    assert res.results["LINE_POINTS"] >= 200
    row = next(csv.DictReader((tmp_path / "bore.csv").open()))
    got = np.array([float(row[f"d_{a}_deg"]) for a in ("omega", "phi", "kappa")])
    std = np.array([float(row[f"std_d_{a}_arcsec"]) for a in ("omega", "phi", "kappa")]) / 3600
    assert np.all(np.abs(got - TRUTH_DEG) < 3 * std), ((got - TRUTH_DEG) * 3600, std * 3600)
    found = read_observations_csv(tmp_path / "obs.csv", camera=cam)
    assert set(found.type) == {"line", "tie"}
    rounds = list(csv.DictReader((tmp_path / "rounds.csv").open()))
    assert len(rounds) == res.results["ROUNDS"] and "no roof plane" in rounds[-1]["ties_refused"]
    page = (tmp_path / "report.html").read_text()
    assert "round 1" in page and "tie measurements per plane" in page
    assert "hand picks, group all" in page and "automatic minus hand" in page
    at = page.index("automatic minus hand")
    print(page[at - 200 : at + 80])


def test_the_job_estimates_the_lever_arm_when_asked(block, files, tmp_path):
    """ESTIMATE_LEVER_ARM (and the other two flags) reach the adjustment through the spec:
    the lever arm is estimated and within 3 sigma of the truth (zero)."""
    from lidarphoto.core.jobs import auto_boresight as job
    from lidarphoto.core.jobs.runner import run_job
    from lidarphoto.core.jobs.spec import options_from, parse_values

    _, inputs = files
    v = parse_values(job.SPEC, {**inputs, "ESTIMATE_INTERIOR": True, "ESTIMATE_TIMING": True})
    opts = options_from(BoresightOptions, job.SPEC, v)
    assert opts.estimate_interior and opts.estimate_timing and not opts.estimate_lever_arm
    out = {"OUTPUT_TABLE": str(tmp_path / "b.csv"), "OUTPUT_EO": str(tmp_path / "e.csv"),
           "OUTPUT_OBSERVATIONS": str(tmp_path / "o.csv"),
           "OUTPUT_HTML": str(tmp_path / "r.html")}  # fmt: skip
    res = run_job(job, {**inputs, "ESTIMATE_LEVER_ARM": True, **out}).data.result
    assert res.lever_arm is not None and res.interior is None
    assert np.all(np.abs(res.lever_arm) < 3 * res.lever_arm_std), (res.lever_arm,
                                                                   res.lever_arm_std)


def test_the_job_finds_the_tie_points_itself(files, tmp_path):
    """No TIE_POINTS: the job runs the tie-point chain on the images (pairs from the
    footprints, least-squares refinement), associates the tracks with the roof planes and
    calibrates; FIND_TIES off leaves the lines alone. Progress reaches 1 and only rises."""
    from lidarphoto.core.jobs import auto_boresight as job
    from lidarphoto.core.jobs.runner import run_job

    _, inputs = files
    inputs = {**inputs, "TIE_POINTS": None}
    out = {"OUTPUT_TABLE": str(tmp_path / "b.csv"), "OUTPUT_EO": str(tmp_path / "e.csv"),
           "OUTPUT_OBSERVATIONS": str(tmp_path / "o.csv"),
           "OUTPUT_HTML": str(tmp_path / "r.html")}  # fmt: skip
    seen = []
    got = run_job(job, {**inputs, **out}, progress=seen.append)
    found = got.data
    res = found.result
    err = np.degrees(res.boresight[0]) - TRUTH_DEG
    std = np.degrees(res.std[0])
    last = found.rounds[-1]
    print("ties found: tracks", last.tie_tracks, "associated", last.ties_associated,
          "refused", last.ties_refused, "err arcsec", np.round(err * 3600, 1), "std",
          np.round(std * 3600, 1))  # fmt: skip
    assert last.tie_tracks > 0 and last.ties_associated > 0
    assert got.results["TIES_ASSOCIATED"] == last.ties_associated
    assert found.converged and np.all(np.abs(err) < 3 * std), (err * 3600, std * 3600)
    assert "tie points found" in (tmp_path / "r.html").read_text()
    assert seen and seen[-1] == pytest.approx(1.0) and np.all(np.diff(seen) >= -1e-12)
    alone = run_job(job, {**inputs, "FIND_TIES": False, **out}).data
    assert alone.rounds[-1].tie_tracks == 0 and alone.rounds[-1].ties_associated == 0


def test_the_job_refuses_bad_inputs_by_name(files, tmp_path):
    from lidarphoto.core.errors import InputError
    from lidarphoto.core.jobs import auto_boresight as job
    from lidarphoto.core.jobs.runner import run_job

    _, inputs = files
    out = {"OUTPUT_TABLE": str(tmp_path / "b.csv"), "OUTPUT_EO": str(tmp_path / "e.csv"),
           "OUTPUT_OBSERVATIONS": str(tmp_path / "o.csv"),
           "OUTPUT_HTML": str(tmp_path / "r.html")}  # fmt: skip
    with pytest.raises(InputError, match="TIE_POINTS need PLANES and CLOUD"):
        run_job(job, {**inputs, "CLOUD": None, **out})
    empty = tmp_path / "none"
    empty.mkdir()
    (empty / "x.png").write_bytes((Path(inputs["IMAGES"][0]) / "a.png").read_bytes())
    with pytest.raises(InputError, match="no image is named in the trajectory"):
        run_job(job, {**inputs, "IMAGES": [str(empty)], **out})
    assert not any(tmp_path.glob("*.csv")) and not any(tmp_path.glob("*.html"))


@pytest.mark.parametrize("sigma", [0.7, 3.6, 14.0])
def test_edge_strength_by_tiles_equals_the_whole_image_filter(sigma):
    """The search's edge strength, filtered tile by tile where it is sampled, is bit for bit
    the whole image's gradient magnitude (the tiles' margins cover the Gaussian's support,
    the image border reflects as in the whole image), and only the sampled tiles are done."""
    from lidarphoto.core.photo.auto_boresight import _EdgeStrength
    from scipy.ndimage import gaussian_gradient_magnitude, map_coordinates

    rng = np.random.default_rng(3)
    grey = (rng.random((700, 900)) * 255).astype(np.float32)
    whole = gaussian_gradient_magnitude(grey, sigma)
    edge = _EdgeStrength(grey, sigma)
    t = rng.random(400)  # samples along a diagonal line that leaves the image, and the corners
    rows = np.r_[-0.7 + 720 * t, 0.0, 699.0, 0.3, 698.6]
    cols = np.r_[5 + 300 * t, 0.0, 899.0, 898.7, 0.2]
    got = edge.sample(rows, cols)
    assert np.array_equal(got, map_coordinates(whole, [rows, cols], order=1))
    assert 0 < edge.done.mean() < 0.5, edge.done.mean()


def _counting(monkeypatch, owner, name: str, after: int, state: dict) -> None:
    """Replace ``owner.name`` by a wrapper that counts its calls and asks for the cancel
    (``state["stop"]``) once it has been called ``after`` times."""
    real = getattr(owner, name)

    def wrapper(*args, **kwargs):
        state["calls"] += 1
        try:
            return real(*args, **kwargs)
        finally:
            if state["calls"] >= after:
                state["stop"] = True

    monkeypatch.setattr(owner, name, wrapper)


@pytest.mark.parametrize(
    ("stage", "after", "doing"),
    [
        ("reading", 1, "reading the images (b.png)"),
        ("ties", 1, "detecting features (b)"),
        ("search", 5, "the boresight search"),
        ("edges", 1, "finding edges along the LiDAR lines (image b)"),
        ("adjustment", 1, "adjusting"),
    ],
)
def test_the_job_stops_within_one_step_of_a_cancel(files, tmp_path, monkeypatch, stage, after,
                                                   doing):  # fmt: skip
    """A cancel asked during a stage (reading the images, finding the tie points, the angle
    search, the edges along the lines, the adjustment) stops the job before the stage's next
    unit of work (image, candidate, adjustment iteration): the project's Cancelled error,
    naming what it was doing, and no output written."""
    from lidarphoto.core.errors import Cancelled
    from lidarphoto.core.io import images as images_io
    from lidarphoto.core.jobs import auto_boresight as job
    from lidarphoto.core.jobs.runner import run_job
    from lidarphoto.core.photo import auto_boresight as ab
    from lidarphoto.core.photo import auto_lines, tie_points

    _, inputs = files
    if stage == "ties":
        inputs = {**inputs, "TIE_POINTS": None}
    state = {"calls": 0, "stop": False}
    owner, name = {
        "reading": (images_io, "read_gray"),
        "ties": (tie_points, "detect_features"),
        "search": (ab._Search, "score"),
        "edges": (auto_lines, "line_observations"),
        "adjustment": (ab, "calibrate"),
    }[stage]
    if stage == "adjustment":  # the cancel is asked as the adjustment starts
        real = ab.calibrate

        def entering(*args, **kwargs):
            state["calls"] += 1
            state["stop"] = True
            return real(*args, **kwargs)

        monkeypatch.setattr(ab, "calibrate", entering)
    else:
        _counting(monkeypatch, owner, name, after, state)
    out = {"OUTPUT_TABLE": str(tmp_path / "b.csv"), "OUTPUT_EO": str(tmp_path / "e.csv"),
           "OUTPUT_OBSERVATIONS": str(tmp_path / "o.csv"),
           "OUTPUT_ROUNDS": str(tmp_path / "r.csv"),
           "OUTPUT_HTML": str(tmp_path / "r.html")}  # fmt: skip
    seen: list[float] = []
    with pytest.raises(Cancelled) as caught:
        run_job(job, {**inputs, **out}, progress=seen.append, should_stop=lambda: state["stop"])
    assert str(caught.value) == f"cancelled while {doing}"
    assert state["calls"] == after  # not one more image, candidate or adjustment
    assert list(tmp_path.iterdir()) == []
    assert np.all(np.diff(seen) >= -1e-12) and all(0.0 <= f <= 1.0 for f in seen)


def test_the_search_reports_its_progress_per_candidate(block, lidar):
    """The angle search reports its fraction of candidates done, rising to 1, many times (a
    24-Mpx search takes minutes: the bar moves while it runs)."""
    from lidarphoto.core.photo import auto_boresight as ab

    cam, frame, _t, traj, images, _planes, lines, _dsm = block
    calls = {"n": 0}
    real = ab._Search.score

    def counting(self, bore):
        calls["n"] += 1
        return real(self, bore)

    seen: list[float] = []
    mp = pytest.MonkeyPatch()
    mp.setattr(ab._Search, "score", counting)
    try:
        ab.search_boresight(traj, cam, Mount.from_parameters(), frame, images, lines,
                            AutoBoresightOptions(search_deg=0.6), progress=seen.append)  # fmt: skip
    finally:
        mp.undo()
    assert seen[-1] == 1.0 and np.all(np.diff(seen) >= 0)
    assert len(seen) >= calls["n"] // 8  # one report per 8 candidates
    assert max(np.diff([0.0, *seen])) < 0.1
    # the candidates counted in advance are those evaluated: no early 1, no jump at the end
    assert seen.count(1.0) == 1 and seen[-2] >= 1.0 - 8.5 / calls["n"], (seen[-3:], calls)
    print("search candidates", calls["n"], "progress reports", len(seen))


def _plant_wrong_edge(cam, true_eo, image, iid, line, shift_px):
    """``image`` with ``line``'s edge in image ``iid`` moved ``shift_px`` across it: a band
    about the true projection (Gaussian weight, 12 px across, faded towards the line's ends)
    blended into a grey step (60 grey units, 0.7 px wide) centred ``shift_px`` off."""
    p0, p1 = PickingScene(true_eo, cam).project(iid, np.array([line.start, line.end]))
    yy, xx = np.mgrid[0 : cam.height_px, 0 : cam.width_px] + 0.5
    d = p1 - p0
    length = float(np.linalg.norm(d))
    u = d / length
    s = ((xx - p0[0]) * u[0] + (yy - p0[1]) * u[1]) / length
    n = (xx - p0[0]) * -u[1] + (yy - p0[1]) * u[0]
    w = (np.exp(-((n / 12.0) ** 2)) * np.exp(-(((s - 0.5) / 0.35) ** 8)))[..., None]
    img = np.asarray(image, float)
    step = img[w[..., 0] > 0.5].mean(axis=0) + 30.0 * np.tanh((n - shift_px) / 0.7)[..., None]
    return np.clip((1 - w) * img + w * step, 0, 255).astype(np.uint8)


def test_a_segment_on_another_edge_is_dropped_not_its_line(block):
    """One line's edge moved 4 px in image a (within the 5-px search: the edge search lands on
    it): the image's segment screen drops that segment alone before the adjustment, the line's
    points in the other images are kept, nothing is rejected by snooping and the boresight is
    within 3 sigma; without the screen the wrong segment enters the adjustment."""
    from lidarphoto.core.photo.auto_lines import REFUSALS

    cam, frame, true_eo, traj, images, planes, lines, dsm = block
    line = lines[7]
    planted = [(iid, _plant_wrong_edge(cam, true_eo, img, iid, line, 4.0) if iid == "a" else img)
               for iid, img in images]  # fmt: skip
    ties, _ = _ties(cam, true_eo, planes, np.random.default_rng(3))
    opt = AutoBoresightOptions(search_deg=0.6)
    runs = {}
    for name, sigmas in (("screen", opt.lines.segment_sigmas), ("none", 1e6)):
        o = replace(opt, lines=replace(opt.lines, segment_sigmas=sigmas))
        runs[name] = auto_calibrate(traj, cam, Mount.from_parameters(), frame, planted,
                                    planes, lines, ties, dsm, o,
                                    BoresightOptions(groups="single"))  # fmt: skip
    tid = str(line.id)
    rows = {k: [i for i, t, y in zip(r.observations.image_id, r.observations.target_id,
                                     r.observations.type) if t == tid and y == "line"]
            for k, r in runs.items()}  # fmt: skip
    assert "a" in rows["none"], "the planted edge was not found: the test shows nothing"
    out = runs["screen"]
    assert "a" not in rows["screen"] and len(set(rows["screen"])) >= 2, rows["screen"]
    last = out.rounds[-1]
    assert 5 <= last.lines_refused[REFUSALS[1]] <= rows["none"].count("a") + 5
    assert last.rejected == 0
    _check_recovered(out, "planted")
