"""The main job end to end on bundled data (``make demo``); outputs in ``demo_output/``.

1. Direct georeferencing of the sample trajectory (``lidarphoto trajectorytoeo``).
2. The real AHN3 tile tests/data/ahn3/ahn3_delft_crop60.laz (60 m x 60 m of Delft,
   EPSG:7415) through the command line: ``groundfilter`` -> ``extractroofplanes`` ->
   ``createlcps`` (roof planes, ridge/hip lines, three-plane control points).
3. A calibration flight simulated over those real roofs (``simulate_flight_over``): two
   opposite lines of a 24 Mpx camera at 130 m with a known boresight and lever arm, INS noise
   of an Applanix POS AV 310, 0.5 px image noise; tie points on the LiDAR planes, points on
   the LiDAR lines, the LCPs, and check points on the roofs.
4. ``lidarphoto boresightcalibration`` (tie + line + LCP, one boresight per flight line).
5. Check points intersected from the images with the initial (uncalibrated) and the calibrated
   orientations, against their true positions: ``lidarphoto accuracyreport`` for both.
6. The recovered boresight against the truth.
7. The images themselves, rendered by ray casting (``core.simulation.render``) from the camera
   and each image's *true* orientation onto the tile's DSM and roof planes, in flight/images/, and
   the check that the projected LiDAR lines fall on the rendered roof edges.
8. The boresight calibrated automatically from those rendered images (``lidarphoto
   autoboresight``: no observation file; tie points found between the images and associated
   with the LiDAR roof planes, image edges found along the projected LiDAR lines, from an
   approximate boresight of 0), in auto_calibration/; its boresight against the truth, in
   sigmas, next to step 6's (the simulated picks), and the run's seconds. The exit code is 1
   when either calibration is beyond 4 sigma of the truth. By default on the first
   ``--auto-images-per-line`` (2) images of each flight line, 4 of the 10 (about 1.5 min
   of CPU); ``--auto`` runs it on all ten 24-Mpx images (6.7 min of CPU with the segment
   weighting: data snooping re-adjusts the whole block once per group it sets aside, issue 32,
   bench/auto_boresight.md), ``--no-auto`` skips it.
9. True orthophotos of the images on the LiDAR DSM with the calibrated orientation
   (``lidarphoto orthorectify``), and their orthomosaic with its seamlines (``lidarphoto
   orthomosaic``: the most nadir image per cell, ground occluded in one image filled from
   another), in ortho/.
10. The QGIS project demo_output/lidarphoto_demo.qgz (scripts/make_demo_project.py, run with
    QGIS's Python when one is installed): layers, DSM, the orthomosaic and the picking dock's
    session (docs/demo_project.md).

Steps 2-3, 7, 8 and 9 are functions (``lidar_step``, ``flight_step``, ``render_step``,
``auto_step``, ``ortho_step``) that tests/qgis/test_demo_project.py calls for a smaller demo
(fewer images, lower resolution).

Heights: the tile is in RD New + NAP; without the NAP geoid grid installed (PROJ), the
calibration treats the heights as ellipsoidal (EPSG:28992). The simulation is made in that
same frame, so this changes nothing in the comparison with the truth.
"""

from __future__ import annotations

import csv
import json
import os
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.frames import MappingFrame
from lidarphoto.core.io.control import read_lcps_csv, read_lines_csv
from lidarphoto.core.io.dsm import dsm_from_las, write_dsm
from lidarphoto.core.io.observations import read_observations_csv
from lidarphoto.core.io.orientation import read_eo_csv, write_eo_csv
from lidarphoto.core.io.planes import read_planes_csv
from lidarphoto.core.io.pointcloud import read_points
from lidarphoto.core.io.raster_write import write_rgb_tiff
from lidarphoto.core.io.tables import write_csv_atomic
from lidarphoto.core.io.trajectory import read_trajectory_csv
from lidarphoto.core.photo.boresight_setup import local_frame_for
from lidarphoto.core.photo.georeference import Trajectory, direct_georeference
from lidarphoto.core.photo.intersection import forward_intersection
from lidarphoto.core.photo.mount import Mount
from lidarphoto.core.photo.orientation import ExteriorOrientationTable
from lidarphoto.core.photo.picking import PickingScene
from lidarphoto.core.simulation.flight_over import (
    ControlFlightConfig,
    ControlFlightSimulation,
    simulate_flight_over,
)
from lidarphoto.core.simulation.render import edge_offsets, render_image
from lidarphoto.core.simulation.render_scene import RenderOptions, RenderScene

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "sample_data" / "trajectory_demo.csv"
TILE = ROOT / "tests" / "data" / "ahn3" / "ahn3_delft_crop60.laz"
OUT = ROOT / "demo_output"
CRS = "EPSG:28992"  # the tile's RD New, heights taken as ellipsoidal (module docstring)
ARCSEC = np.pi / (180.0 * 3600.0)
TRUE_BORESIGHT_DEG = (0.12, -0.25, 0.40)
LEVER_ARM = (0.10, -0.05, -0.20)
DSM_CELL = 0.5  # metres: about 2 AHN3 points per cell
ORTHO_GSD = 0.05  # metres: the orthomosaic's cell (the images' own GSD is 1.7 cm)
PROJECT_SCRIPT = ROOT / "scripts" / "make_demo_project.py"


