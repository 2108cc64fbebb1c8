"""Least-squares matching: speed (one core) and accuracy, against OpenCV's ECC as the peer, on
synthetic pairs (known affine + gain/offset + noise) and on real pairs with known homographies
(Oxford boat 1->2, bikes 1->2, graffiti 1->3; Mikolajczyk et al. 2005).

Run with one thread: ``OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 python bench/bench_lsm.py``
(the script also tells OpenCV to use one thread); ``--real-only``: only the real pairs;
``--split-sample``: only the dense real-pair study (published homographies against a robust
refit, split-sample residuals of LSM, SIFT and NCC; about a minute). Data:
``../shared/data`` next to the repository (or LIDARPHOTO_SHARED). Prints markdown tables for
bench/matching.md.
"""

from __future__ import annotations

import os
import platform
import sys
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")

import cv2
import numpy as np
from lidarphoto.core.photo.least_squares_matching import (
    LsmOptions,
    affine_start,
    lsm_batch,
    lsm_in_image,
)
from lidarphoto.core.photo.match_accuracy import (
    fit_homography,
    homography_difference,
    split_sample_residuals,
)
from lidarphoto.core.photo.template_matching import ncc_search

cv2.setNumThreads(1)
HERE = Path(__file__).resolve().parent
SHARED = Path(os.environ.get("LIDARPHOTO_SHARED", HERE.parent.parent / "shared"))
M, S = 21, 41


def waves(x, y, seed, fmax=0.25, n=40):
    """Analytic texture: exact grey values at any sub-pixel position."""
    rng = np.random.default_rng(seed)
    f = rng.uniform(0.03, fmax, n)
    th = rng.uniform(0, np.pi, n)
    ph = rng.uniform(0, 2 * np.pi, n)
    amp = 1.0 / (1 + (f / 0.1) ** 2)
    out = np.zeros(np.broadcast(x, y).shape)
    for k in range(n):
        out += amp[k] * np.cos(2 * np.pi * f[k] * (np.cos(th[k]) * x + np.sin(th[k]) * y) + ph[k])
    return 100 + 40 * out


