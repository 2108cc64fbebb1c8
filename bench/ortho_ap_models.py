"""The comparison of Lima, Debiasi & Menezes (their Table 1) made as they made it: one
orthomosaic per additional-parameter family, the check points measured on each mosaic.

The simulated UAV block of the bundle-adjustment benchmark (`simulate_uav_block("real")`: a
compact camera's Brown-Conrady lens, 15 images at 188 m, 16 control and 5 check points) is
rendered over a textured terrain (the block's terrain as a 0.25 m DSM whose cells carry random
LAS classes: an aperiodic texture, so that a shift is measured without ambiguity). For each AP
family the bundle is adjusted from the direct-georeferencing start (the full pipeline of
`bench/bundle_ap_models.py`), its camera and orientations are written as files, and the
command-line jobs `orthorectify` and `orthomosaic` make the mosaic on the DSM, as a user
would. A reference mosaic is made the same way with the true camera and orientations.

Measuring a check point on a mosaic: the shift between a chip of the family's mosaic and the
same chip of the reference mosaic (phase correlation to 1/100 cell, whitened) around the
point's true position; the shift is where the mosaic shows that ground, i.e. the planimetric
discrepancy a user would measure on it. The same measurement with a shift planted in the
reference gives the planted shift back (checked at the start of the run).

Run: ``.venv/bin/python bench/ortho_ap_models.py [workdir]`` (about 10 minutes on one core);
writes bench/ortho_ap_models.md. A ``workdir`` that holds an earlier run's images and reference
mosaic reuses them (the simulation is deterministic).
"""

from __future__ import annotations

import json
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
from lidarphoto.core.cli import main as cli
from lidarphoto.core.geometry.grid import Grid
from lidarphoto.core.geometry.surface import Dsm
from lidarphoto.core.io.camera import write_camera_json
from lidarphoto.core.io.dsm import write_dsm
from lidarphoto.core.io.orientation import write_eo_csv
from lidarphoto.core.io.raster import RasterReader
from lidarphoto.core.io.raster_write import write_rgb_tiff
from lidarphoto.core.photo.bundle import bundle_adjust
from lidarphoto.core.photo.bundle_setup import BundleOptions
from lidarphoto.core.quality.registration import phase_correlation
from lidarphoto.core.simulation.render import render_image
from lidarphoto.core.simulation.render_scene import RenderOptions, RenderScene
from lidarphoto.core.simulation.uav_block import simulate_uav_block

HERE = Path(__file__).resolve().parent
FAMILIES = ("none", "lens_k1k2", "bauer", "jacobsen", "ebner", "brown", "conrady_brown")
TABLE1 = {  # Lima, Debiasi & Menezes, Table 1: planimetric discrepancies (m), mean / std / RMS
    "bauer": (0.452, 0.216, 0.417),
    "ebner": (0.471, 0.127, 0.442),
    "brown": (0.935, 1.406, 1.325),
    "jacobsen": (0.705, 0.696, 0.795),
    "lens_k1k2": (0.308, 0.051, 0.312),
}
DSM_CELL = 0.25  # m
GSD = 0.10  # m, the mosaics' cell
CHIP = 96  # cells (9.6 m) around each check point


def _dsm_and_scene(blk, margin: float = 160.0):
    """The block's terrain as a DSM over the images' footprints, with random classes."""
    xyz = blk.eo_true.xyz
    x0, x1 = xyz[:, 0].min() - margin, xyz[:, 0].max() + margin
    y0, y1 = xyz[:, 1].min() - margin, xyz[:, 1].max() + margin
    cols, rows = int((x1 - x0) / DSM_CELL), int((y1 - y0) / DSM_CELL)
    grid = Grid(x0, y0 + rows * DSM_CELL, DSM_CELL, cols, rows)
    xc = grid.x0 + (np.arange(cols) + 0.5) * DSM_CELL
    yc = grid.y_top - (np.arange(rows) + 0.5) * DSM_CELL
    xx, yy = np.meshgrid(xc, yc)
    z = blk.terrain(xx, yy).astype(np.float32)
    dsm = Dsm(z, grid, blk.mapping.crs)
    rng = np.random.default_rng(2)
    cls = rng.choice(np.array([2, 3, 6, 9]), size=z.shape)
    pts = np.column_stack([xx.ravel(), yy.ravel(), z.ravel()])
    return dsm, RenderScene.build(dsm, pts, cls.ravel(), crs=blk.mapping.crs)