def lidarphoto(*args: str) -> None:
    """Run one ``lidarphoto`` subcommand, echoing it (paths relative to the repository)."""
    shown = [str(Path(a).relative_to(ROOT)) if a.startswith(str(ROOT)) else a for a in args]
    print("\n$ lidarphoto " + " ".join(shown), flush=True)
    # One BLAS thread unless the user chose otherwise: the adjustments solve small systems
    # many times, and threaded BLAS only adds contention (step 8 on a 2-core machine with one
    # core busy: 1,300 s of CPU threaded against 110 s on one thread, the same result).
    env = dict(os.environ)
    for name in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        env.setdefault(name, "1")
    subprocess.run([sys.executable, "-m", "lidarphoto", *args], check=True, env=env)


def georeferencing_step() -> None:
    """Step 1: the sample trajectory (two opposite strips, SIRGAS 2000 / UTM 23S)."""
    eo_csv = OUT / "sample_exterior_orientation.csv"
    lidarphoto(
        "trajectorytoeo", "--input", str(SAMPLE), "--crs", "EPSG:31983",
        "--lever-arm", "0.12,-0.05,-1.35", "--mount", "image_top_forward",
        "--boresight", "0.012,-0.008,0.035", "--output-csv", str(eo_csv),
    )  # fmt: skip
    eo = read_eo_csv(eo_csv)
    traj = read_trajectory_csv(SAMPLE)
    frame = MappingFrame.from_user_input("EPSG:31983")
    theta = np.degrees(frame.grid_north_azimuth(frame.map_to_geodetic(traj.position)))
    gap = (np.degrees(eo.opk[:, 2]) + np.degrees(traj.rph[:, 2]) + theta + 180.0) % 360.0 - 180.0
    print(
        f"{len(eo)} images; kappa + heading + grid convergence within {np.abs(gap).max():.3f} "
        f"deg (roll/pitch/boresight); lever arm 1.35 m up: Z - INS height = "
        f"{np.mean(eo.xyz[:, 2] - traj.position[:, 2]):.3f} m"
    )


def write_points(path: Path, ids, xyz) -> None:
    write_csv_atomic(
        path, ("id", "e", "n", "h"), [(i, *(f"{v:.4f}" for v in p)) for i, p in zip(ids, xyz)]
    )


@dataclass(frozen=True)
class Lidar:
    """The outputs of the LiDAR step, read back."""

    folder: Path
    planes: list
    lines: list
    lcps: list
    xyz: np.ndarray
    classification: np.ndarray
    plane_id: np.ndarray


def lidar_step(lidar: Path, tile: Path = TILE) -> Lidar:
    """Step 2: ground filter, roof planes, LiDAR control of the real tile (command line)."""
    lidar.mkdir(parents=True, exist_ok=True)
    lidarphoto("groundfilter", "--input", str(tile), "--output-cloud", str(lidar / "ground.laz"))
    lidarphoto(
        "extractroofplanes", "--input", str(lidar / "ground.laz"),
        "--output-csv", str(lidar / "planes.csv"), "--output-cloud", str(lidar / "planes.laz"),
    )  # fmt: skip
    lidarphoto(
        "createlcps", "--planes", str(lidar / "planes.csv"), "--cloud", str(lidar / "planes.laz"),
        "--points-csv", str(lidar / "lcps.csv"), "--lines-csv", str(lidar / "lines.csv"),
    )  # fmt: skip
    arrays, _ = read_points(lidar / "planes.laz", ("x", "y", "z", "classification", "plane_id"))
    return Lidar(
        lidar,
        read_planes_csv(lidar / "planes.csv"),
        read_lines_csv(lidar / "lines.csv"),
        read_lcps_csv(lidar / "lcps.csv"),
        np.column_stack([arrays["x"], arrays["y"], arrays["z"]]),
        arrays["classification"],
        arrays["plane_id"],
    )


