"""Benchmark: opening a 195-megapixel aerial frame in the picking view vs QGIS's own renderer.

    QT_QPA_PLATFORM=offscreen .venv-qgis/bin/python bench/bench_image_open.py [--data DIR]
        [--cases striped_raw,striped_lzw,tiled_lzw,tiled_jpeg8] [--size 17310x11310]

The frames (made once into DIR, default $TMPDIR/lidarphoto_bench_images, with GDAL): the size
of an UltraCam Falcon frame, 17310 x 11310 x 3 bands, an aerial-like texture (vignetting,
gradients, 64-px parcels of random brightness per band, Gaussian noise of 250 DN, so
compression and the stretch behave as on real frames), stored as

* ``striped_raw``: uint16, uncompressed, striped (GDAL's default: one row per strip), no
  overviews (the way photogrammetric suppliers deliver frames: the worst case);
* ``striped_lzw``: the same, LZW;
* ``tiled_lzw``: uint16, 256 x 256 tiles, LZW, no overviews;
* ``tiled_jpeg8``: 8-bit RGB, 256 x 256 tiles, JPEG (YCbCr, quality 90), internal overviews
  (a common delivery).

Each measurement runs in a fresh child process (its own QgsApplication, peak RSS = ru_maxrss of
that process alone), in this order per frame: QGIS without overviews, the view without
overviews (which builds the sidecar .ovr in the background), the former synchronous path
(``ImageSource(build_overviews=True)``: pyramid built in the GUI thread) for the blocked
time, then the view and QGIS again with the .ovr. The page cache is warm (the frames were just
written or read); the machine is shared, so wall times carry noise (see ../shared/PEERS.md).

Ours: :class:`ImageView` 1200 x 800 px, shown offscreen. "preview" = the fitted image first on
screen; "first view" = nothing left to load at the fit zoom (the tiles of the fit level, or,
while the pyramid is being built, the preview that stands for them when it is at most 1.5x
upscaled); "sharp" = once the pyramid exists, the fit level read from it; "1:1" = zoom about
a point to one image pixel per screen pixel until every visible tile is shown; "pan" = one
screen width right, then one screen height down, until every tile is shown. "GUI block" = the
longest interval between two ticks of a 10 ms QTimer in the GUI thread during all of it.

Peer: QGIS 3.22 rendering the same file as a QgsRasterLayer with its default renderer
(multiband colour, cumulative cut stretch) through QgsMapRendererParallelJob at the same
output size: layer creation + first render of the full extent, a render at 1:1 about the same
point, one screen to the right, one screen down. QGIS blocks nothing either (its jobs are
threaded), so the comparison is the time until the picture is there.

Prints one JSON line per run and a Markdown table; bench/image_open.md has the last figures.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

VIEW_W, VIEW_H = 1200, 800
CASES = ("striped_raw", "striped_lzw", "tiled_lzw", "tiled_jpeg8")
ZOOM_AT = (0.3, 0.6)  # the 1:1 zoom is about this point of the view (fraction of its size)


# ------------------------------------------------------------------------------ frames
def _texture(r0: int, h: int, w: int, full_h: int, rng, coarse) -> np.ndarray:
    yy = np.arange(r0, r0 + h, dtype=np.float32)[:, None]
    xx = np.arange(w, dtype=np.float32)[None, :]
    r2 = ((xx - w / 2) / w) ** 2 + ((yy - full_h / 2) / full_h) ** 2
    base = 14000.0 * (1.0 - 0.8 * r2) + 3000.0 * (xx / w) - 2000.0 * (yy / full_h)
    base = base + 1200.0 * np.sin(xx / 23.0) * np.cos(yy / 31.0)
    parcels = coarse[(np.arange(r0, r0 + h) // 64)[:, None], (np.arange(w) // 64)[None, :]]
    a = base[:, :, None] * parcels + rng.normal(0.0, 250.0, (h, w, 3)).astype(np.float32)
    return np.clip(a, 0, 65535).astype(np.uint16)


def make_frames(folder: Path, w: int, h: int, cases) -> dict[str, Path]:
    """The frames of the cases (kept between runs; remade when missing)."""
    from osgeo import gdal

    gdal.UseExceptions()
    folder.mkdir(parents=True, exist_ok=True)
    tag = f"{w}x{h}"
    paths = {c: folder / f"{c}_{tag}.tif" for c in CASES}
    raw = paths["striped_raw"]
    if not raw.exists():
        t0 = time.perf_counter()
        rng = np.random.default_rng(7)
        coarse = rng.uniform(0.35, 1.3, (h // 64 + 1, w // 64 + 1, 3)).astype(np.float32)
        tmp = raw.with_suffix(".part.tif")
        ds = gdal.GetDriverByName("GTiff").Create(str(tmp), w, h, 3, gdal.GDT_UInt16)
        for r0 in range(0, h, 256):
            a = _texture(r0, min(256, h - r0), w, h, rng, coarse)
            ds.WriteRaster(
                0, r0, w, a.shape[0], a.tobytes(), buf_type=gdal.GDT_UInt16,
                band_list=[1, 2, 3], buf_pixel_space=6, buf_line_space=6 * w, buf_band_space=2,
            )  # fmt: skip
        ds = None
        os.replace(tmp, raw)
        print(f"made {raw.name} in {time.perf_counter() - t0:.1f} s", file=sys.stderr)
    recipes = {
        "striped_lzw": dict(creationOptions=["COMPRESS=LZW"]),
        "tiled_lzw": dict(creationOptions=["TILED=YES", "COMPRESS=LZW"]),
        "tiled_jpeg8": dict(
            outputType=gdal.GDT_Byte,
            scaleParams=[[1000, 22000, 0, 255]],
            creationOptions=["TILED=YES", "COMPRESS=JPEG", "PHOTOMETRIC=YCBCR", "JPEG_QUALITY=90"],
        ),
    }
    for case, opts in recipes.items():
        path = paths[case]
        if case not in cases or path.exists():
            continue
        t0 = time.perf_counter()
        tmp = path.with_suffix(".part.tif")
        gdal.Translate(str(tmp), str(raw), **opts)
        if case == "tiled_jpeg8":  # internal overviews, JPEG too, as delivered
            gdal.SetConfigOption("COMPRESS_OVERVIEW", "JPEG")
            gdal.SetConfigOption("PHOTOMETRIC_OVERVIEW", "YCBCR")
            ds = gdal.Open(str(tmp), gdal.GA_Update)
            ds.BuildOverviews("AVERAGE", [2, 4, 8, 16, 32, 64])
            ds = None
            gdal.SetConfigOption("COMPRESS_OVERVIEW", None)
            gdal.SetConfigOption("PHOTOMETRIC_OVERVIEW", None)
        os.replace(tmp, path)
        for aux in folder.glob("*.part.tif.aux.xml"):
            aux.unlink()
        print(f"made {path.name} in {time.perf_counter() - t0:.1f} s", file=sys.stderr)
    return {c: paths[c] for c in cases}


# ------------------------------------------------------------------------------ children
_APP = []  # the application outlives every widget (destroyed last, at exit)


def _app():
    from qgis.core import QgsApplication  # noqa: TID251 - a QGIS benchmark

    app = QgsApplication([], True)
    app.initQgis()
    _APP.append(app)
    return app


def _rss_mb() -> float:
    """Peak resident memory of this process, MB. VmHWM, not ru_maxrss: Linux carries
    ru_maxrss over exec, so a child would report its parent's peak (the frame generation)."""
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024.0
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _wait(app, cond, timeout_s: float) -> bool:
    t_end = time.perf_counter() + timeout_s
    while not cond() and time.perf_counter() < t_end:
        app.processEvents()
        time.sleep(0.001)
    return cond()


