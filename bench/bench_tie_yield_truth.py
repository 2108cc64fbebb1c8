"""Yield settings of the tie points against the simulated truth (bench/matching.md, "Tie
points: yield against COLMAP"): the test block of tests/core/test_tie_points.py (15 images of
1000 x 750 px rendered from the simulated UAV block, 2 grey levels of noise, footprint pairs
from the direct-georeferencing EO), matched with each variant of bench/bench_tie_yield.py.

Per variant: tracks, tracks seen in >= 3 images, measurements, CPU (user + sys of this
process), and every measurement against the projection of its track's true ground point
(median of the exact ground points of its measurements): median, 95th percentile, wrong
measurements (> 3 px) and wrong tracks. The keypoints (refinement off) and the refined
measurements (the default) are both reported, since the refinement hides part of what the
detector does.

Usage: OMP_NUM_THREADS=1 nice -n 10 python bench/bench_tie_yield_truth.py
[--variants default,...] [--features 1500]
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_tie_yield import VARIANTS, cpu


def render(folder: Path):
    """The 15 test images as PNG in ``folder``; (TexturedBlock, footprints)."""
    import cv2
    from lidarphoto.core.geometry.camera import Camera
    from lidarphoto.core.photo.tie_pairs import footprints
    from lidarphoto.core.simulation.textured_block import TexturedBlock, make_texture, render_view
    from lidarphoto.core.simulation.uav_block import simulate_uav_block

    cam = Camera("small", focal_mm=5.0, pixel_size_mm=0.00616, width_px=1000, height_px=750)
    blk = simulate_uav_block("none", seed=3, n_tie=50, camera=cam, true_focal_mm=5.03,
                             true_x0_mm=0.03, true_y0_mm=-0.02)  # fmt: skip
    tb = TexturedBlock.of(blk)
    tex = make_texture(tb.extent(), 0.2, seed=1)
    for k, name in enumerate(blk.eo_true.image_id):
        cv2.imwrite(str(folder / f"{name}.png"), render_view(tb, tex, k, noise_dn=2.0))
    fps = footprints(blk.camera, blk.eo_dg.xyz, blk.eo_dg.opk, blk.config.ground_height_m)
    # image k of the chain is image k of the block (the truth's poses): files in EO order
    files = [folder / f"{name}.png" for name in blk.eo_true.image_id]
    return tb, list(fps), files


def truth_errors(tb, tracks) -> np.ndarray:
    """|measurement - projection of the track's true ground point|, pixels."""
    from lidarphoto.core.geometry.collinearity import project_with_status
    from lidarphoto.core.simulation.textured_block import ground_of_pixels

    ground = np.zeros((tracks.track.size, 3))
    for k in np.unique(tracks.image):
        sel = tracks.image == k
        ground[sel] = ground_of_pixels(tb, tracks.pixels[sel], int(k))
    local = tb.local.map_to_enu(ground)
    med = np.array([np.median(local[tracks.track == t], axis=0)
                    for t in range(tracks.n_tracks)])  # fmt: skip
    err = np.zeros(tracks.track.size)
    for k in np.unique(tracks.image):
        sel = np.flatnonzero(tracks.image == k)
        px, _, _ = project_with_status(med[tracks.track[sel]], tb.eo_local[int(k)],
                                       tb.block.true_camera)  # fmt: skip
        err[sel] = np.hypot(*(px - tracks.pixels[sel]).T)
    return err


def run(tb, fps, files, options) -> dict:
    """One run of the chain with ``options``: the figures."""
    from lidarphoto.core.io.images import read_gray
    from lidarphoto.core.photo.tie_points import detect_features, tie_points

    ids = [f.stem for f in files]
    t0 = cpu()
    res = tie_points(ids, lambda k: detect_features(read_gray(files[k]), ids[k], options),
                     options, fps, load_image=lambda k: read_gray(files[k]))  # fmt: skip
    t = cpu() - t0
    err = truth_errors(tb, res.tracks)
    wrong = np.unique(res.tracks.track[err > 3.0]).size
    kept = [p for p in res.pairs if p.kept]
    return {"cpu_s": round(t, 1), "verified": int(sum(p.n_inliers for p in kept)),
            "tracks": res.tracks.n_tracks, "tracks3": int((res.tracks.lengths() >= 3).sum()),
            "measurements": int(res.tracks.track.size),
            "median_px": round(float(np.median(err)), 4),
            "p95_px": round(float(np.percentile(err, 95)), 3),
            "wrong_meas_pct": round(100 * float(np.mean(err > 3.0)), 3),
            "wrong_tracks": int(wrong)}  # fmt: skip


def main() -> None:
    from lidarphoto.core.photo.tie_options import TiePointOptions

    ap = argparse.ArgumentParser()
    ap.add_argument("--variants", default="default")
    ap.add_argument("--features", type=int, default=1500)
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tb, fps, files = render(Path(tmp))
        base = TiePointOptions(max_features=a.features, pair_mode="footprints")
        run(tb, fps[:2], files[:2], dataclasses.replace(base, pair_mode="all"))  # warm-up (numba)
        for name in a.variants.split(","):
            change: dict = {}
            for part in name.split("+"):
                change.update(VARIANTS[part])
            for refine in (False, True):
                opt = dataclasses.replace(base, **{**change, "refine": refine})
                fig = run(tb, fps, files, opt)
                print(name, "refined" if refine else "keypoints", json.dumps(fig), flush=True)


if __name__ == "__main__":
    main()