def flight_step(
    lidar: Lidar, flight: Path, camera: Camera | None = None, images_per_line: int = 5
) -> tuple[ControlFlightSimulation, dict[str, Path], ExteriorOrientationTable]:
    """Step 3: a flight simulated over the tile's roofs; writes its inputs, the truth and the
    true exterior orientation (flight/eo_true.csv, what the images are rendered with)."""
    xyz = lidar.xyz
    extra = {} if camera is None else {"camera": camera}
    config = ControlFlightConfig(
        crs=CRS,
        centre=tuple(float(v) for v in (xyz[:, :2].min(axis=0) + xyz[:, :2].max(axis=0)) / 2),
        true_boresight_deg=(TRUE_BORESIGHT_DEG,),
        lever_arm_m=LEVER_ARM,
        images_per_line=images_per_line,
        **extra,
    )
    sim = simulate_flight_over(
        lidar.planes, lidar.lines, lidar.lcps, xyz, lidar.plane_id, config, seed=5
    )
    paths = sim.write(flight)
    eo = true_eo(sim)
    write_eo_csv(flight / "eo_true.csv", eo)
    paths["eo_true"] = flight / "eo_true.csv"
    return sim, paths, eo


def true_eo(sim: ControlFlightSimulation) -> ExteriorOrientationTable:
    """The images' true exterior orientation (mapping CRS): the noise-free trajectory through
    the true lever arm and each group's true boresight."""
    t = sim.truth.trajectory
    frame = MappingFrame.from_user_input(sim.config.crs)
    xyz, opk = np.empty((len(t), 3)), np.empty((len(t), 3))
    groups = np.array(t.group)
    for g, bore in sim.truth.boresight.items():
        sel = groups == g
        sub = Trajectory(tuple(np.array(t.image_id)[sel]), t.time[sel], tuple(groups[sel]),
                         t.position[sel], t.geodetic, t.rph[sel])  # fmt: skip
        table = direct_georeference(sub, Mount(sim.truth.lever_arm, sim.mount.nominal, bore), frame)
        xyz[sel], opk[sel] = table.xyz, table.opk
    return ExteriorOrientationTable(t.image_id, t.time, t.group, xyz, opk, frame.crs.to_wkt())


def _wkt_polygon_z(ring: np.ndarray) -> str:
    closed = np.vstack([ring, ring[:1]])
    return "POLYGON Z ((" + ", ".join(f"{x:.4f} {y:.4f} {z:.4f}" for x, y, z in closed) + "))"


