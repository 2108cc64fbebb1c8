"""The picking view keeps the GUI responsive on a large striped image without overviews.

Real QGIS (pytest-qgis, offscreen), a real GDAL striped 16-bit RGB TIFF made here (6000 x 4000,
LZW, one row per strip: GDAL's default and the way photogrammetric suppliers deliver frames),
the real ImageView/ImageSource and the real QGIS task manager.

How GUI blocking is measured: a QTimer in the GUI thread ticks every 20 ms while the image is
opened, the pyramid built and the view zoomed and panned; the largest interval between two
ticks is the longest time the GUI thread was unavailable. The bound is the issue's 0.2 s: one
GUI-thread step here is at most a 1024-px background copy or a reopen of the dataset (a few
ms), and a 0.2 s bound leaves room for the scheduler of a shared 2-core machine. The same
measurement of the synchronous path (the pyramid built in the caller's thread, as before)
must exceed the bound, which shows that the measurement can fail.
"""

from __future__ import annotations

import math
import shutil
import time
from pathlib import Path

import numpy as np
import pytest
from lidarphoto.plugin.image_source import ImageSource, ImageSourceError
from lidarphoto.plugin.image_view import TILE, ImageView
from osgeo import gdal
from qgis.PyQt.QtCore import QPoint, QPointF, Qt, QTimer
from qgis.PyQt.QtTest import QTest
from qgis.PyQt.QtWidgets import QApplication

W, H = 6000, 4000
BLOCK_BOUND_S = 0.2
NOISE_DN = 250.0


