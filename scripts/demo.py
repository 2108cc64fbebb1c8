"""The main job on bundled sample data (``make demo``).

For now: direct georeferencing of the sample trajectory (two opposite strips over Pouso
Alegre, Brazil, SIRGAS 2000 / UTM 23S) through the ``lidarphoto`` command, then a check of
the result against a closed-form expectation. Later capabilities extend this pipeline.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
from lidarphoto.core.frames import MappingFrame
from lidarphoto.core.orientation import read_eo_csv
from lidarphoto.core.trajectory_to_eo import read_trajectory_csv

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "sample_data" / "trajectory_demo.csv"
OUT = ROOT / "demo_output"
CRS = "EPSG:31983"


def main() -> int:
    OUT.mkdir(exist_ok=True)
    eo_csv = OUT / "exterior_orientation.csv"
    cmd = [
        sys.executable, "-m", "lidarphoto", "trajectorytoeo",
        "--input", str(SAMPLE), "--crs", CRS,
        "--lever-arm", "0.12,-0.05,-1.35", "--mount", "image_top_forward",
        "--boresight", "0.012,-0.008,0.035", "--output-csv", str(eo_csv),
    ]  # fmt: skip
    print("$ lidarphoto " + " ".join(cmd[3:]), flush=True)
    subprocess.run(cmd, check=True)
    eo = read_eo_csv(eo_csv)
    traj = read_trajectory_csv(SAMPLE)
    frame = MappingFrame.from_user_input(CRS)
    theta = np.degrees(frame.grid_north_azimuth(frame.map_to_geodetic(traj.position)))
    print(f"\n{'image':8} {'X':>12} {'Y':>13} {'Z':>9} {'omega':>9} {'phi':>9} {'kappa':>10}")
    for i, image in enumerate(eo.image_id):
        x, y, z = eo.xyz[i]
        w, p, k = np.degrees(eo.opk[i])
        print(f"{image:8} {x:12.3f} {y:13.3f} {z:9.3f} {w:9.4f} {p:9.4f} {k:10.4f}")
    # For a near-level image flown with image top forward, kappa ~ -(heading + convergence).
    heading = np.degrees(traj.rph[:, 2])
    kappa = np.degrees(eo.opk[:, 2])
    gap = (kappa + heading + theta + 180.0) % 360.0 - 180.0
    print(f"\ngrid convergence here: {theta.mean():+.4f} deg (true north seen from grid north)")
    print(
        f"kappa + heading + convergence: max |{np.abs(gap).max():.3f}| deg (roll/pitch/boresight)"
    )
    print(
        f"lever arm 1.35 m up: Z - INS height = {np.mean(eo.xyz[:, 2] - traj.position[:, 2]):.3f} m"
    )
    print(f"\nwrote {eo_csv}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