def render_step(
    lidar: Lidar,
    sim: ControlFlightSimulation,
    eo: ExteriorOrientationTable,
    images: Path,
    options: RenderOptions | None = None,
) -> dict:
    """Step 7: the DSM (lidar/dsm.tif), the plane outlines of the rendering
    (lidar/plane_outlines.csv, with WKT), the images rendered with the true orientation, and
    the distance from the projected LiDAR lines to the rendered edges. Returns the figures."""
    t0 = time.perf_counter()
    dsm = dsm_from_las(lidar.folder / "planes.laz", DSM_CELL, crs=CRS)
    write_dsm(lidar.folder / "dsm.tif", dsm)
    scene = RenderScene.build(dsm, lidar.xyz, lidar.classification, lidar.plane_id,
                              lidar.planes, lidar.lines, crs=CRS)  # fmt: skip
    outlines = scene.outlines()
    write_csv_atomic(
        lidar.folder / "plane_outlines.csv",
        ("id", "a", "b", "c", "d", "slope_deg", "aspect_deg", "n_points", "rms", "sigma_d", "wkt"),
        [
            (p.id, *(repr(float(v)) for v in (*p.normal, p.d, p.slope_deg, p.aspect_deg)),
             p.n_points, repr(float(p.rms)), repr(float(p.sigma_d)), _wkt_polygon_z(outlines[p.id]))
            for p in lidar.planes if p.id in outlines
        ],
    )  # fmt: skip
    prep_s = time.perf_counter() - t0
    cam = sim.camera
    opt = options or RenderOptions()
    seconds, offsets = [], []
    picking = PickingScene(eo, cam, CRS)  # the project's projection chain, not the renderer's
    ends = np.array([[ln.start, ln.end] for ln in lidar.lines]).reshape(-1, 3)
    pairs = [ln.plane_ids for ln in lidar.lines]
    images.mkdir(parents=True, exist_ok=True)
    for k, name in enumerate(eo.image_id):
        img = render_image(scene, cam, eo.xyz[k], eo.opk[k], _with_seed(opt, k))
        t1 = time.perf_counter()
        write_rgb_tiff(images / f"{name}.tif", img.rgb)
        seconds.append((img.seconds, time.perf_counter() - t1))
        px = picking.project(name, ends)
        off, _ = edge_offsets(img.plane_id, px[0::2], px[1::2], pairs)
        offsets.append(off)
    off = np.abs(np.concatenate(offsets)) if offsets else np.empty(0)
    render_s = np.array(seconds).reshape(-1, 2)
    figures = {
        "images": len(eo),
        "size_px": [cam.width_px, cam.height_px],
        "step_px": opt.step_px,
        "scene_s": round(prep_s, 2),
        "render_s_per_image": [round(float(v), 2) for v in render_s[:, 0]],
        "write_s_per_image": [round(float(v), 2) for v in render_s[:, 1]],
        "edge_profiles": int(off.size),
        "edge_offset_median_px": round(float(np.median(off)), 3) if off.size else None,
        "edge_offset_p95_px": round(float(np.percentile(off, 95)), 3) if off.size else None,
        "edge_within_1px": round(float(np.mean(off <= 1.0)), 4) if off.size else None,
    }
    return figures


def ortho_step(demo: Path, eo_csv: Path, gsd: float = ORTHO_GSD) -> dict:
    """Step 9: true orthophotos of the rendered images on the LiDAR DSM (ortho/orthophotos/),
    their orthomosaic (ortho/orthomosaic.tif) and seamlines (ortho/seamlines.csv), through the
    command line; returns the figures."""
    t0 = time.perf_counter()
    ortho = demo / "ortho"
    flight, lidar = demo / "flight", demo / "lidar"
    lidarphoto(
        "orthorectify", "--camera", str(flight / "camera.json"), "--eo", str(eo_csv),
        "--images", str(flight / "images"), "--dsm", str(lidar / "dsm.tif"), "--crs", CRS,
        "--gsd", repr(gsd), "--true-ortho", "true", "--output-folder", str(ortho / "orthophotos"),
    )  # fmt: skip
    t1 = time.perf_counter()
    lidarphoto(
        "orthomosaic", "--orthophotos", str(ortho / "orthophotos"), "--feather", "6",
        "--output", str(ortho / "orthomosaic.tif"),
        "--seamlines-csv", str(ortho / "seamlines.csv"),
    )  # fmt: skip
    t2 = time.perf_counter()
    return {"orthorectify_s": round(t1 - t0, 2), "orthomosaic_s": round(t2 - t1, 2),
            "gsd": gsd, "eo": eo_csv.name}  # fmt: skip