def _mosaic(work: Path, name: str, camera, eo, images: Path, dsm_path: Path, crs: str) -> Path:
    """camera + EO files, then orthorectify and orthomosaic through the command line."""
    folder = work / name
    folder.mkdir(parents=True, exist_ok=True)
    write_camera_json(folder / "camera.json", camera)
    write_eo_csv(folder / "eo.csv", eo)
    code = cli(["orthorectify", "--camera", str(folder / "camera.json"),
                "--eo", str(folder / "eo.csv"), "--images", str(images),
                "--dsm", str(dsm_path), "--crs", crs, "--gsd", str(GSD),
                "--output-folder", str(folder / "ortho")])  # fmt: skip
    if code:
        raise SystemExit(f"orthorectify failed for {name}")
    out = folder / "mosaic.tif"
    code = cli(["orthomosaic", "--orthophotos", str(folder / "ortho"), "--output", str(out)])
    if code:
        raise SystemExit(f"orthomosaic failed for {name}")
    return out


def _grey(path: Path) -> tuple[np.ndarray, np.ndarray, tuple]:
    r = RasterReader(path)
    data = r.read().astype(np.float64).mean(axis=0)
    return data, r.read_mask(), r.info.geotransform


def _chip(img: np.ndarray, gt: tuple, x: float, y: float) -> np.ndarray | None:
    c = round((x - gt[0]) / gt[1]) - CHIP // 2
    r = round((y - gt[3]) / gt[5]) - CHIP // 2
    if r < 0 or c < 0 or r + CHIP > img.shape[0] or c + CHIP > img.shape[1]:
        return None
    return img[r : r + CHIP, c : c + CHIP]


def measure(ref, mos, points) -> np.ndarray:
    """(n, 2) planimetric discrepancies (dE, dN), metres, of the points on the mosaic ``mos``
    against the reference mosaic (NaN where a chip is incomplete); each is (data, mask,
    geotransform)."""
    (a, am, agt), (b, bm, bgt) = ref, mos
    # the grids are aligned on multiples of the GSD (orthorectify): chips of the same cells
    assert agt[1] == bgt[1] and agt[5] == bgt[5], "the mosaics must share their cell size"
    assert abs((agt[0] - bgt[0]) / agt[1] - round((agt[0] - bgt[0]) / agt[1])) < 1e-6
    out = np.full((len(points), 2), np.nan)
    for k, (x, y) in enumerate(points[:, :2]):
        ca, cb = _chip(a, agt, x, y), _chip(b, bgt, x, y)
        ma, mb = _chip(am, agt, x, y), _chip(bm, bgt, x, y)
        if ca is None or cb is None or not (ma.all() and mb.all()):
            continue
        dx, dy, _ = phase_correlation(ca, cb, whiten=True)
        # the mosaic shows at cell (c + dx, r + dy) the ground the reference shows at (c, r):
        # the point a user clicks is dx cells east and dy rows south of its true place
        out[k] = dx * agt[1], dy * agt[5]
    return out


def _self_check(ref) -> float:
    """A shift planted in the reference (integer cells + sub-cell by Fourier shift) is
    measured back: the largest error, metres."""
    from scipy import ndimage

    data, mask, gt = ref
    shifted = np.real(np.fft.ifft2(ndimage.fourier_shift(np.fft.fft2(data), (-1.3, 2.45))))
    y, x = gt[3] + gt[5] * data.shape[0] / 2, gt[0] + gt[1] * data.shape[1] / 2
    d = measure(ref, (shifted, mask, gt), np.array([[x, y]]))[0]
    return float(np.hypot(d[0] - 2.45 * gt[1], d[1] - (-1.3) * gt[5]))


