"""Automatic boresight calibration of a 10-image flight of 24-Mpx images (issue 32, speed):
the data, the two command lines timed as whole processes, and the accuracy of their results
against the simulated truth (bench/auto_boresight.md).

The flight: the three hip-roof houses of tests/core/test_auto_boresight.py (the project's
renderer, core/simulation/render.py), a 24-Mpx frame camera (6000 x 4000 px, 3.9 um pixels,
85 mm: GSD 6.9 mm at 150 m), two east-west lines of five exposures (4 m apart, 4 m between the
lines, opposite headings), a true boresight of (0.3, -0.2, 0.25) degrees, INS noise of the POS
AV 310 grade, the approximate boresight zero (0.3 degree off) with the default search of 1
degree. The images are written as JPEG (quality 92) with the camera, trajectory, LiDAR lines,
planes, the cloud with plane ids and 30 hand picks per image (0.5 px, on the LiDAR lines:
what an operator clicks in the dock) to ``--data`` (default: a folder under the temporary
directory), made once and reused (delete the folder to remake it; it is not committed).

Usage:
    python bench/auto_boresight.py                 # make the data (once), print the commands
    python bench/auto_boresight.py --run           # and run each once, times and accuracy
    python bench/auto_boresight.py --check DIR     # accuracy of the outputs written in DIR

The commands are meant to be timed from outside as whole processes (e.g. ``/usr/bin/time -v``
over several runs): A is ``lidarphoto autoboresight`` on the images (tie points found in the
run), B is ``lidarphoto boresightcalibration`` on the hand picks (the dock-picking workflow's
adjustment alone).
"""

from __future__ import annotations

import argparse
import csv
import shlex
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
TRUTH_DEG = np.array([0.3, -0.2, 0.25])
CRS = "EPSG:28992"
N_IMAGES = 10


def _helpers():
    """The scene and the hand picks of the tests (one scene for both)."""
    sys.path.insert(0, str(ROOT / "tests" / "core"))
    import test_auto_boresight as t

    return t


def _trajectory(noise: np.random.Generator | None):
    """Two lines of five exposures, 1 s apart (velocities from neighbouring exposures): the
    true poses, or with ``noise`` those plus INS errors of the POS AV 310 grade. The roll and
    pitch (0.4 degree of turbulence) are drawn once from a fixed seed, so both share them (the
    first version drew them again for the noisy trajectory: the trajectory written differed
    from the rendered poses by some 0.5 degree, far beyond the INS noise)."""
    from lidarphoto.core.photo.georeference import Trajectory

    t = _helpers()
    xs = np.arange(-8.0, 8.1, 4.0)
    pos = np.vstack([np.column_stack([xs, np.full(5, 2.0), np.full(5, 150.0)]),
                     np.column_stack([xs[::-1], np.full(5, -2.0), np.full(5, 150.0)])])
    pos = pos + [t.X0, t.Y0, 0.0]
    tilt = np.random.default_rng(11).normal(0, 0.4, (N_IMAGES, 2))
    rph = np.radians(np.column_stack([tilt, np.r_[np.full(5, 90.0), np.full(5, 270.0)]]))
    if noise is not None:  # POS AV 310: 0.02 m, 0.05 m, 0.015 deg, 0.035 deg
        pos = pos + noise.normal(0, 1, (N_IMAGES, 3)) * [0.02, 0.02, 0.05]
        rph = rph + np.radians(noise.normal(0, 1, (N_IMAGES, 3)) * [0.015, 0.015, 0.035])
    ids = tuple(f"img{k:02d}" for k in range(N_IMAGES))
    return Trajectory(ids, np.arange(float(N_IMAGES)), ("E",) * 5 + ("W",) * 5, pos, False,
                      rph)


def make(data: Path, step_px: int) -> None:
    """Render the flight and write every input (skipped when ``data/ready`` exists)."""
    import cv2
    import laspy
    from lidarphoto.core.geometry.camera import Camera
    from lidarphoto.core.geometry.frames import MappingFrame
    from lidarphoto.core.io.camera import write_camera_json
    from lidarphoto.core.io.control import write_lines_csv
    from lidarphoto.core.io.observations import write_observations_csv
    from lidarphoto.core.io.planes import write_planes_csv
    from lidarphoto.core.io.trajectory import write_trajectory_csv
    from lidarphoto.core.photo.georeference import direct_georeference
    from lidarphoto.core.photo.mount import Mount
    from lidarphoto.core.simulation.render import render_image
    from lidarphoto.core.simulation.render_scene import RenderOptions

    # the trajectory is cheap: always rewritten (data made by the first version had a wrong
    # one, see _trajectory); the images are rendered once
    data.mkdir(parents=True, exist_ok=True)
    write_trajectory_csv(data / "traj.csv", _trajectory(np.random.default_rng(12)))
    if (data / "ready").exists():
        return
    t = _helpers()
    (data / "images").mkdir(parents=True, exist_ok=True)
    scene, _dsm, planes, lines, pts, pid = t._scene()
    cam = Camera("24mpx", focal_mm=85.0, pixel_size_mm=0.0039, width_px=6000, height_px=4000)
    frame = MappingFrame.from_user_input(CRS)
    true_eo = direct_georeference(_trajectory(None),
                                  Mount.from_parameters(boresight_deg=TRUTH_DEG), frame)
    start = time.perf_counter()
    for k, iid in enumerate(true_eo.image_id):
        rgb = render_image(scene, cam, true_eo.xyz[k], true_eo.opk[k],
                           RenderOptions(step_px=step_px, seed=k)).rgb
        cv2.imwrite(str(data / "images" / f"{iid}.jpg"), cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR),
                    [cv2.IMWRITE_JPEG_QUALITY, 92])
        print(f"rendered {iid} ({time.perf_counter() - start:.0f} s)", flush=True)
    write_camera_json(data / "camera.json", cam)
    write_lines_csv(data / "lines.csv", lines)
    write_planes_csv(data / "planes.csv", planes)
    header = laspy.LasHeader(point_format=3, version="1.2")
    header.offsets, header.scales = pts.min(axis=0), np.full(3, 0.001)
    header.add_extra_dim(laspy.ExtraBytesParams(name="plane_id", type=np.int32))
    las = laspy.LasData(header)
    las.x, las.y, las.z = pts.T
    las.plane_id = pid.astype(np.int32)
    las.write(data / "cloud.las")
    picks = t._hand_picks(cam, true_eo, lines, np.random.default_rng(8), per_image=30)
    write_observations_csv(data / "picks.csv", picks)
    (data / "ready").write_text("ok\n")