def auto_step(
    demo: Path, mount: str, per_line: int | None = None, hand_picks: bool = True
) -> dict:
    """Step 8: ``lidarphoto autoboresight`` on the rendered images (flight/images/*.tif) with
    the camera, trajectory, mount and an approximate boresight of 0, the LiDAR planes, lines
    and the cloud with plane ids (the planes' outlines), and no observation: the tie points
    are found between the images and the line points along the projected LiDAR lines. Outputs
    in auto_calibration/ (the simulated picks of step 3 given as hand picks to compare with).
    ``per_line``: only the first images of each flight line (a reduced run). With
    ``--accept-doubtful``: a run that fails its checks (e.g. data snooping rejecting more than
    its false alarms explain) still writes its outputs, each with the warning at its top; the
    warnings are printed and kept in the figures, and the comparison with the truth decides.
    Returns the figures: the seconds (wall, and the job's CPU: user + system), counts,
    warnings and the boresight per group against the truth."""
    flight, lidar, auto = demo / "flight", demo / "lidar", demo / "auto_calibration"
    auto.mkdir(parents=True, exist_ok=True)
    files = sorted((flight / "images").glob("*.tif"))
    if per_line is not None:
        by_line: dict[str, list[Path]] = {}
        for f in files:
            by_line.setdefault(f.stem.split("_")[0], []).append(f)
        files = [f for line in by_line.values() for f in line[:per_line]]
    picks = ["--hand-picks", str(flight / "observations.csv")] if hand_picks else []
    t0, c0 = time.perf_counter(), os.times()
    lidarphoto(
        "autoboresight", "--images", *map(str, files), "--camera", str(flight / "camera.json"),
        "--trajectory", str(flight / "trajectory.csv"), "--crs", CRS,
        "--lever-arm", ",".join(repr(v) for v in LEVER_ARM), "--mount", mount,
        "--boresight", "0,0,0", "--planes", str(lidar / "planes.csv"),
        "--lines", str(lidar / "lines.csv"), "--cloud", str(lidar / "planes.laz"), *picks,
        "--grouping", "group", "--output-table", str(auto / "boresight.csv"),
        "--output-eo", str(auto / "eo.csv"),
        "--output-observations", str(auto / "observations.csv"),
        "--output-rounds", str(auto / "rounds.csv"), "--output-html", str(auto / "summary.html"),
        "--accept-doubtful", "true",
    )  # fmt: skip
    seconds, c1 = time.perf_counter() - t0, os.times()
    cpu = (c1.children_user - c0.children_user) + (c1.children_system - c0.children_system)
    last = read_table(auto / "rounds.csv")[-1]
    with open(auto / "boresight.csv", encoding="utf-8") as fh:  # the job's doubts, if any
        warnings = [line[2:].strip() for line in fh if line.startswith("# ")]
    return {
        "images": [f.stem for f in files],
        "seconds": round(seconds, 1),
        "cpu_seconds": round(cpu, 1),
        "rounds": int(last["round"]),
        "line_points": int(last["line_points"]),
        "lines_seen": int(last["lines_seen"]),
        "tie_tracks": int(last["tie_tracks"]),
        "ties_associated": int(last["ties_associated"]),
        "ties_refused": last["ties_refused"],
        "groups": boresight_against_truth(auto / "boresight.csv"),
        "warnings": warnings,
    }


def read_table(path: Path) -> list[dict]:
    """The rows of one of the jobs' CSV tables (the ``# warning`` lines before the header
    skipped)."""
    with open(path, encoding="utf-8") as fh:
        return list(csv.DictReader(line for line in fh if not line.startswith("#")))


def boresight_against_truth(table: Path) -> list[dict]:
    """The boresight per group of a calibration's table (boresight.csv) against the truth:
    per angle the estimate, its sigma and the error (arc-seconds) and the error in sigmas."""
    true = np.array(TRUE_BORESIGHT_DEG) * 3600.0
    out = []
    for row in read_table(table):
        angles = {}
        for k, angle in enumerate(("omega", "phi", "kappa")):
            est = float(row[f"d_{angle}_arcsec"])
            sig = float(row[f"std_d_{angle}_arcsec"])
            err = est - true[k]
            angles[angle] = {"truth": true[k], "estimate": est, "sigma": sig, "error": err,
                             "error_sigmas": err / sig}  # fmt: skip
        out.append({"group": row["group"], "sigma0": float(row["sigma0"]), "angles": angles})
    return out