def run_ours(path: Path, mode: str) -> dict:
    """mode "async": the view as it is; "sync": the pyramid built in the GUI thread first."""
    from lidarphoto.plugin.image_source import ImageSource
    from lidarphoto.plugin.image_view import ImageView
    from qgis.PyQt.QtCore import QPointF, QThreadPool, QTimer  # noqa: TID251

    app = _app()
    view = ImageView()
    view.resize(VIEW_W, VIEW_H)
    view.show()
    ticks: list[float] = []
    beat = QTimer()
    beat.setInterval(10)
    beat.timeout.connect(lambda: ticks.append(time.perf_counter()))
    beat.start()
    _wait(app, lambda: len(ticks) >= 3, 2.0)
    built: list[float] = []
    view.overviewFinished.connect(lambda ok, _m: built.append(time.perf_counter()) if ok else None)
    had_ovr = Path(str(path) + ".ovr").exists()
    t0 = time.perf_counter()
    source = ImageSource(path, build_overviews=(mode == "sync"))
    open_s = time.perf_counter() - t0
    view.set_source(source)
    returned_s = time.perf_counter() - t0
    building = view.building()
    out = {"tool": "ours", "mode": mode, "file": path.name, "had_ovr": had_ovr}
    ok = _wait(app, lambda: view.preview_shown, 600.0)
    out["preview_s"] = round(time.perf_counter() - t0, 3)
    ok = ok and view.wait_idle(600.0, build=False)
    out["first_view_s"] = round(time.perf_counter() - t0, 3)
    if building:
        ok = ok and view.wait_idle(1200.0, build=True)
        out["ovr_build_s"] = round(built[-1] - t0, 2) if built else None
        out["sharp_view_s"] = round(time.perf_counter() - t0, 3)
    elif mode == "sync" and not had_ovr:
        out["ovr_build_s"] = round(open_s, 2)  # ImageSource built it, in this thread
    vp = view.viewport().rect()
    at = QPointF(vp.width() * ZOOM_AT[0], vp.height() * ZOOM_AT[1])
    t1 = time.perf_counter()
    view.zoom_about(1.0 / view.zoom, at)
    ok = ok and view.wait_idle(600.0)
    out["zoom_1to1_s"] = round(time.perf_counter() - t1, 3)
    t1 = time.perf_counter()
    view.pan(-vp.width(), 0)
    ok = ok and view.wait_idle(600.0)
    out["pan_right_s"] = round(time.perf_counter() - t1, 3)
    t1 = time.perf_counter()
    view.pan(0, -vp.height())
    ok = ok and view.wait_idle(600.0)
    out["pan_down_s"] = round(time.perf_counter() - t1, 3)
    _wait(app, lambda: False, 0.05)
    gaps = np.diff(np.array(ticks))
    out.update(
        ok=bool(ok) and not view.last_error,
        open_s=round(open_s, 3),
        set_source_returned_s=round(returned_s, 3),
        gui_block_s=round(float(gaps.max()), 3),
        tiles_read=view._loader.tiles_read,
        overviews=source.overview_count,
        rss_mb=round(_rss_mb()),
    )
    assert view.shutdown(60.0)
    source.close()  # GDAL handles must not outlive exitQgis (it destroys GDAL's drivers)
    view.deleteLater()
    app.processEvents()
    QThreadPool.globalInstance().waitForDone()
    app.exitQgis()
    return out


