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

Heights: the tile is in RD New + NAP; without the NAP geoid grid installed (PROJ), the
calibration treats the heights as ellipsoidal (EPSG:28992). The simulation is made in that
same frame, so this changes nothing in the comparison with the truth.
"""

from __future__ import annotations

import csv
import json
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from lidarphoto.core.boresight import local_frame_for
from lidarphoto.core.boresight_run import forward_intersection
from lidarphoto.core.frames import MappingFrame
from lidarphoto.core.io.control import read_lcps_csv, read_lines_csv
from lidarphoto.core.io.observations import read_observations_csv
from lidarphoto.core.io.tables import write_csv_atomic
from lidarphoto.core.orientation import read_eo_csv
from lidarphoto.core.planes import read_planes_csv
from lidarphoto.core.pointcloud import read_points
from lidarphoto.core.simulate_flight import ControlFlightConfig, simulate_flight_over
from lidarphoto.core.trajectory_to_eo import read_trajectory_csv

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "sample_data" / "trajectory_demo.csv"
TILE = ROOT / "tests" / "data" / "ahn3" / "ahn3_delft_crop60.laz"
OUT = ROOT / "demo_output"
CRS = "EPSG:28992"  # the tile's RD New, heights taken as ellipsoidal (module docstring)
ARCSEC = np.pi / (180.0 * 3600.0)
TRUE_BORESIGHT_DEG = (0.12, -0.25, 0.40)
LEVER_ARM = (0.10, -0.05, -0.20)


def lidarphoto(*args: str) -> None:
    """Run one ``lidarphoto`` subcommand, echoing it (paths relative to the repository)."""
    shown = [str(Path(a).relative_to(ROOT)) if a.startswith(str(ROOT)) else a for a in args]
    print("\n$ lidarphoto " + " ".join(shown), flush=True)
    subprocess.run([sys.executable, "-m", "lidarphoto", *args], check=True)


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


def main() -> int:
    start = time.perf_counter()
    if OUT.exists():
        shutil.rmtree(OUT)
    OUT.mkdir()
    georeferencing_step()

    # ---- 2. the real tile: ground, roof planes, LiDAR control
    lidar = OUT / "lidar"
    lidar.mkdir()
    lidarphoto("groundfilter", "--input", str(TILE), "--output-cloud", str(lidar / "ground.laz"))
    lidarphoto(
        "extractroofplanes", "--input", str(lidar / "ground.laz"),
        "--output-csv", str(lidar / "planes.csv"), "--output-cloud", str(lidar / "planes.laz"),
    )  # fmt: skip
    lidarphoto(
        "createlcps", "--planes", str(lidar / "planes.csv"), "--cloud", str(lidar / "planes.laz"),
        "--points-csv", str(lidar / "lcps.csv"), "--lines-csv", str(lidar / "lines.csv"),
    )  # fmt: skip
    planes = read_planes_csv(lidar / "planes.csv")
    lines = read_lines_csv(lidar / "lines.csv")
    lcps = read_lcps_csv(lidar / "lcps.csv")
    arrays, _ = read_points(lidar / "planes.laz", ("x", "y", "z", "plane_id"))
    xyz = np.column_stack([arrays["x"], arrays["y"], arrays["z"]])

    # ---- 3. images simulated over the real roofs, with a known boresight
    config = ControlFlightConfig(
        crs=CRS,
        centre=tuple(float(v) for v in (xyz[:, :2].min(axis=0) + xyz[:, :2].max(axis=0)) / 2),
        true_boresight_deg=(TRUE_BORESIGHT_DEG,),
        lever_arm_m=LEVER_ARM,
    )
    sim = simulate_flight_over(planes, lines, lcps, xyz, arrays["plane_id"], config, seed=5)
    flight = OUT / "flight"
    paths = sim.write(flight)
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
        "--observations", str(paths["observations"]), "--planes", str(lidar / "planes.csv"),
        "--lines", str(lidar / "lines.csv"), "--lcps", str(lidar / "lcps.csv"),
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
    summary = {
        "truth_arcsec": true.tolist(),
        "groups": rows,
        "check_rmse_m": {k: list(v[1:]) for k, v in rmse.items()},
    }
    (OUT / "demo_summary.json").write_text(json.dumps(summary, indent=2), encoding="utf-8")
    print(
        f"\nOutputs in {OUT}/: lidar/ (ground, planes, LCPs, lines), flight/ (simulated inputs "
        "and truth), calibration/ (boresight.csv, eo.csv, residuals.csv, summary.html, "
        f"accuracy_initial.html, accuracy_calibrated.html); {time.perf_counter() - start:.0f} s"
    )
    return 0 if worst < 4.0 else 1


if __name__ == "__main__":
    raise SystemExit(main())