def print_comparison(picked: list[dict], auto: list[dict]) -> float:
    """Step 6's table (simulated picks) next to step 8's (automatic); returns the automatic
    calibration's largest |error| / sigma."""
    print("\nBoresight against the truth (arc-seconds): step 4 from the simulated picks, step 8 "
          "automatic (autoboresight, no pick)")  # fmt: skip
    print(f"{'group':6} {'angle':8} {'truth':>7} | {'picks':>7} {'sigma':>6} {'err/sig':>7} | "
          f"{'auto':>7} {'sigma':>6} {'err/sig':>7}")  # fmt: skip
    by_group = {g["group"]: g for g in picked}
    worst = 0.0
    for g in auto:
        hand = by_group.get(g["group"])
        for angle, a in g["angles"].items():
            h = hand["angles"][angle] if hand else None
            left = f"{h['estimate']:7.1f} {h['sigma']:6.1f} {h['error_sigmas']:7.2f}" if h else ""
            print(f"{g['group']:6} d_{angle:6} {a['truth']:7.1f} | {left:22} | {a['estimate']:7.1f}"
                  f" {a['sigma']:6.1f} {a['error_sigmas']:7.2f}")  # fmt: skip
            worst = max(worst, abs(a["error_sigmas"]))
    print(f"automatic: largest |error| / sigma {worst:.2f}")
    return worst


def _with_seed(options: RenderOptions, k: int) -> RenderOptions:
    from dataclasses import replace

    return replace(options, seed=options.seed + k)


def qgis_python() -> str | None:
    """A Python that imports qgis.core (the QGIS test venv, then the system one), or None."""
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen")
    for exe in (ROOT / ".venv-qgis" / "bin" / "python", Path("/usr/bin/python3")):
        if exe.exists():
            ok = subprocess.run([str(exe), "-c", "import qgis.core"], env=env,
                                capture_output=True).returncode == 0  # fmt: skip
            if ok:
                return str(exe)
    return None


def project_command(python: str = "/usr/bin/python3") -> list[str]:
    return [python, str(PROJECT_SCRIPT), "--demo", str(OUT)]


def project_step() -> Path | None:
    """Step 10: the QGIS project, made by a QGIS Python in its own process (or a hint)."""
    python = qgis_python()
    if python is None:
        print(
            "\nNo Python with QGIS found: the QGIS project was not made. With QGIS installed, "
            "make it with:\n  QT_QPA_PLATFORM=offscreen " + " ".join(project_command())
        )
        return None
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen", QGIS_PREFIX_PATH="/usr")
    env.setdefault("PROJ_DATA", "/usr/share/proj")
    env.setdefault("XDG_RUNTIME_DIR", "/tmp/xdg-lidarphoto")
    Path(env["XDG_RUNTIME_DIR"]).mkdir(mode=0o700, exist_ok=True)
    print("\n$ " + " ".join(project_command(python)), flush=True)
    subprocess.run(project_command(python), env=env, check=True)
    return OUT / "lidarphoto_demo.qgz"