def run_qgis(path: Path) -> dict:
    from qgis.core import (  # noqa: TID251
        QgsMapRendererParallelJob,
        QgsMapSettings,
        QgsRasterLayer,
        QgsRectangle,
    )
    from qgis.PyQt.QtCore import QSize  # noqa: TID251

    app = _app()
    had_ovr = Path(str(path) + ".ovr").exists()
    out = {"tool": "qgis", "mode": "QgsMapRendererParallelJob", "file": path.name}
    out["had_ovr"] = had_ovr

    def render(extent: QgsRectangle, layer) -> tuple[float, object]:
        s = QgsMapSettings()
        s.setLayers([layer])
        s.setOutputSize(QSize(VIEW_W, VIEW_H))
        s.setExtent(extent)
        s.setDestinationCrs(layer.crs())
        job = QgsMapRendererParallelJob(s)
        t = time.perf_counter()
        job.start()
        job.waitForFinished()
        return time.perf_counter() - t, job.renderedImage()

    t0 = time.perf_counter()
    layer = QgsRasterLayer(str(path), "frame", "gdal")
    assert layer.isValid(), path
    out["layer_s"] = round(time.perf_counter() - t0, 3)
    full = layer.extent()
    first, img = render(full, layer)
    out["first_view_s"] = round(time.perf_counter() - t0, 3)
    out["first_render_s"] = round(first, 3)
    # 1:1 about the same image point as ours: the fitted view maps VIEW px to the extent
    px = full.width() / layer.width()  # map units per image pixel
    scale = max(full.width() / VIEW_W, full.height() / VIEW_H)  # map units per screen px
    cx = full.center().x() + (ZOOM_AT[0] - 0.5) * VIEW_W * scale
    cy = full.center().y() - (ZOOM_AT[1] - 0.5) * VIEW_H * scale
    half_w, half_h = VIEW_W * px / 2, VIEW_H * px / 2
    one = QgsRectangle(cx - half_w, cy - half_h, cx + half_w, cy + half_h)
    t, _img = render(one, layer)
    out["zoom_1to1_s"] = round(t, 3)
    right = QgsRectangle(one)
    right.setXMinimum(one.xMinimum() + VIEW_W * px)
    right.setXMaximum(one.xMaximum() + VIEW_W * px)
    t, _img = render(right, layer)
    out["pan_right_s"] = round(t, 3)
    down = QgsRectangle(right)
    down.setYMinimum(right.yMinimum() - VIEW_H * px)
    down.setYMaximum(right.yMaximum() - VIEW_H * px)
    t, _img = render(down, layer)
    out["pan_down_s"] = round(t, 3)
    out["ok"] = not img.isNull()
    out["rss_mb"] = round(_rss_mb())
    del layer
    app.exitQgis()
    return out