def commands(data: Path, out: Path) -> tuple[list[str], list[str]]:
    """(A: autoboresight on the images, B: boresightcalibration on the hand picks)."""
    exe = str(Path(sys.executable).with_name("lidarphoto"))
    common = ["--camera", str(data / "camera.json"), "--trajectory", str(data / "traj.csv"),
              "--crs", CRS, "--lines", str(data / "lines.csv"), "--planes",
              str(data / "planes.csv"), "--grouping", "single"]
    a = [exe, "autoboresight", "--images", str(data / "images"), *common,
         "--cloud", str(data / "cloud.las"),
         "--output-table", str(out / "auto_bore.csv"), "--output-eo", str(out / "auto_eo.csv"),
         "--output-observations", str(out / "auto_obs.csv"),
         "--output-rounds", str(out / "auto_rounds.csv"),
         "--output-html", str(out / "auto.html")]
    b = [exe, "boresightcalibration", *common, "--observations", str(data / "picks.csv"),
         "--output-table", str(out / "hand_bore.csv"), "--output-eo", str(out / "hand_eo.csv"),
         "--output-html", str(out / "hand.html")]
    return a, b


def check(out: Path) -> None:
    """Each result against the truth: error and sigma per angle (arc-seconds)."""
    for name in ("auto", "hand"):
        path = out / f"{name}_bore.csv"
        if not path.exists():
            continue
        row = next(csv.DictReader(s for s in path.open() if not s.startswith("#")))
        got = np.array([float(row[f"d_{a}_deg"]) for a in ("omega", "phi", "kappa")])
        std = np.array([float(row[f"std_d_{a}_arcsec"]) for a in ("omega", "phi", "kappa")])
        err = (got - TRUTH_DEG) * 3600
        print(f"{name}: error {np.round(err, 1)} arcsec, sigma {np.round(std, 1)} arcsec, "
              f"|error| / sigma {np.round(np.abs(err) / std, 2)}")
    rounds = out / "auto_rounds.csv"
    if rounds.exists():
        first = next(csv.DictReader(rounds.open()))
        # the angle search's result: round 1's boresight less its change from the search
        search = np.array([float(first[f"d_{a}_deg"]) - float(first[f"change_d_{a}_arcsec"])
                           / 3600 for a in ("omega", "phi", "kappa")])
        print(f"angle search: {np.round(search, 4)} deg, error "
              f"{np.round((search - TRUTH_DEG) * 3600, 1)} arcsec")
        for r in csv.DictReader(rounds.open()):
            print(f"round {r['round']}: line points {r['line_points']} on {r['lines_seen']} "
                  f"lines, tie tracks {r['tie_tracks']}, on planes {r['ties_associated']}, "
                  f"refused {r['ties_refused']}, rejected {r['rejected']}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", type=Path,
                    default=Path(tempfile.gettempdir()) / "lidarphoto-bench-autoboresight")
    ap.add_argument("--step-px", type=int, default=4, help="renderer's DSM ray step")
    ap.add_argument("--run", action="store_true", help="run A and B once each")
    ap.add_argument("--check", type=Path, help="accuracy of the outputs in this folder")
    args = ap.parse_args()
    if args.check:
        check(args.check)
        return
    make(args.data, args.step_px)
    out = args.data / "out"
    out.mkdir(exist_ok=True)
    a, b = commands(args.data, out)
    print("A:", shlex.join(a))
    print("B:", shlex.join(b))
    if args.run:
        for name, cmd in (("A", a), ("B", b)):
            start = time.perf_counter()
            r = subprocess.run(cmd, capture_output=True, text=True)
            print(f"{name}: exit {r.returncode}, {time.perf_counter() - start:.1f} s wall")
            if r.returncode:
                print(r.stderr[-3000:])
        check(out)


if __name__ == "__main__":
    main()