def boresight_table(cal: Path, rmse: dict) -> tuple[list[dict], np.ndarray, float]:
    """Step 6's printout: the recovered boresight against the truth and the check points'
    RMSE; returns the table's rows, the truth (arc-seconds) and the largest |error| / sigma."""
    with open(cal / "boresight.csv", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    true = np.array(TRUE_BORESIGHT_DEG) * 3600.0
    print("\nRecovered boresight against the truth (arc-seconds; initial value 0):")
    print(f"{'group':6} {'angle':8} {'truth':>9} {'estimate':>10} {'sigma':>7} {'error':>8} "
          f"{'error/sigma':>12}")  # fmt: skip
    worst = 0.0
    for row in rows:
        for k, angle in enumerate(("omega", "phi", "kappa")):
            est = float(row[f"d_{angle}_arcsec"])
            sig = float(row[f"std_d_{angle}_arcsec"])
            err = est - true[k]
            worst = max(worst, abs(err) / sig)
            print(f"{row['group']:6} d_{angle:6} {true[k]:9.1f} {est:10.1f} {sig:7.1f} "
                  f"{err:8.1f} {err / sig:12.2f}")  # fmt: skip
    print(f"sigma0 {float(rows[0]['sigma0']):.3f}; largest |error| / sigma {worst:.2f}")
    print("\nCheck points intersected from the images (m, against the truth):")
    print(f"{'orientation':12} {'points':>6} {'RMSE E':>8} {'RMSE N':>8} {'RMSE H':>8}")
    for name, (n, e, nn, h) in rmse.items():
        print(f"{name:12} {n:6d} {e:8.3f} {nn:8.3f} {h:8.3f}")
    return rows, true, worst


def auto_report(args, cal: Path, mount: str) -> tuple[dict | None, float]:
    """Step 8 unless ``--no-auto``: autoboresight on the first ``--auto-images-per-line``
    rendered images of each flight line (all of them with ``--auto``) and its table next to
    step 6's; returns its figures and its largest |error| / sigma (None and 0 when skipped)."""
    if args.no_auto:
        print(
            "\nStep 8 (autoboresight on the rendered images, no picked point) skipped "
            "(--no-auto)"
        )
        return None, 0.0
    per_line = None if args.auto else args.auto_images_per_line
    auto = auto_step(OUT, mount, per_line=per_line)
    print(
        f"\nautoboresight on the {len(auto['images'])} rendered images: {auto['seconds']:.0f} s "
        f"({auto['cpu_seconds']:.0f} s of CPU); "
        f"{auto['rounds']} rounds; {auto['line_points']} line points on {auto['lines_seen']} "
        f"LiDAR lines, {auto['ties_associated']} of {auto['tie_tracks']} tie tracks on roof "
        f"planes (refused: {auto['ties_refused'] or 'none'})"
        + "".join(f"\n  WARNING: {w}" for w in auto["warnings"])
    )
    return auto, print_comparison(boresight_against_truth(cal / "boresight.csv"), auto["groups"])


def main(argv: list[str] | None = None) -> int:
    import argparse

    parser = argparse.ArgumentParser(description="The main job end to end (make demo).")
    parser.add_argument(
        "--auto", action="store_true",
        help="run step 8 on all ten 24-Mpx rendered images (slow: about 7 min of CPU, "
        "issue 32)",
    )  # fmt: skip
    parser.add_argument(
        "--auto-images-per-line", type=int, default=2, metavar="N",
        help="run step 8 on the first N images of each flight line (default 2: 4 of the 10 "
        "images, about 1.5 min of CPU)",
    )  # fmt: skip
    parser.add_argument(
        "--no-auto", action="store_true", help="skip step 8 (the automatic calibration)"
    )  # fmt: skip
    args = parser.parse_args(argv)
    start = time.perf_counter()
    if OUT.exists():
        shutil.rmtree(OUT)
    OUT.mkdir()
    georeferencing_step()

    # ---- 2. the real tile: ground, roof planes, LiDAR control
    lidar = lidar_step(OUT / "lidar")
    planes, lines, lcps = lidar.planes, lidar.lines, lidar.lcps

    # ---- 3. images simulated over the real roofs, with a known boresight
    flight = OUT / "flight"
    sim, paths, eo_true = flight_step(lidar, flight)
    config = sim.config
    obs = sim.observations
    kinds, counts = np.unique(np.array(obs.type), return_counts=True)
    cam = sim.camera
    print(
        f"\nsimulated flight ({flight.relative_to(ROOT)}): {len(sim.trajectory)} images "
        f"({', '.join(sorted(set(sim.trajectory.group)))}), {cam.name}, "
        f"{config.flying_height_m:g} m above the lowest point (GSD "
        f"{config.flying_height_m * cam.pixel_size_mm / cam.focal_mm * 100:.1f} cm); "
        f"{len(planes)} planes, {len(lines)} lines, {len(lcps)} LCPs from the tile; image "
        f"observations: {', '.join(f'{k} {c}' for k, c in zip(kinds, counts))}"
    )

    # ---- 4. calibration
    cal = OUT / "calibration"
    cal.mkdir()
    lever = ",".join(repr(v) for v in LEVER_ARM)
    lidarphoto(
        "boresightcalibration", "--camera", str(paths["camera"]),
        "--trajectory", str(paths["trajectory"]), "--crs", CRS, "--lever-arm", lever,
        "--mount", config.mount, "--boresight", "0,0,0",
        "--observations", str(paths["observations"]),
        "--planes", str(lidar.folder / "planes.csv"), "--lines", str(lidar.folder / "lines.csv"),
        "--lcps", str(lidar.folder / "lcps.csv"),
        "--grouping", "group", "--control-types", "tie,line,lcp",
        "--output-table", str(cal / "boresight.csv"), "--output-eo", str(cal / "eo.csv"),
        "--residuals-csv", str(cal / "residuals.csv"), "--output-html", str(cal / "summary.html"),
    )  # fmt: skip

    # ---- 5. check points: initial vs calibrated orientations
    lidarphoto(
        "trajectorytoeo", "--input", str(paths["trajectory"]), "--crs", CRS,
        "--lever-arm", lever, "--mount", config.mount, "--boresight", "0,0,0",
        "--output-csv", str(cal / "eo_initial.csv"),
    )  # fmt: skip
    frame = MappingFrame.from_user_input(CRS)
    local = local_frame_for(sim.trajectory, frame)
    observations = read_observations_csv(paths["observations"])
    rmse = {}
    for name in ("initial", "calibrated"):
        eo = read_eo_csv(cal / ("eo_initial.csv" if name == "initial" else "eo.csv"))
        ids, pts, _ = forward_intersection(observations, eo, cam, local)
        write_points(cal / f"check_{name}.csv", ids, pts)
        lidarphoto(
            "accuracyreport", "--measured", str(cal / f"check_{name}.csv"),
            "--reference", str(paths["check_points"]), "--crs", CRS,
            "--standards", "asprs,nssda", "--output-html", str(cal / f"accuracy_{name}.html"),
            "--output-json", str(cal / f"accuracy_{name}.json"),
        )  # fmt: skip
        truth = np.array([sim.check_points[i] for i in ids])
        d = pts - truth
        rmse[name] = (len(ids), *np.sqrt(np.mean(d**2, axis=0)))

    # ---- 6. recovered boresight against the truth
    rows, true, worst = boresight_table(cal, rmse)

    # ---- 7. the images, rendered with the true orientation, and the check of their geometry
    t0 = time.perf_counter()
    figures = render_step(lidar, sim, eo_true, flight / "images")
    per = figures["render_s_per_image"]
    print(
        f"\nRendered {figures['images']} images of {cam.width_px} x {cam.height_px} px "
        f"({flight.relative_to(ROOT)}/images/, 8-bit RGB TIFF): {np.mean(per):.2f} s per image "
        f"(max {np.max(per):.2f} s) + {np.mean(figures['write_s_per_image']):.2f} s writing; "
        f"{time.perf_counter() - t0:.0f} s in all"
    )
    print(
        f"LiDAR lines projected with the true orientation vs the rendered roof edges: "
        f"{figures['edge_profiles']} profiles, median {figures['edge_offset_median_px']} px, "
        f"95 % {figures['edge_offset_p95_px']} px, {100 * figures['edge_within_1px']:.1f} % "
        "within 1 px"
    )

    # ---- 8. the boresight calibrated automatically from the rendered images
    auto, worst_auto = auto_report(args, cal, config.mount)

    # ---- 9. true orthophotos and their mosaic, with the calibrated orientation
    ortho = ortho_step(OUT, cal / "eo.csv")
    print(
        f"\nTrue orthophotos of the {len(eo_true)} images on the LiDAR DSM ({ORTHO_GSD:g} m, "
        f"calibrated orientation): {ortho['orthorectify_s']:.1f} s; orthomosaic "
        f"(ortho/orthomosaic.tif, seamlines in ortho/seamlines.csv): {ortho['orthomosaic_s']:.1f} s"
    )

    # ---- 10. the QGIS project
    project = project_step()
    summary = {
        "truth_arcsec": true.tolist(),
        "groups": rows,
        "check_rmse_m": {k: list(v[1:]) for k, v in rmse.items()},
        "rendering": figures,
        "auto_calibration": auto,
        "ortho": ortho,
        "project": str(project) if project else None,
    }
    (OUT / "demo_summary.json").write_text(json.dumps(summary, indent=2), encoding="utf-8")
    print(
        f"\nOutputs in {OUT}/: lidar/ (ground, planes, LCPs, lines, DSM), flight/ (simulated "
        "inputs, truth, images/), calibration/ (boresight.csv, eo.csv, residuals.csv, "
        "summary.html, accuracy_initial.html, accuracy_calibrated.html), "
        + ("auto_calibration/ (boresight.csv, eo.csv, observations.csv, rounds.csv, "
           "summary.html), " if auto else "")
        + "ortho/ (true orthophotos, orthomosaic.tif, seamlines.csv)"
        + (f", {project.name} (open it in QGIS: docs/demo_project.md)" if project else "")
        + f"; {time.perf_counter() - start:.0f} s"
    )
    return 0 if worst < 4.0 and worst_auto < 4.0 else 1


if __name__ == "__main__":
    raise SystemExit(main())