def _texture(r0: int, h: int, rng, coarse) -> np.ndarray:
    """Rows r0..r0+h of an aerial-like 16-bit RGB texture: vignetting, gradients, 64-px
    "parcels" of random brightness per band and Gaussian noise (so LZW and the stretch work
    as on real frames)."""
    yy = np.arange(r0, r0 + h, dtype=np.float32)[:, None]
    xx = np.arange(W, dtype=np.float32)[None, :]
    r2 = ((xx - W / 2) / W) ** 2 + ((yy - H / 2) / H) ** 2
    base = 14000.0 * (1.0 - 0.8 * r2) + 3000.0 * (xx / W) - 2000.0 * (yy / H)
    base = base + 1200.0 * np.sin(xx / 23.0) * np.cos(yy / 31.0)
    parcels = coarse[(np.arange(r0, r0 + h) // 64)[:, None], (np.arange(W) // 64)[None, :]]
    a = base[:, :, None] * parcels + rng.normal(0.0, NOISE_DN, (h, W, 3)).astype(np.float32)
    return np.clip(a, 0, 65535).astype(np.uint16)


@pytest.fixture(scope="module")
def striped(tmp_path_factory) -> Path:
    """The 6000 x 4000 x 3 uint16 striped LZW TIFF without overviews (made once)."""
    path = tmp_path_factory.mktemp("striped") / "frame.tif"
    rng = np.random.default_rng(11)
    coarse = rng.uniform(0.35, 1.3, (H // 64 + 1, W // 64 + 1, 3)).astype(np.float32)
    ds = gdal.GetDriverByName("GTiff").Create(str(path), W, H, 3, gdal.GDT_UInt16, ["COMPRESS=LZW"])
    for r0 in range(0, H, 500):
        a = _texture(r0, min(500, H - r0), rng, coarse)
        ds.WriteRaster(
            0, r0, W, a.shape[0], a.tobytes(), buf_type=gdal.GDT_UInt16,
            band_list=[1, 2, 3], buf_pixel_space=6, buf_line_space=6 * W, buf_band_space=2,
        )  # fmt: skip
    ds = None
    check = gdal.Open(str(path))
    assert check.GetRasterBand(1).GetBlockSize() == [W, 1]  # striped, one row per strip
    assert check.GetRasterBand(1).GetOverviewCount() == 0
    return path


@pytest.fixture()
def image(striped, tmp_path) -> Path:
    """A fresh copy (no .ovr) in a folder of its own."""
    path = tmp_path / "frame.tif"
    shutil.copy(striped, path)
    return path


@pytest.fixture()
def view(qgis_app):
    v = ImageView()
    v.resize(1000, 700)
    v.show()
    QTest.qWaitForWindowExposed(v, 2000)
    yield v
    v.set_source(None)
    _wait(lambda: not v.background_tasks(), 30.0)
    v.close()
    v.deleteLater()
    QApplication.processEvents()


def _wait(cond, timeout_s: float = 60.0) -> bool:
    t_end = time.perf_counter() + timeout_s
    while not cond() and time.perf_counter() < t_end:
        QApplication.processEvents()
        time.sleep(0.002)
    return cond()


class Heartbeat:
    """Ticks of a 20 ms QTimer in the GUI thread; ``max_gap()`` is the longest block."""

    def __init__(self) -> None:
        self.ticks: list[float] = []
        self.timer = QTimer()
        self.timer.setInterval(20)
        self.timer.timeout.connect(lambda: self.ticks.append(time.perf_counter()))

    def __enter__(self) -> Heartbeat:
        self.timer.start()
        _wait(lambda: len(self.ticks) >= 2, 2.0)
        return self

    def __exit__(self, *exc) -> None:
        _wait(lambda: False, 0.05)
        self.timer.stop()

    def max_gap(self) -> float:
        return float(np.diff(self.ticks).max())


def _temporaries(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if "lidarphoto-ovr" in p.name)


def _pixmap_rgb(item) -> np.ndarray:
    """(h, w, 3) uint8 of a QGraphicsPixmapItem's pixmap."""
    img = item.pixmap().toImage()
    w, h = img.width(), img.height()
    ptr = img.constBits()
    ptr.setsize(img.bytesPerLine() * h)
    a = np.frombuffer(ptr, np.uint8).reshape(h, img.bytesPerLine() // 4, 4)[:, :w]
    return a[:, :, 2::-1].copy()  # B G R A -> R G B


def test_open_without_overviews_does_not_block_and_then_shows_the_pyramid(view, image):
    progress = []
    finished = []
    view.overviewProgress.connect(progress.append)
    view.overviewFinished.connect(lambda ok, msg: finished.append((ok, msg)))
    with Heartbeat() as beat:
        t0 = time.perf_counter()
        source = ImageSource(image)
        view.set_source(source)
        returned_s = time.perf_counter() - t0
        assert view.building() and not source.quick
        assert _wait(lambda: view.preview_shown, 30.0)
        preview_s = time.perf_counter() - t0
        # zoom in and pan while the pyramid is being built: tiles come from the worker
        view.zoom_about(4.0, QPointF(300, 250))
        view.pan(-200, 150)
        assert view.wait_idle(120.0), view.last_error
        done_s = time.perf_counter() - t0
    gap = beat.max_gap()
    print(
        f"\nopen returned {returned_s:.3f} s, preview {preview_s:.3f} s, built and idle "
        f"{done_s:.3f} s, longest GUI block {gap:.3f} s, {len(progress)} progress signals"
    )
    assert gap < BLOCK_BOUND_S
    assert finished and finished[-1][0], finished
    assert progress and progress[-1] == pytest.approx(100.0) and progress == sorted(progress)
    assert (image.parent / "frame.tif.ovr").is_file() and not _temporaries(image.parent)
    assert source.overview_count >= 4 and source.quick
    assert view.tile_count() > 0

    # the sharp levels: at 1/2 zoom the tiles are level 1 of the pyramid, GDAL's 2 x 2 mean
    # of the full-resolution pixels (a decimated read would differ by the noise)
    view.set_zoom(0.5, QPointF(W / 2 + 100, H / 2 - 60))
    assert view.wait_idle(60.0) and view.level_for_zoom() == 1
    _level, tiles = view.visible_tiles()
    assert tiles and all(t.key in view._tiles for t in tiles)
    t = tiles[0]
    shown = _pixmap_rgb(view._tiles[t.key]).astype(float)
    ds = gdal.Open(str(image))
    full = ds.ReadAsArray(t.x0, t.y0, t.w, t.h).astype(float)  # (3, h, w), no overviews used
    mean = full.reshape(3, t.h // 2, 2, t.w // 2, 2).mean(axis=(2, 4))
    low, high = source.stretch_limits
    expect = np.clip((np.moveaxis(mean, 0, -1) - low) * 255.0 / (high - low), 0, 255)
    assert shown.shape == expect.shape
    # 1 grey level of rounding in GDAL's mean and 1 in our float32 stretch
    assert np.abs(shown - expect).max() <= 2.0
    noise_grey = NOISE_DN * 255.0 / float(np.min(high - low))
    assert noise_grey > 3.0  # so that a decimated (noisy) tile would fail the check above


def test_synchronous_build_blocks_the_gui_control(view, image):
    """The former behaviour (pyramid built in the caller's thread), measured the same way."""
    with Heartbeat() as beat:
        source = ImageSource(image, build_overviews=True)
        view.set_source(source)
        assert view.wait_idle(30.0)
    gap = beat.max_gap()
    print(f"\nsynchronous open: longest GUI block {gap:.3f} s")
    assert source.overview_count >= 4 and not view.building()
    assert gap > BLOCK_BOUND_S  # the heartbeat does see a blocked GUI
    assert not _temporaries(image.parent)


def _expected_scene(view: ImageView, p: QPoint) -> tuple[float, float]:
    """Scene point of the centre of a viewport pixel from the zoom and the scroll offsets
    (the view's transform is a pure scale, scrolled)."""
    z = view.transform().m11()
    assert view.transform().m12() == 0.0 and view.transform().m21() == 0.0
    hs, vs = view.horizontalScrollBar().value(), view.verticalScrollBar().value()
    return (p.x() + 0.5 + hs) / z, (p.y() + 0.5 + vs) / z


def test_click_after_zoom_maps_to_the_pixel(view, image):
    picks = []
    view.pointPicked.connect(lambda c, r: picks.append((c, r)))
    view.set_source(ImageSource(image), build_overviews=False)
    view.zoom_about(1.37, QPointF(412, 233))
    view.zoom_about(2.71, QPointF(97, 555))
    view.pan(-333, 121)
    p = QPoint(517, 389)
    QTest.mouseClick(view.viewport(), Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, p)
    assert len(picks) == 1
    col, row = _expected_scene(view, p)
    assert abs(picks[0][0] - col) < 1e-6 and abs(picks[0][1] - row) < 1e-6
    # the tiles arriving in the background move nothing: the same click gives the same pixel
    assert view.wait_idle(60.0, build=False)
    assert view.level_for_zoom() == 0 and view.tile_count() > 0
    QTest.mouseClick(view.viewport(), Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, p)
    assert picks[1] == picks[0]
    # and the pixel under the click is the one shown there: compare with a direct read
    x, y = math.floor(col), math.floor(row)
    key = (0, x // TILE, y // TILE)
    shown = _pixmap_rgb(view._tiles[key])[y % TILE, x % TILE]
    direct = view.source.read(x, y, 1, 1, 1, 1)[0, 0]
    assert np.array_equal(shown, direct)


@pytest.mark.parametrize("how", ["close", "other"])
def test_cancel_leaves_no_overview_file(view, image, tmp_path, how):
    small = tmp_path / "small.tif"
    ds = gdal.GetDriverByName("GTiff").Create(str(small), 600, 400, 1, gdal.GDT_Byte)
    ds.GetRasterBand(1).WriteArray(np.full((400, 600), 90, np.uint8))
    ds = None
    progress = []
    view.overviewProgress.connect(progress.append)
    view.set_source(ImageSource(image))
    assert _wait(lambda: progress and progress[-1] > 0.0, 30.0)  # the build is under way
    if how == "close":
        view.set_source(None)
    else:
        view.set_source(ImageSource(small))
    assert not view.building()
    assert _wait(lambda: not view.background_tasks(), 30.0)
    assert progress[-1] < 100.0
    assert not (image.parent / "frame.tif.ovr").exists()
    assert not _temporaries(image.parent), _temporaries(image.parent)
    if how == "other":
        assert view.wait_idle(10.0) and view.source.path == small
    # the image is intact: opened again, its pyramid builds to the end
    view.set_source(ImageSource(image))
    assert view.wait_idle(120.0)
    assert (image.parent / "frame.tif.ovr").is_file() and not _temporaries(image.parent)


def test_panning_on_drops_stale_tile_requests(view, image):
    view.set_source(ImageSource(image), build_overviews=False)
    assert view.wait_idle(30.0, build=False)
    view.set_zoom(1.0, QPointF(700, 500))
    for _ in range(10):  # 300 rows down at a time, faster than the strips can be decoded
        view.pan(0, -300)
        QApplication.processEvents()
    assert view.visible_rect().center().y() == pytest.approx(3500, abs=2)
    assert view.wait_idle(60.0, build=False)
    loader = view._loader
    print(f"\n{loader.tiles_requested} tiles requested, {loader.tiles_read} read")
    assert loader.tiles_read < loader.tiles_requested
    level, tiles = view.visible_tiles()
    assert level == 0 and tiles and all(t.key in view._tiles for t in tiles)


def test_unreadable_files_name_the_file(view, tmp_path, striped):
    broken = tmp_path / "broken frame.tif"
    broken.write_bytes(b"II*\x00" + bytes(range(256)) * 8)
    with pytest.raises(ImageSourceError, match=r"broken frame\.tif"):
        ImageSource(broken)
    missing = tmp_path / "missing.tif"
    with pytest.raises(ImageSourceError, match=r"missing\.tif.*does not exist"):
        ImageSource(missing)
    # truncated: GDAL opens the header, the strips past the end fail in the worker
    cut = tmp_path / "cut.tif"
    data = striped.read_bytes()
    cut.write_bytes(data[: len(data) // 3])
    failures = []
    view.loadFailed.connect(failures.append)
    view.set_source(ImageSource(cut), build_overviews=False)
    assert _wait(lambda: bool(failures), 30.0)
    assert "cut.tif" in failures[0] and "read failed" in failures[0]
    assert view.status_label.isVisible() and "cut.tif" in view.status_label.text()
