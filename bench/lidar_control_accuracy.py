"""Synthetic accuracy of LiDAR control points and lines (issue 4): towns of hip, pyramid and
gable roofs sampled with LiDAR noise of known sigma, planes fitted to the true faces, corners
and ridges compared with the exact geometry over repeated noise draws.

Run: .venv/bin/python bench/lidar_control_accuracy.py  (about a minute); prints a Markdown table.
"""

from __future__ import annotations

import numpy as np
from lidarphoto.core.geometry.planes import fit_plane
from lidarphoto.core.lidar.control import ControlOptions, lidar_control
from lidarphoto.core.simulation.town import make_town, sample_town

DRAWS = 60


def true_corners(town) -> np.ndarray:
    out = []
    for b in town.buildings:
        verts = np.vstack([town.faces[f].polygon for f in b.face_ids])
        keys, counts = np.unique(np.round(verts, 6), axis=0, return_counts=True)
        out.extend(keys[counts >= 3])
    return np.array(out)


def run(sigma: float, density: float) -> dict:
    town = make_town(n_buildings=9, roof_types=("hip", "pyramid", "gable"), n_trees=0, seed=7)
    truth = true_corners(town)
    options = ControlOptions(delta=max(0.6, 2.0 / np.sqrt(density)), max_support_distance=1.5)
    err, sig, maha, found = [], [], [], []
    d2, pred2, kinds_ok, n_lines = [], [], 0, 0
    for seed in range(1000, 1000 + DRAWS):
        pts = sample_town(town, density=density, noise_sigma=sigma, seed=seed)
        roof = (pts.face_id >= 0) & ~pts.is_wall
        xyz, face = pts.xyz[roof], pts.face_id[roof]
        planes = [fit_plane(xyz[face == f], plane_id=int(f)) for f in np.unique(face)]
        result = lidar_control(planes, xyz, face, options)
        found.append(len(result.points))
        for p in result.points:
            e = p.xyz - truth[np.argmin(np.linalg.norm(truth - p.xyz, axis=1))]
            err.append(e)
            sig.append(p.sigma)
            maha.append(e @ np.linalg.solve(p.covariance, e))
        for b in town.buildings:
            for seg in b.ridges:
                for ln in result.lines:
                    dist = [np.linalg.norm(np.cross(x - ln.point, ln.direction)) for x in seg]
                    if max(dist) < 0.5:
                        n_lines += 1
                        expected = "ridge" if abs(seg[1, 2] - seg[0, 2]) < 1e-6 else "hip"
                        kinds_ok += ln.kind == expected
                        for x, dd in zip(seg, dist):
                            d2.append(dd**2)
                            t = float((x - ln.point) @ ln.direction)
                            pred2.append(2 * ln.sigma_across(t) ** 2)
    err, sig = np.array(err), np.array(sig)
    return {
        "sigma": sigma,
        "density": density,
        "corners_true": len(truth),
        "corners_found": float(np.mean(found)),
        "rmse": np.sqrt((err**2).mean(axis=0)),
        "mean_sigma": sig.mean(axis=0),
        "maha": float(np.mean(maha)),
        "line_rms_across": float(np.sqrt(np.mean(d2) / 2)),
        "line_pred_across": float(np.sqrt(np.mean(pred2) / 2)),
        "lines_per_draw": n_lines / DRAWS,
        "lines_true": sum(len(b.ridges) for b in town.buildings),
        "kinds_ok": kinds_ok / max(n_lines, 1),
    }


def main() -> None:
    print(
        "| LiDAR sigma (m) | density (pts/m^2) | corners found / true | RMSE X Y Z (m) "
        "| mean reported sigma X Y Z (m) | mean Mahalanobis^2 (expect 3) "
        "| lines found / true | line RMS across at the ends (m) | predicted (m) | kind correct |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    for sigma, density in ((0.03, 8.0), (0.05, 8.0), (0.10, 4.0), (0.15, 2.0)):
        r = run(sigma, density)
        print(
            f"| {r['sigma']:.2f} | {r['density']:.0f} | {r['corners_found']:.1f} / "
            f"{r['corners_true']} | {' '.join(f'{v:.3f}' for v in r['rmse'])} | "
            f"{' '.join(f'{v:.3f}' for v in r['mean_sigma'])} | {r['maha']:.2f} | "
            f"{r['lines_per_draw']:.1f} / {r['lines_true']} | {r['line_rms_across']:.3f} | "
            f"{r['line_pred_across']:.3f} | {100 * r['kinds_ok']:.0f} % |",
            flush=True,
        )


if __name__ == "__main__":
    main()
