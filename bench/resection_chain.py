"""The chain of dos Santos, Dal Poz & Dalmolin (2010) on the demo (bench/resection.md): image A
resected from the LiDAR control, its line end points monoplotted on the LiDAR DSM, those 3D
lines used as the only control to resect image B, compared with B's point-based resection (the
source's Table 2) and with the truth. Also every demo image resected from its LiDAR control
points, its LiDAR lines and both, against the true orientation.

    PYTHONPATH=<parent of the plugin folder> python bench/resection_chain.py [work folder]

The demo's steps (scripts/demo.py): the real AHN3 tile -> ground filter, roof planes,
createlcps; a simulated flight over its roofs with image points on the LCPs and on the LiDAR
ridge/hip lines (0.5 px).
"""

from __future__ import annotations

import csv
import importlib.util
import sys
import time
from pathlib import Path

import numpy as np
from lidarphoto.core.io.observations import read_observations_csv, write_observations_csv
from lidarphoto.core.jobs import monoplot, resection
from lidarphoto.core.jobs.runner import run_job

ROOT = Path(__file__).resolve().parents[1]


def _demo():
    spec = importlib.util.spec_from_file_location("lidarphoto_demo", ROOT / "scripts" / "demo.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["lidarphoto_demo"] = module
    spec.loader.exec_module(module)
    return module


def _rows(path):
    with open(path, newline="", encoding="utf-8") as f:
        return {r["image_id"]: r for r in csv.DictReader(f)}


def _diff(row, truth, k):
    """Differences (m, mdeg) of one EO row from the truth, and in units of its sigmas."""
    xyz = np.array([float(row[c]) for c in ("X", "Y", "Z")]) - truth.xyz[k]
    ang = np.array([float(row[c]) for c in ("omega_deg", "phi_deg", "kappa_deg")])
    dang = (ang - np.degrees(truth.opk[k]) + 180) % 360 - 180
    sig = np.array([float(row[c]) for c in ("sigma_X", "sigma_Y", "sigma_Z", "sigma_omega_deg",
                                            "sigma_phi_deg", "sigma_kappa_deg")])  # fmt: skip
    d = np.r_[xyz, dang]
    return d, d / sig, sig


def main(work: Path) -> int:
    demo = _demo()
    t0 = time.perf_counter()
    lidar_dir, flight = work / "lidar", work / "flight"
    lidar = demo.lidar_step(lidar_dir)
    _sim, paths, truth = demo.flight_step(lidar, flight)
    obs = read_observations_csv(paths["observations"])
    # the simulation sees some lines with a single point in an image: not a line there,
    pairs = [(i, t) if k == "line" else None for i, t, k in zip(obs.image_id, obs.target_id,
                                                                 obs.type)]  # fmt: skip
    # ... or with its points less than 20 px apart (partly hidden): not measured there either
    span = {}
    for p, px in zip(pairs, obs.pixels):
        if p is not None:
            span.setdefault(p, []).append(px)
    long = {p: np.ptp(np.array(v), axis=0).max() >= 20.0 for p, v in span.items()}
    two = np.array([p is None or long[p] for p in pairs])
    obs = obs.subset(~obs.mask("line") | two)
    keep = obs.mask("lcp") | obs.mask("line")
    ctrl_obs = work / "observations_control.csv"
    write_observations_csv(ctrl_obs, obs.subset(keep))
    base = {"CAMERA": str(paths["camera"]), "CRS": demo.CRS}
    lcps, lines = str(lidar_dir / "lcps.csv"), str(lidar_dir / "lines.csv")
    # The tile has only 3 LCPs: the point-based solution (the source's aerotriangulation) uses
    # the demo's ground check points (true coordinates, given 1 cm) as control points.
    gcp_obs, gcps = work / "observations_gcp.csv", work / "gcps.csv"
    chk = obs.subset(obs.mask("check"))
    write_observations_csv(gcp_obs, type(chk)(chk.image_id, chk.point_id, chk.pixels,
                                               chk.sigma_px, ("lcp",) * len(chk),
                                               chk.target_id))  # fmt: skip
    with open(paths["check_points"], newline="", encoding="utf-8") as f, \
            open(gcps, "w", newline="", encoding="utf-8") as g:  # fmt: skip
        w = csv.writer(g)
        w.writerow(("point_id", "X", "Y", "Z", "sx", "sy", "sz"))
        for r in csv.DictReader(f):
            w.writerow((r["id"], r["e"], r["n"], r["h"], 0.01, 0.01, 0.01))
    print(f"demo: {len(truth.image_id)} images, {len(lidar.lcps)} LCPs, {len(lidar.lines)} "
          f"lines ({time.perf_counter() - t0:.0f} s)")  # fmt: skip

    # every image from points, lines, both
    runs = {}
    for name, extra in (
        ("points", {"OBSERVATIONS": str(gcp_obs), "CONTROL_POINTS": str(gcps)}),
        ("lines", {"LINE_OBSERVATIONS": str(ctrl_obs), "CONTROL_LINES": lines}),
        ("LCPs and lines", {"OBSERVATIONS": str(ctrl_obs), "CONTROL_POINTS": lcps,
                   "CONTROL_LINES": lines}),
    ):  # fmt: skip
        t = time.perf_counter()
        out = work / f"eo_{name}.csv"
        run_job(resection, {**base, **extra, "OUTPUT_EO": str(out)})
        runs[name] = (_rows(out), time.perf_counter() - t)
    print("\n| control | images | RMS error X, Y, Z (m) | RMS error omega, phi, kappa (mdeg) | "
          "RMS error / sigma (6 parameters) | median points / lines per image | "
          "time per image (ms, read + compute + write) |")
    print("|---|---|---|---|---|---|---|")
    for name, (rows, secs) in runs.items():
        ds, zs = [], []
        for k, i in enumerate(truth.image_id):
            d, z, _ = _diff(rows[i], truth, k)
            ds.append(d)
            zs.append(z)
        ds, zs = np.array(ds), np.array(zs)
        rms = np.sqrt(np.mean(ds**2, axis=0))
        zr = np.sqrt(np.mean(zs**2, axis=0))
        npts = np.median([int(r["points"]) for r in rows.values()])
        nln = np.median([int(r["lines"]) for r in rows.values()])
        print(f"| {name} | {len(rows)} | {rms[0]:.3f}, {rms[1]:.3f}, {rms[2]:.3f} | "
              f"{rms[3] * 1e3:.2f}, {rms[4] * 1e3:.2f}, {rms[5] * 1e3:.2f} | "
              f"{', '.join(f'{v:.2f}' for v in zr)} | {npts:g} / {nln:g} | "
              f"{secs / len(rows) * 1e3:.0f} |")  # fmt: skip

    # the chain: A from its LiDAR control, its lines monoplotted, B from those lines only
    ids = list(truth.image_id)
    line_rows = obs.subset(obs.mask("line"))
    targets = {i: {t for j, t in zip(line_rows.image_id, line_rows.target_id) if j == i}
               for i in ids}  # fmt: skip
    a, b = max(((x, y) for x, y in zip(ids, ids[1:])),
               key=lambda p: len(targets[p[0]] & targets[p[1]]))  # fmt: skip
    common = targets[a] & targets[b]
    eo_a = work / "eo_A.csv"
    run_job(resection, {**base, "OBSERVATIONS": str(ctrl_obs), "CONTROL_POINTS": lcps,
                        "CONTROL_LINES": lines, "IMAGES": a, "OUTPUT_EO": str(eo_a)})
    a_lines = work / "lines_A.csv"
    write_observations_csv(a_lines, line_rows.subset(
        [j == a and t in common for j, t in zip(line_rows.image_id, line_rows.target_id)]))
    mono = work / "monoplot_A.csv"
    row_a = _rows(eo_a)[a]
    sig_a = [float(row_a[c]) for c in ("sigma_X", "sigma_Y", "sigma_Z", "sigma_omega_deg",
                                       "sigma_phi_deg", "sigma_kappa_deg")]  # fmt: skip
    run_job(monoplot, {"OBSERVATIONS": str(a_lines), "CAMERA": str(paths["camera"]),
                       "EO": str(eo_a), "DSM": str(lidar_dir / "planes.laz"), "CRS": demo.CRS,
                       "DSM_CRS": demo.CRS,  # NAP heights taken as ellipsoidal, as the demo
                       "CELL_SIZE": demo.DSM_CELL, "EO_SIGMAS": sig_a,
                       "OUTPUT_POINTS": str(work / "mono_points.gpkg"),
                       "OUTPUT_LINES": str(work / "mono_lines.gpkg"),
                       "LINES_CSV": str(mono)})  # fmt: skip
    b_lines = work / "lines_B.csv"
    write_observations_csv(b_lines, line_rows.subset(
        [j == b and t in common for j, t in zip(line_rows.image_id, line_rows.target_id)]))
    eo_bl, eo_bp = work / "eo_B_lines.csv", work / "eo_B_points.csv"
    run_job(resection, {**base, "LINE_OBSERVATIONS": str(b_lines), "CONTROL_LINES": str(mono),
                        "OUTPUT_EO": str(eo_bl), "OUTPUT_HTML": str(work / "B_lines.html")})
    run_job(resection, {**base, "OBSERVATIONS": str(gcp_obs), "CONTROL_POINTS": str(gcps),
                        "IMAGES": b, "OUTPUT_EO": str(eo_bp)})  # fmt: skip
    kb = ids.index(b)
    rl, rp = _rows(eo_bl)[b], _rows(eo_bp)[b]
    dl, zl, sl = _diff(rl, truth, kb)
    dp, zp, sp = _diff(rp, truth, kb)
    print(f"\nChain: image {a} resected from {row_a['points']} LCPs and {row_a['lines']} lines, "
          f"{len(common)} of its lines monoplotted on the DSM, image {b} resected from those "
          f"lines only, and from its {rp['points']} ground points (the point-based solution).\n")
    print("| parameter | B from monoplotted lines | sigma | B from ground points | sigma | "
          "lines - points | truth - lines (in sigma) |")
    print("|---|---|---|---|---|---|---|")
    names = ("X (m)", "Y (m)", "Z (m)", "omega (deg)", "phi (deg)", "kappa (deg)")
    cols = ("X", "Y", "Z", "omega_deg", "phi_deg", "kappa_deg")
    for j in range(6):
        vl, vp = float(rl[cols[j]]), float(rp[cols[j]])
        fmt = ".3f" if j < 3 else ".5f"
        print(f"| {names[j]} | {vl:{fmt}} | {sl[j]:{fmt}} | {vp:{fmt}} | {sp[j]:{fmt}} | "
              f"{vl - vp:+{fmt}} | {-zl[j]:+.2f} |")
    print(f"\nsigma0: lines {float(rl['sigma0']):.3f}, points {float(rp['sigma0']):.3f}; "
          f"chi-square (lines) {float(rl['chi2']):.2f} against {float(rl['chi2_critical']):.2f} "
          f"(redundancy {rl['redundancy']}; passed {rl['chi2_passed']}); "
          f"chi-square (points) {float(rp['chi2']):.2f} against {float(rp['chi2_critical']):.2f}")
    # the source's test: are the two solutions the same? (difference / combined sigma)
    comb = np.sqrt(sl**2 + sp**2)
    dd = np.array([float(rl[c]) - float(rp[c]) for c in cols])
    t = float(np.sum((dd / comb) ** 2))
    print(f"lines - points: sum of squared differences / combined sigmas = {t:.2f} for 6 "
          f"degrees of freedom (5 % critical value 12.59); largest {np.max(np.abs(dd / comb)):.2f}"
          f" sigma; truth within {np.max(np.abs(zl)):.2f} sigma (lines), "
          f"{np.max(np.abs(zp)):.2f} sigma (points)")
    da, za, _ = _diff(row_a, truth, ids.index(a))
    print(f"image A's own error (its orientation, which every monoplotted line carries): "
          f"X, Y, Z {', '.join(f'{v:+.3f}' for v in da[:3])} m, omega, phi, kappa "
          f"{', '.join(f'{v * 1e3:+.1f}' for v in da[3:])} mdeg ("
          f"{', '.join(f'{v:+.2f}' for v in za)} sigma); B from lines - truth: "
          f"{', '.join(f'{v:+.3f}' for v in dl[:3])} m, "
          f"{', '.join(f'{v * 1e3:+.1f}' for v in dl[3:])} mdeg; from points - truth "
          f"{', '.join(f'{v:+.3f}' for v in dp[:3])} m, "
          f"{', '.join(f'{v * 1e3:+.1f}' for v in dp[3:])} mdeg")
    print(f"\ntotal {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("resection_chain")))