def main(work: Path) -> None:
    t0 = time.perf_counter()
    blk = simulate_uav_block("real", seed=1)
    crs = blk.config.crs
    dsm, scene = _dsm_and_scene(blk)
    dsm_path = work / "dsm.tif"
    write_dsm(dsm_path, dsm)
    images = work / "images"
    images.mkdir(parents=True, exist_ok=True)
    for k, name in enumerate(blk.eo_true.image_id):
        if (images / f"{name}.tif").exists():  # a workdir of an earlier run: reused
            continue
        img = render_image(scene, blk.true_camera, blk.eo_true.xyz[k], blk.eo_true.opk[k],
                           RenderOptions(step_px=2, noise_dn=1.0, seed=k))  # fmt: skip
        write_rgb_tiff(images / f"{name}.tif", img.rgb)
    t_render = time.perf_counter() - t0
    print(f"rendered {len(blk.eo_true.image_id)} images in {t_render:.0f} s", flush=True)

    truth = work / "truth" / "mosaic.tif"
    if not truth.exists():
        truth = _mosaic(work, "truth", blk.true_camera, blk.eo_true, images, dsm_path, crs)
    ref = _grey(truth)
    planted = _self_check(ref)
    print(f"planted shift measured back within {planted * 1000:.3f} mm", flush=True)
    check = np.array([r == "check" for r in blk.ground.role])
    check_xyz = blk.ground_true[check]
    check_id = [p for p, c in zip(blk.ground.point_id, check) if c]

    rows = []
    for fam in FAMILIES:
        t = time.perf_counter()
        res = bundle_adjust([blk.camera], blk.observations, blk.ground, blk.mapping, blk.eo_dg,
                            blk.eo_sigma, options=BundleOptions(ap_model=fam))  # fmt: skip
        cam = next(iter(res.cameras.values()))
        mos = _grey(_mosaic(work, fam, cam, res.eo, images, dsm_path, crs))
        d = measure(ref, mos, check_xyz)
        ok = np.isfinite(d[:, 0])
        planim = np.hypot(d[ok, 0], d[ok, 1])
        st = res.check.statistics()
        rows.append({
            "family": fam, "n": int(ok.sum()), "mean": planim.mean(), "std": planim.std(ddof=1),
            "rms": float(np.sqrt(np.mean(planim**2))), "max": planim.max(),
            "bundle_rms": st["rms_planimetric"], "sigma0": res.sigma0,
            "per_point": {p: (float(a), float(b)) for p, (a, b) in zip(check_id, d)},
            "s": time.perf_counter() - t,
        })  # fmt: skip
        print(fam, f"{rows[-1]['rms']:.3f} m (bundle {st['rms_planimetric']:.3f})", flush=True)
    rows.sort(key=lambda r: r["rms"])
    (work / "rows.json").write_text(json.dumps([rows, planted, t_render]), encoding="utf-8")
    _write(rows, planted, len(blk.eo_true.image_id), t_render, time.perf_counter() - t0)