def child(args) -> None:
    path = Path(args.child_file)
    out = run_qgis(path) if args.child == "qgis" else run_ours(path, args.child)
    print("RESULT " + json.dumps(out), flush=True)


def spawn(kind: str, path: Path) -> dict:
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen")
    cmd = [sys.executable, __file__, "--child", kind, "--child-file", str(path)]
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=3600)
    for line in proc.stdout.splitlines():
        if line.startswith("RESULT "):
            out = json.loads(line[7:])
            print(json.dumps(out), flush=True)
            return out
    raise RuntimeError(f"{kind} {path.name} failed:\n{proc.stdout[-2000:]}\n{proc.stderr[-3000:]}")


def _remove_ovr(path: Path) -> None:
    ovr = Path(str(path) + ".ovr")
    if ovr.exists():
        ovr.unlink()


def _remove_aux(path: Path) -> None:
    """QGIS stores the statistics of its stretch in <frame>.aux.xml: every QGIS run starts
    without them, as with a frame just delivered."""
    aux = Path(str(path) + ".aux.xml")
    if aux.exists():
        aux.unlink()


def table(rows: list[dict]) -> str:
    head = (
        "| frame | .ovr | tool | preview s | first view s | ratio | .ovr build s | sharp s | "
        "1:1 s | pan right s | pan down s | GUI block s | peak RSS MB |"
    )
    lines = [head, "|" + " --- |" * 13]
    peers = {(r["file"], r["had_ovr"]): r for r in rows if r["tool"] == "qgis"}

    def f(v, fmt="{:.3f}"):
        return "-" if v is None else fmt.format(v)

    for r in rows:
        peer = peers.get((r["file"], r["had_ovr"]))
        ratio = (
            f"{r['first_view_s'] / peer['first_view_s']:.2f}"
            if peer and r["tool"] == "ours"
            else "-"
        )
        tool = "QGIS" if r["tool"] == "qgis" else f"ours ({r['mode']})"
        lines.append(
            f"| {r['file']} | {'yes' if r['had_ovr'] else 'no'} | {tool} | "
            f"{f(r.get('preview_s'))} | {f(r['first_view_s'])} | {ratio} | "
            f"{f(r.get('ovr_build_s'), '{:.2f}')} | "
            f"{f(r.get('sharp_view_s'))} | {f(r['zoom_1to1_s'])} | {f(r['pan_right_s'])} | "
            f"{f(r['pan_down_s'])} | {f(r.get('gui_block_s'))} | {r['rss_mb']} |"
        )
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument(
        "--data", type=Path, default=Path(tempfile.gettempdir()) / "lidarphoto_bench_images"
    )
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--size", default="17310x11310")
    ap.add_argument("--child", help=argparse.SUPPRESS)
    ap.add_argument("--child-file", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        child(args)
        return
    w, h = (int(v) for v in args.size.lower().split("x"))
    cases = [c for c in args.cases.split(",") if c]
    frames = make_frames(args.data, w, h, cases)
    rows = []
    for case in cases:
        path = frames[case]
        internal = case == "tiled_jpeg8"  # delivered with its pyramid: nothing to build
        _remove_ovr(path)
        _remove_aux(path)
        rows.append(spawn("qgis", path))
        rows.append(spawn("async", path))
        if not internal:
            _remove_ovr(path)
            rows.append(spawn("sync", path))  # the former behaviour, for the GUI block
            rows.append(spawn("async", path))  # now with the .ovr
            _remove_aux(path)
            rows.append(spawn("qgis", path))
    print()
    print(table(rows))


if __name__ == "__main__":
    main()