def synthetic(k: int, noise: float, seed: int = 0):
    """k pairs, each its own texture, affine, shift, gain and offset; truth positions."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:M, 0:M] - (M - 1) / 2
    yy2, xx2 = np.mgrid[0:S, 0:S] - (S - 1) / 2
    f = np.empty((k, M, M))
    g = np.empty((k, S, S))
    truth = np.empty((k, 2))
    for i in range(k):
        a = np.eye(2) + rng.normal(0, 0.03, (2, 2))
        t = rng.uniform(-0.5, 0.5, 2)
        u = a[0, 0] * xx + a[0, 1] * yy + t[0]
        v = a[1, 0] * xx + a[1, 1] * yy + t[1]
        gain, off = rng.uniform(0.7, 1.3), rng.uniform(-20, 20)
        f[i] = gain * waves(u, v, 1000 + i) + off + rng.normal(0, noise, (M, M))
        g[i] = waves(xx2, yy2, 1000 + i) + rng.normal(0, noise, (S, S))
        truth[i] = (S - 1) / 2 + t
    return f, g, truth


def ecc_peer(f, g, start):
    """cv2.findTransformECC (MOTION_AFFINE) per patch: template f, input g."""
    out = np.full((len(f), 2), np.nan)
    crit = (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 30, 1e-4)
    h = (M - 1) / 2
    for i in range(len(f)):
        # warp: template (x, y) from its top-left -> input (col, row)
        w = np.array([[1, 0, start[i, 0] - h], [0, 1, start[i, 1] - h]], np.float32)
        try:
            _, w = cv2.findTransformECC(
                f[i].astype(np.float32),
                g[i].astype(np.float32),
                w,
                cv2.MOTION_AFFINE,
                crit,
                None,
                1,
            )
        except cv2.error:
            continue
        out[i] = w[:, :2] @ [h, h] + w[:, 2]
    return out


def speed_table():
    rows = []
    f, g, truth = synthetic(2000, 2.0)
    start = np.round(truth)
    for interp in ("bicubic", "bilinear"):
        opt = LsmOptions(interpolation=interp)
        lsm_batch(f[:50], g[:50], affine_start(start[:50]), options=opt)  # warm-up
        t0 = time.perf_counter()
        res = lsm_batch(f, g, affine_start(start), options=opt)
        dt = time.perf_counter() - t0
        err = np.hypot(*(res.position - truth).T)[res.ok]
        rows.append(
            (
                f"ours, LSM {interp} (batch of 2000)",
                len(f) / dt,
                res.ok.mean(),
                np.median(err),
                np.sqrt(np.mean(err**2)),
            )
        )
    n = 500
    t0 = time.perf_counter()
    pos = ecc_peer(f[:n], g[:n], start[:n])
    dt = time.perf_counter() - t0
    ok = np.isfinite(pos[:, 0])
    err = np.hypot(*(pos - truth[:n]).T)[ok]
    rows.append(
        (
            "OpenCV findTransformECC affine (per patch, 500)",
            n / dt,
            ok.mean(),
            np.median(err),
            np.sqrt(np.mean(err**2)),
        )
    )
    return rows


def monte_carlo_table():
    """Per texture: 500 noise draws (sigma 2 grey values in both images) of one pair with a
    known affine, gain 0.8 and offset 10: bias of the mean position and the ratio of the
    reported sigma to the Monte Carlo spread."""
    rows = []
    a_true = np.array([[1.05, 0.03], [-0.02, 0.97]])
    t_true = np.array([0.37, -0.21])
    yy, xx = np.mgrid[0:M, 0:M] - (M - 1) / 2
    yy2, xx2 = np.mgrid[0:S, 0:S] - (S - 1) / 2
    for seed in (1, 2, 3, 4, 5):
        rng = np.random.default_rng(100 + seed)
        u = a_true[0, 0] * xx + a_true[0, 1] * yy + t_true[0]
        v = a_true[1, 0] * xx + a_true[1, 1] * yy + t_true[1]
        k = 500
        f = 0.8 * waves(u, v, seed) + 10 + rng.normal(0, 2.0, (k, M, M))
        g = waves(xx2, yy2, seed) + rng.normal(0, 2.0, (k, S, S))
        c = (S - 1) / 2
        res = lsm_batch(f, g, affine_start(np.full((k, 2), c)))
        err = res.position[res.ok] - (c + t_true)
        ratio = np.sqrt((res.sigma_px[res.ok] ** 2).mean(axis=0)) / err.std(axis=0)
        rows.append((seed, res.ok.mean(), err.mean(axis=0), err.std(axis=0), ratio))
    return rows


def read_h(path: Path) -> np.ndarray:
    if path.suffix == ".xml":
        fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_READ)
        h = fs.getNode("H13").mat()
        fs.release()
        if h is None:
            h = np.loadtxt(path)
        return h / h[2, 2]
    h = np.loadtxt(path)
    return h / h[2, 2]


def apply_h(h, p):
    q = np.c_[p, np.ones(len(p))] @ h.T
    return q[:, :2] / q[:, 2:]


def local_affine(h, p):
    """(N, 2, 2) Jacobian of the homography at p."""
    eps = 0.5
    jx = (apply_h(h, p + [eps, 0]) - apply_h(h, p - [eps, 0])) / (2 * eps)
    jy = (apply_h(h, p + [0, eps]) - apply_h(h, p - [0, eps])) / (2 * eps)
    return np.stack([jx, jy], axis=2)


def warped(img1, h_true, shape):
    """img1 resampled exactly (float coordinates, cubic B-spline) into the geometry of the
    second image by h_true: a pair whose truth has no error of its own."""
    from scipy import ndimage

    a = cv2.imread(str(img1), cv2.IMREAD_GRAYSCALE).astype(np.float64)
    rr, cc = np.mgrid[0 : shape[0], 0 : shape[1]]
    src = apply_h(np.linalg.inv(h_true), np.c_[cc.ravel(), rr.ravel()].astype(np.float64))
    out = ndimage.map_coordinates(a, [src[:, 1], src[:, 0]], order=3, mode="constant", cval=0)
    rng = np.random.default_rng(0)
    return np.clip(out.reshape(shape) + rng.normal(0, 1.0, shape), 0, 255)


def local_residuals(src, dst, k: int = 12):
    """Leave-one-out residuals (px) of each match against an affine map fitted to its k
    nearest matches (in image 1): a precision figure that a smooth departure from one global
    homography (lens distortion, a scene not exactly planar, the benchmark homography's own
    error) does not enter, unlike "vs truth" and "vs own H"."""
    from scipy.spatial import cKDTree

    _, nb = cKDTree(src).query(src, k + 1)
    out = np.empty(len(src))
    for i, idx in enumerate(nb):
        idx = idx[1:]
        a = np.column_stack([src[idx] - src[i], np.ones(k)])
        coef, *_ = np.linalg.lstsq(a, dst[idx], rcond=None)
        out[i] = np.hypot(*(dst[i] - coef[2]))
    return out


def real_pair(name, img1, img2, h_true):
    a = cv2.imread(str(img1), cv2.IMREAD_GRAYSCALE)
    if isinstance(img2, np.ndarray):
        b = np.round(img2).astype(np.uint8)
    else:
        b = cv2.imread(str(img2), cv2.IMREAD_GRAYSCALE)
    sift = cv2.SIFT_create(4000)
    k1, d1 = sift.detectAndCompute(a, None)
    k2, d2 = sift.detectAndCompute(b, None)
    knn = cv2.BFMatcher().knnMatch(d1, d2, k=2)
    good = [m for m, n in knn if m.distance < 0.75 * n.distance]
    p1 = np.float64([k1[m.queryIdx].pt for m in good])
    p2 = np.float64([k2[m.trainIdx].pt for m in good])
    h_est, inl = cv2.findHomography(p1, p2, cv2.RANSAC, 3.0)
    inl = inl.ravel().astype(bool)
    sift_err = np.hypot(*(p2[inl] - apply_h(h_true, p1[inl])).T)
    # points: SIFT inlier keypoints of img1 far enough from both borders
    pts = p1[inl]
    q = apply_h(h_true, pts)
    keep = (
        (pts > 30).all(1)
        & (pts[:, 0] < a.shape[1] - 30)
        & (pts[:, 1] < a.shape[0] - 30)
        & (q > 30).all(1)
        & (q[:, 0] < b.shape[1] - 30)
        & (q[:, 1] < b.shape[0] - 30)
    )
    pts = pts[keep][:400]
    truth = apply_h(h_true, pts)
    start = apply_h(h_est, pts)
    jac = local_affine(h_est, pts)
    h = M // 2
    # NCC: img1 template warped into img2 geometry, +-4 px around the SIFT-homography position
    ncc_pos = np.full((len(pts), 2), np.nan)
    tmpl = np.empty((len(pts), M, M))
    refs = np.empty((len(pts), 2))
    af = a.astype(np.float64)
    bf = b.astype(np.float64)
    for i, (p, s, j) in enumerate(zip(pts, start, jac)):
        c, r = int(np.rint(p[0])), int(np.rint(p[1]))
        tmpl[i] = af[r - h : r + h + 1, c - h : c + h + 1]
        refs[i] = p - [c - h, r - h]
        jinv = np.linalg.inv(j)
        warp = np.hstack([jinv, (p - jinv @ [h, h])[:, None]])
        t_img = cv2.warpAffine(
            a.astype(np.float32), warp, (M, M), flags=cv2.INTER_CUBIC | cv2.WARP_INVERSE_MAP
        )
        sc, sr = int(np.rint(s[0])), int(np.rint(s[1]))
        win = bf[sr - h - 4 : sr + h + 5, sc - h - 4 : sc + h + 5]
        m = ncc_search(t_img, win)
        ncc_pos[i] = (sc - h - 4 + m.col, sr - h - 4 + m.row)
    # LSM per point (each has its own reference); batched by the reference's rounding
    lsm_pos = np.full((len(pts), 2), np.nan)
    ok = np.zeros(len(pts), bool)
    t0 = time.perf_counter()
    for i in range(len(pts)):
        res = lsm_in_image(
            tmpl[i][None],
            bf,
            affine_start(ncc_pos[i][None], jac[i][None]),
            reference=tuple(refs[i]),
        )
        lsm_pos[i] = res.position[0]
        ok[i] = res.ok[0]
    dt = time.perf_counter() - t0
    ncc_err = np.hypot(*(ncc_pos - truth).T)
    lsm_err = np.hypot(*(lsm_pos - truth).T)[ok]
    # internal precision: residuals of a homography fitted to the LSM matches
    h_fit, _ = cv2.findHomography(pts[ok], lsm_pos[ok], cv2.LMEDS)
    fit_res = np.hypot(*(lsm_pos[ok] - apply_h(h_fit, pts[ok])).T)
    h_fit_n, _ = cv2.findHomography(pts, ncc_pos, cv2.LMEDS)
    fit_n = np.hypot(*(ncc_pos - apply_h(h_fit_n, pts)).T)
    h_fit_s, _ = cv2.findHomography(p1[inl], p2[inl], cv2.LMEDS)
    fit_s = np.hypot(*(p2[inl] - apply_h(h_fit_s, p1[inl])).T)
    return {
        "pair": name,
        "sift_local": np.median(local_residuals(p1[inl], p2[inl])),
        "ncc_local": np.median(local_residuals(pts, ncc_pos)),
        "lsm_local": np.median(local_residuals(pts[ok], lsm_pos[ok])),
        "sift_n": int(inl.sum()),
        "sift": np.median(sift_err),
        "sift_fit": np.median(fit_s),
        "n": len(pts),
        "ncc": np.median(ncc_err),
        "ncc_fit": np.median(fit_n),
        "lsm_ok": int(ok.sum()),
        "lsm": np.median(lsm_err),
        "lsm_fit": np.median(fit_res),
        "lsm_rate": len(pts) / dt,
        "lsm_bias": np.median(lsm_pos[ok] - truth[ok], axis=0),
    }


# --- dense study: how good are the published homographies, how good are the matches ---------

GRID = 10  # px between the grid points of image 1
BIG = 41  # template side of the dense study
BLOCK = 64.0  # checkerboard block of the split-sample design, px
#: LSM points kept by their own a-posteriori sigma (larger axis). Chosen from the synthetic
#: pairs, where the reported sigma is within 5 % of the Monte Carlo spread: the median error
#: of such a point from noise alone is at most 1.18 x 0.02 = 0.024 px.
SIGMA_MAX = 0.02


def _grey(path) -> np.ndarray:
    return cv2.imread(str(path), cv2.IMREAD_GRAYSCALE)


def _sift(a, b):
    sift = cv2.SIFT_create(4000)
    k1, d1 = sift.detectAndCompute(a, None)
    k2, d2 = sift.detectAndCompute(b, None)
    good = [m for m, n in cv2.BFMatcher().knnMatch(d1, d2, k=2) if m.distance < 0.75 * n.distance]
    p1 = np.float64([k1[m.queryIdx].pt for m in good])
    p2 = np.float64([k2[m.trainIdx].pt for m in good])
    h_est, inl = cv2.findHomography(p1, p2, cv2.RANSAC, 3.0)
    inl = inl.ravel().astype(bool)
    return p1[inl], p2[inl], h_est / h_est[2, 2]


def _ncc_dense(a, b, pts, start, jac, m):
    """NCC with the image-1 template warped by the local affine, +-4 px, parabola peak."""
    h = m // 2
    out = np.full((len(pts), 2), np.nan)
    af = a.astype(np.float32)
    bf = b.astype(np.float32)
    for i, (p, s, j) in enumerate(zip(pts, start, jac)):
        jinv = np.linalg.inv(j)
        warp = np.hstack([jinv, (p - jinv @ [h, h])[:, None]])
        t_img = cv2.warpAffine(af, warp, (m, m), flags=cv2.INTER_CUBIC | cv2.WARP_INVERSE_MAP)
        sc, sr = int(np.rint(s[0])), int(np.rint(s[1]))
        win = bf[sr - h - 4 : sr + h + 5, sc - h - 4 : sc + h + 5]
        if win.shape != (m + 8, m + 8):
            continue
        r = ncc_search(t_img, win)
        out[i] = (sc - h - 4 + r.col, sr - h - 4 + r.row)
    return out


def _med(r) -> float:
    r = np.asarray(r, dtype=np.float64).reshape(-1, 2)
    d = np.hypot(*r.T)
    d = d[np.isfinite(d)]
    return float(np.median(d)) if d.size else float("nan")


def dense_pair(name, a, b, h_pub, plane_rows=None):
    """Grid points of image 1 (every GRID px) matched into image 2 by LSM (BIG-px template of
    image 1's pixels, start: the SIFT homography's position and local affine), NCC (the same
    start) and SIFT keypoints; each scored against the published homography and by the
    split-sample residuals (a homography, and a homography + cubic correction, fitted to the
    other half of a checkerboard of BLOCK-px squares). ``plane_rows``: only image-1 rows
    above it lie on the plane (graffiti: the strip below the wall is another plane)."""
    s1, s2, h_sift = _sift(a, b)
    half = BIG // 2
    mg = half + 8
    rr, cc = np.mgrid[mg : a.shape[0] - mg : GRID, mg : a.shape[1] - mg : GRID]
    pts = np.column_stack([cc.ravel(), rr.ravel()]).astype(np.float64)
    if plane_rows is not None:
        pts = pts[pts[:, 1] < plane_rows]
        keep_s = s1[:, 1] < plane_rows
        s1, s2 = s1[keep_s], s2[keep_s]
    start = apply_h(h_sift, pts)
    inside = ((start > mg) & (start < np.array(b.shape[::-1]) - mg)).all(axis=1)
    pts, start = pts[inside], start[inside]
    jac = local_affine(h_sift, pts)
    af = a.astype(np.float64)
    ci = pts.astype(np.intp)
    tmpl = np.stack([af[r - half : r + half + 1, c - half : c + half + 1] for c, r in ci])
    t0 = time.process_time()
    res = lsm_in_image(tmpl, b.astype(np.float64), affine_start(start, jac))
    cpu = time.process_time() - t0
    ncc = _ncc_dense(a, b, pts, start, jac, BIG)
    ok = res.ok
    sel = ok & (res.sigma_px.max(axis=1) < SIGMA_MAX)
    lsm = res.position
    # (a) the published homography against a robust refit to all accepted LSM matches
    h_fit, kept = fit_homography(pts[ok], lsm[ok])
    grid, diff = homography_difference(h_fit, h_pub, a.shape, GRID)
    if plane_rows is not None:
        on = grid[:, 1] < plane_rows
        grid, diff = grid[on], diff[on]
    dn = np.hypot(*diff.T)
    # the difference field's affine part: shift at the image centre, scale, rotation
    c0 = grid.mean(axis=0)
    coef = np.linalg.lstsq(np.column_stack([np.ones(len(grid)), grid - c0]), diff, rcond=None)[0]
    lin = coef[1:].T
    smooth = np.hypot(*(diff - np.column_stack([np.ones(len(grid)), grid - c0]) @ coef).T)
    field = {
        "median": np.median(dn), "p95": np.percentile(dn, 95), "max": dn.max(),
        "shift": coef[0], "scale": 0.5 * np.trace(lin), "rot": 0.5 * (lin[1, 0] - lin[0, 1]),
        "rest": np.percentile(smooth, 95), "kept": kept.mean(),
    }  # fmt: skip
    rows = []
    for label, p, q in (
        ("SIFT keypoints (RANSAC inliers)", s1, s2),
        (f"NCC {BIG} px, parabola peak", pts, ncc),
        (f"LSM {BIG} px, all accepted", pts[ok], lsm[ok]),
        (f"LSM {BIG} px, sigma < {SIGMA_MAX} px", pts[sel], lsm[sel]),
    ):
        fin = np.isfinite(q).all(axis=1)
        p, q = p[fin], q[fin]
        rows.append(
            (
                label,
                len(p),
                _med(q - apply_h(h_pub, p)),
                _med(split_sample_residuals(p, q, BLOCK)),
                _med(split_sample_residuals(p, q, BLOCK, degree=3)),
            )
        )
    return {"pair": name, "field": field, "rows": rows, "rate": len(pts) / cpu, "n": len(pts)}


def split_sample_study() -> None:
    hp = SHARED / "data" / "homography-pairs"
    ga = SHARED / "data" / "opencv-aerial"
    cases = []
    for seq, n in (("boat", 2), ("boat", 3), ("bikes", 2), ("bikes", 3)):
        img_n = _grey(hp / seq / f"img{n}.png")
        h_n = read_h(hp / seq / f"H1to{n}p")
        cases.append((f"{seq} 1->{n}", _grey(hp / seq / "img1.png"), img_n, h_n, None))
    cases.append(("graf 1->3 (wall: image-1 rows < 500)", _grey(ga / "graf1.png"),
                  _grey(ga / "graf3.png"), read_h(ga / "H1to3p.xml"), 500))  # fmt: skip
    b1 = _grey(hp / "boat" / "img1.png")
    hb = read_h(hp / "boat" / "H1to2p")
    cases.append(("control: boat 1 -> 1 warped by H1to2p, noise 1 grey value", b1,
                  np.round(warped(hp / "boat" / "img1.png", hb, b1.shape)).astype(np.uint8),
                  hb, None))  # fmt: skip
    out = [dense_pair(*c) for c in cases]
    print(
        f"\n(a) Published homography against a robust refit to the accepted LSM matches "
        f"({BIG} px templates, grid {GRID} px); difference over an image-1 grid of {GRID} px:"
    )
    print(
        "\n| pair | matches kept by the fit | median (px) | 95th pct | max | "
        "shift at centre dx, dy | scale | rotation | 95th pct after the affine part |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for r in out:
        f = r["field"]
        print(
            f"| {r['pair']} | {f['kept']:.0%} | {f['median']:.3f} | {f['p95']:.3f} | "
            f"{f['max']:.3f} | {f['shift'][0]:+.3f}, {f['shift'][1]:+.3f} | "
            f"{f['scale'] * 1e6:+.0f} ppm | {f['rot'] * 1e6:+.0f} µrad | {f['rest']:.3f} |"
        )
    print(
        f"\n(b) Median match error (px): against the published homography; split-sample "
        f"(checkerboard of {BLOCK:.0f} px blocks, fit on one colour, scored on the other) "
        "with a homography and with a homography + cubic correction:"
    )
    print("\n| pair | method | points | vs published H | split-sample H | "
          "split-sample H + cubic |")  # fmt: skip
    print("|---|---|---|---|---|---|")
    for r in out:
        for label, n, pub, s0, s3 in r["rows"]:
            print(f"| {r['pair']} | {label} | {n} | {pub:.3f} | {s0:.3f} | {s3:.3f} |")
    rates = ", ".join(f"{r['pair'].split(' (')[0]} {r['rate']:,.0f}" for r in out)
    print(f"\nLSM {BIG} px, matches per CPU second: {rates}")


def main() -> int:
    import subprocess

    load = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    when = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    print(
        f"date {when}; {platform.processor() or platform.machine()}; "
        f"python {sys.version.split()[0]}, numpy {np.__version__}, opencv {cv2.__version__}; "
        f"uptime: {load}"
    )
    if "--split-sample" in sys.argv:
        split_sample_study()
        return 0
    print("\n| method | matches/s (1 thread) | accepted | median error (px) | RMS error (px) |")
    print("|---|---|---|---|---|")
    if "--real-only" not in sys.argv:
        for name, rate, acc, med, rms in speed_table():
            print(f"| {name} | {rate:,.0f} | {acc:.1%} | {med:.4f} | {rms:.4f} |")
        print(
            "\n| texture seed | accepted | bias col, row (px) | MC sigma col, row (px) | "
            "reported / MC sigma |"
        )
        print("|---|---|---|---|---|")
        for seed, acc, bias, mc, ratio in monte_carlo_table():
            print(
                f"| {seed} | {acc:.0%} | {bias[0]:+.4f}, {bias[1]:+.4f} | "
                f"{mc[0]:.4f}, {mc[1]:.4f} | {ratio[0]:.2f}, {ratio[1]:.2f} |"
            )
    hp = SHARED / "data" / "homography-pairs"
    ga = SHARED / "data" / "opencv-aerial"
    pairs = [
        ("boat 1->2", hp / "boat/img1.png", hp / "boat/img2.png", read_h(hp / "boat/H1to2p")),
        ("bikes 1->2", hp / "bikes/img1.png", hp / "bikes/img2.png", read_h(hp / "bikes/H1to2p")),
    ]
    pairs.append(("graf 1->3", ga / "graf1.png", ga / "graf3.png", read_h(ga / "H1to3p.xml")))
    for name, i1, i2, h in list(pairs):
        shape = cv2.imread(str(i2), cv2.IMREAD_GRAYSCALE).shape
        pairs.append(
            (
                f"{name.split()[0]} 1 -> 1 warped by the H of {name.split()[1]}, "
                "noise 1 grey value",
                i1,
                warped(i1, h, shape),
                h,
            )
        )
    print(
        "\n| pair | SIFT matches | SIFT vs truth | SIFT vs own H | points | NCC vs truth | "
        "NCC vs own H | LSM accepted | LSM vs truth | LSM vs own H | LSM median dx, dy | "
        "local affine LOO: SIFT / NCC / LSM |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name, i1, i2, h in pairs:
        r = real_pair(name, i1, i2, h)
        print(
            f"| {r['pair']} | {r['sift_n']} | {r['sift']:.3f} | {r['sift_fit']:.3f} | {r['n']} | "
            f"{r['ncc']:.3f} | {r['ncc_fit']:.3f} | {r['lsm_ok']} | {r['lsm']:.3f} | "
            f"{r['lsm_fit']:.3f} | {r['lsm_bias'][0]:+.3f}, {r['lsm_bias'][1]:+.3f} | "
            f"{r['sift_local']:.3f} / {r['ncc_local']:.3f} / {r['lsm_local']:.3f} |"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