def _write(rows, planted: float, n_images: int, t_render: float, total: float) -> None:
    import cv2
    import scipy

    lines = [
        "# Orthomosaics per AP family: the comparison of Lima, Debiasi & Menezes",
        "",
        f"`bench/ortho_ap_models.py`, {time.strftime('%Y-%m-%d')}, {platform.machine()} "
        f"(2 cores, shared), Python {platform.python_version()}, numpy {np.__version__}, "
        f"scipy {scipy.__version__}, OpenCV {cv2.__version__}; the whole run {total / 60:.1f} "
        f"min ({n_images} images rendered in {t_render:.0f} s). Method: the module docstring.",
        "",
        f"Block: `simulate_uav_block('real', seed=1)`; a compact camera's Brown-Conrady lens "
        f"(about 30 px barrel, 2 px decentring), the nominal camera as the start; DSM of the "
        f"true terrain at {DSM_CELL} m; mosaics at {GSD} m through `orthorectify` + "
        f"`orthomosaic` (bilinear, nadir-most image per cell). Check points measured on each "
        f"mosaic against the reference mosaic (true camera and orientations) by whitened phase "
        f"correlation of {CHIP} x {CHIP}-cell chips; a planted shift is measured back within "
        f"{planted * 1000:.3f} mm.",
        "",
        "Columns: planimetric discrepancies of the check points on the mosaic (metres); "
        "'bundle' is the planimetric RMS of the same check points intersected in the bundle "
        "(bench/bundle.md); Table 1 of the paper (real block, its own orthomosaics) for the "
        "families it has.",
        "",
        "| rank | family | check pts | mean | std | RMS | max | bundle RMS | sigma0 | s | "
        "paper mean / std / RMS |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for k, r in enumerate(rows, 1):
        paper = TABLE1.get(r["family"])
        ptxt = " / ".join(f"{v:.3f}" for v in paper) if paper else ""
        lines.append(
            f"| {k} | {r['family']} | {r['n']} | {r['mean']:.3f} | {r['std']:.3f} | "
            f"{r['rms']:.3f} | {r['max']:.3f} | {r['bundle_rms']:.3f} | {r['sigma0']:.3f} | "
            f"{r['s']:.0f} | {ptxt} |"
        )
    good = [r for r in rows if r["rms"] < 5 * GSD / 10]
    bad = [r for r in rows if r["rms"] >= 5 * GSD / 10]
    lines += [
        "",
        "Reading. A mosaic shows only the systematic error that the camera and orientations put "
        "on the ground (no pointing error of an operator, no survey error), and each point of "
        "it comes from one image. The families that represent the lens ("
        + ", ".join(r["family"] for r in good)
        + f") put the check points within {max(r['max'] for r in good) * 100:.1f} cm of their "
        f"place (RMS {min(r['rms'] for r in good) * 1000:.0f}-"
        f"{max(r['rms'] for r in good) * 1000:.0f} mm, a tenth of the {GSD} m cell at most); "
        "those that cannot ("
        + ", ".join(r["family"] for r in bad)
        + ") leave "
        + ", ".join(f"{r['rms']:.2f} m RMS ({r['max']:.2f} m at most)" for r in bad)
        + ": several times the planimetric RMS of the same check points intersected in the "
        "bundle ("
        + ", ".join(f"{r['bundle_rms']:.2f} m" for r in bad)
        + "), because an intersection averages the distortion of several rays where the "
        "mosaic shows one image's. The paper's figures on its real block (0.31-1.33 m RMS) "
        "have the magnitude of the families that cannot represent the lens here; its ranking "
        "(k1 k2 first, Brown last) is not reproduced: on a simulated block every family able "
        "to follow the lens reaches the same centimetre, so the paper's spread comes from what "
        "the simulation does not have (the real lens and its residual errors, the paper's own "
        "surface, manual measurement on the mosaic).",
    ]
    lines += ["", "Per check point (dE, dN in metres) on each family's mosaic:", ""]
    ids = list(rows[0]["per_point"])
    lines.append("| family | " + " | ".join(ids) + " |")
    lines.append("|---" * (len(ids) + 1) + "|")
    for r in rows:
        cells = [f"{a:+.3f}, {b:+.3f}" for a, b in r["per_point"].values()]
        lines.append(f"| {r['family']} | " + " | ".join(cells) + " |")
    (HERE / "ortho_ap_models.md").write_text("\n".join(lines) + "\n", encoding="utf-8")
    print("\n".join(lines))


if __name__ == "__main__":
    if len(sys.argv) > 1:
        main(Path(sys.argv[1]))
    else:
        with tempfile.TemporaryDirectory() as tmp:
            main(Path(tmp))
