"""Benchmark: how long the picking dock blocks QGIS when it opens and at each click.

    QT_QPA_PLATFORM=offscreen .venv-qgis/bin/python bench/bench_dock_latency.py
        [--in-image 1000] [--other 2000] [--clicks 40] [--data DIR] [--json FILE]

The project (made into DIR, default a temporary folder): a simulated calibration flight
(``core.simulation.flight``: 23 buildings, 76 roof planes, 2 lines of 5 images of a
6000 x 4000 px camera) with its camera and exterior orientation; one 6000 x 4000 8-bit RGB
striped GeoTIFF with its .ovr (as the dock leaves an image after its first opening), linked
under every image id; the roof planes, LiDAR lines and LiDAR control points in a GeoPackage
loaded as QGIS layers; an observation file with ``--in-image`` tie points in the image the
dock shows and ``--other`` in the other images; the dock's session stored in a QGIS project
file, as the dock stores it. Opening the dock restores all of it: reads the camera, the EO,
the three layers and the observations, shows the image with every overlay.

What is timed (the user's wait: the GUI thread is busy, QGIS does not respond):

* **opening** (``ImagePickingDock(...)`` as the menu action makes it, ``show()``, then the
  events until everything is drawn), three ways: in a fresh process that has read the project
  and loaded the plugin's Processing provider, as QGIS at its start, with the dock's modules
  imported by the opening itself, or already imported (what the plugin does once QGIS is
  idle); and a second opening in the benchmark's process. Times from the constructor's call:
  its return, the first paint of the image view, the first paint that shows the image and the
  control, the first that shows the observation markers. *Longest GUI block*: the longest
  interval between two ticks of a 5 ms QTimer in the GUI thread from the constructor's call
  until every tile is in (the tiles are read in a worker thread).
* **clicks**: a real left click (``QTest.mouseClick`` on the view's viewport) near a roof
  plane's centre at 100 % zoom, type *tie* (the plane under the cursor, its selection on the
  map, the prediction in the other images, the autosave of the whole table, the redraw), then
  the events until the view has repainted; *LCP* clicks 1 px off the control points (whole
  image in view); Ctrl+Z and Ctrl+Shift+Z. Median, 90th percentile and maximum of
  ``--clicks`` each, with the time Python's full garbage collections took within the slowest.

The machine is shared: the load average is recorded with each run. Prints a JSON line and
Markdown tables; bench/dock_latency.md has the figures.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

CRS = "EPSG:28992"
TARGET_CLICK_S = 0.020
TARGET_OPEN_S = 0.2


# ------------------------------------------------------------------------------ project
def make_project(folder: Path, n_in_image: int, n_other: int, seed: int = 3) -> dict:
    """The files of the benchmark project; returns their paths and the shown image id."""
    from lidarphoto.core.geometry.frames import MappingFrame
    from lidarphoto.core.io.orientation import write_eo_csv
    from lidarphoto.core.photo.georeference import direct_georeference
    from lidarphoto.core.photo.mount import Mount
    from lidarphoto.core.photo.picking import PickingScene
    from lidarphoto.core.simulation.flight import FlightConfig, simulate_flight
    from lidarphoto.core.simulation.flight_over import small_format_camera
    from osgeo import gdal

    gdal.UseExceptions()
    folder.mkdir(parents=True, exist_ok=True)
    camera = small_format_camera()  # 6000 x 4000 px, as in the demo
    config = FlightConfig(
        camera=camera, plane_source="exact", n_check=0, images_per_line=5, n_lines=2
    )
    sim = simulate_flight(config, seed=seed, exact=True)
    paths = sim.write(folder / "flight")
    group = sim.truth.groups[0]
    mount = Mount(sim.truth.lever_arm, sim.mount.nominal, sim.truth.boresight[group])
    eo = direct_georeference(sim.truth.trajectory, mount, MappingFrame.from_user_input(CRS))
    write_eo_csv(folder / "eo.csv", eo)
    faces = {f.face_id: f for f in sim.town.faces}
    outlines = [faces[int(p.id)].polygon for p in sim.planes]
    scene = PickingScene(eo, camera, CRS)
    # the image the dock shows: the one that sees the most roof planes whole
    counts = [
        sum(
            bool(np.isfinite(r).all() and camera.in_frame(r, 50).all())
            for r in scene.project_rings(i, outlines)
        )
        for i in eo.image_id
    ]
    shown = eo.image_id[int(np.argmax(counts))]
    # one image file, linked under every id (the dock opens one image at a time)
    image = folder / "images" / "frame.tif"
    image.parent.mkdir(exist_ok=True)
    if not image.exists():
        # 8-bit RGB, striped, as the demo's rendered frames; its .ovr built (as the dock
        # leaves it after the first opening)
        rng = np.random.default_rng(seed)
        w, h = camera.width_px, camera.height_px
        ds = gdal.GetDriverByName("GTiff").Create(str(image), w, h, 3, gdal.GDT_Byte)
        for r0 in range(0, h, 500):
            a = rng.normal(120, 30, (3, min(500, h - r0), w)).clip(0, 255).astype(np.uint8)
            ds.WriteRaster(0, r0, w, a.shape[1], a.tobytes())
        ds = None
        ds = gdal.Open(str(image))
        ds.BuildOverviews("AVERAGE", [2, 4, 8, 16])
        ds = None
    images = []
    for image_id in eo.image_id:
        link = folder / "images" / f"{image_id}.tif"
        if not link.exists():
            link.symlink_to(image.name)
        images.append(link)
    files = {
        "sim": sim,
        "camera": paths["camera"],
        "eo": folder / "eo.csv",
        "images": images,
        "shown": shown,
        "outlines": outlines,
        "observations": folder / "observations.csv",
        "folder": folder,
        "n_in_image": n_in_image,
        "n_other": n_other,
        "seed": seed,
    }
    write_observations(files)
    return files


def write_observations(files: dict) -> None:
    """Random tie points on the planes: ``n_in_image`` in the shown image, ``n_other`` in the
    others (made again before each measurement: the docks save what they measure)."""
    from lidarphoto.core.io.observations import write_observations_csv
    from lidarphoto.core.photo.observations import ImageObservations

    sim, camera, shown = files["sim"], files["sim"].camera, files["shown"]
    n_in_image = files["n_in_image"]
    rng = np.random.default_rng(files["seed"] + 1)
    ids, pts, pix, types, targets = [], [], [], [], []
    all_ids = [p.stem for p in files["images"]]
    others = [i for i in all_ids if i != shown]
    for k in range(n_in_image + files["n_other"]):
        img = shown if k < n_in_image else others[k % len(others)]
        ids.append(img)
        pts.append(f"B{k + 1}")
        pix.append(rng.uniform([10, 10], [camera.width_px - 10, camera.height_px - 10]))
        types.append("tie")
        targets.append(str(sim.planes[k % len(sim.planes)].id))
    obs = ImageObservations.from_arrays(
        ids, pts, np.array(pix), np.full(len(ids), 0.5), types, targets
    )
    write_observations_csv(files["observations"], obs)


def make_layers(project_files: dict):
    """The control as GeoPackage layers in the current QgsProject: (planes, lines, lcps)."""
    import qgis.core as qgc  # noqa: TID251 - a QGIS benchmark

    sim, folder = project_files["sim"], project_files["folder"]
    gpkg = folder / "control.gpkg"
    specs = {
        "planes": ("PolygonZ", [(p.id, o) for p, o in zip(sim.planes, project_files["outlines"])]),
        "lines": ("LineStringZ", [(ln.id, np.array([ln.start, ln.end])) for ln in sim.lines]),
        "lcps": ("PointZ", [(c.id, c.xyz[None]) for c in sim.lcps]),
    }
    layers = []
    for name, (geometry, rows) in specs.items():
        mem = qgc.QgsVectorLayer(f"{geometry}?crs={CRS}&field=id:integer", name, "memory")
        feats = []
        for fid, xyz in rows:
            pts = [qgc.QgsPoint(*map(float, p)) for p in xyz]
            if geometry == "PolygonZ":
                g = qgc.QgsGeometry(qgc.QgsPolygon(qgc.QgsLineString([*pts, pts[0]])))
            elif geometry == "LineStringZ":
                g = qgc.QgsGeometry(qgc.QgsLineString(pts))
            else:
                g = qgc.QgsGeometry(pts[0])
            f = qgc.QgsFeature(mem.fields())
            f.setGeometry(g)
            f.setAttributes([int(fid)])
            feats.append(f)
        mem.dataProvider().addFeatures(feats)
        options = qgc.QgsVectorFileWriter.SaveVectorOptions()
        options.driverName = "GPKG"
        options.layerName = name
        options.actionOnExistingFile = (
            qgc.QgsVectorFileWriter.ActionOnExistingFile.CreateOrOverwriteLayer
            if gpkg.exists()
            else qgc.QgsVectorFileWriter.ActionOnExistingFile.CreateOrOverwriteFile
        )
        err = qgc.QgsVectorFileWriter.writeAsVectorFormatV3(
            mem, str(gpkg), qgc.QgsCoordinateTransformContext(), options
        )
        if err[0] != qgc.QgsVectorFileWriter.WriterError.NoError:
            raise RuntimeError(f"cannot write {name}: {err}")
        layer = qgc.QgsVectorLayer(f"{gpkg}|layername={name}", name, "ogr")
        assert layer.isValid(), name
        layers.append(layer)
    qgc.QgsProject.instance().addMapLayers(layers)
    return layers


def store_session(project_files: dict, layers) -> None:
    """The dock's session in the QGIS project, as the dock stores it."""
    from lidarphoto.plugin.observation_store import SESSION_SCOPE, save_session
    from qgis.core import QgsProject  # noqa: TID251 - a QGIS benchmark

    project = QgsProject.instance()
    planes, lines, lcps = layers
    save_session(
        project,
        {
            "camera": str(project_files["camera"]),
            "eo": str(project_files["eo"]),
            "observations": str(project_files["observations"]),
            "images": [str(p) for p in project_files["images"]],
            "planes_layer": planes.id(),
            "lines_layer": lines.id(),
            "lcps_layer": lcps.id(),
            "current_image": project_files["shown"],
        },
    )
    project.writeEntry(SESSION_SCOPE, "crs", CRS)


# ------------------------------------------------------------------------------ measuring
class Heartbeat:
    """Ticks of a 5 ms QTimer in the GUI thread; ``max_gap()`` is the longest block, s."""

    def __init__(self) -> None:
        from qgis.PyQt.QtCore import QTimer  # noqa: TID251 - a QGIS benchmark

        self.ticks: list[float] = []
        self.timer = QTimer()
        self.timer.setInterval(5)
        self.timer.timeout.connect(lambda: self.ticks.append(time.perf_counter()))

    def start(self) -> None:
        from qgis.PyQt.QtWidgets import QApplication  # noqa: TID251 - a QGIS benchmark

        self.ticks.clear()
        self.timer.start()
        t_end = time.perf_counter() + 1.0
        while len(self.ticks) < 2 and time.perf_counter() < t_end:
            QApplication.processEvents()
            time.sleep(0.001)

    def stop(self) -> float:
        self.timer.stop()
        return float(np.diff(self.ticks).max()) if len(self.ticks) > 1 else float("nan")


class PaintCounter:
    """Counts the paint events of a widget (to know the repaint after a click is done), and
    records when a paint first shows a state: ``watch(name, predicate)`` -> ``seen[name]``,
    the time of the first paint at which the predicate held."""

    def __init__(self, widget) -> None:
        from qgis.PyQt.QtCore import QEvent, QObject  # noqa: TID251 - a QGIS benchmark

        counter = self

        class _Filter(QObject):
            def eventFilter(self, obj, event):  # Qt override
                if event.type() == QEvent.Type.Paint:
                    counter.count += 1
                    now = time.perf_counter()
                    for name, pred in list(counter._watch.items()):
                        if pred():
                            counter.seen[name] = now
                            del counter._watch[name]
                return False

        self.count = 0
        self.seen: dict[str, float] = {}
        self._watch: dict = {}
        self._filter = _Filter()
        widget.installEventFilter(self._filter)

    def watch(self, name: str, predicate) -> None:
        self._watch[name] = predicate


def open_dock(app, parent, n_markers: int):
    """Open the dock as the menu action does (the plugin imports the dock's module at the
    first opening): its session is restored from the project. Times: the constructor; the
    first paint of the image view (the dock on screen); the paint with the ``n_markers``
    observation markers of the image on it; the longest GUI block until all the tiles are in.
    """
    from qgis.PyQt.QtTest import QTest  # noqa: TID251 - a QGIS benchmark

    hb = Heartbeat()
    gcw = GcWatch()
    hb.start()
    t0 = time.perf_counter()
    from lidarphoto.plugin.image_dock import ImagePickingDock

    dock = ImagePickingDock(None, parent)
    dock.choose_candidate = lambda cands, labels: cands[0]
    t_construct = time.perf_counter() - t0
    overlays = dock.viewer.overlays
    paints = PaintCounter(dock.view.viewport())
    paints.watch("any", lambda: True)
    paints.watch("image", lambda: dock.source is not None and overlays.counts["planes"] > 0)
    paints.watch("markers", lambda: overlays.counts["observations"] >= n_markers)
    dock.resize(1000, 950)
    dock.show()
    QTest.qWaitForWindowExposed(dock, 5000)
    t_end = time.perf_counter() + 30.0
    while len(paints.seen) < 3 and time.perf_counter() < t_end:
        app.processEvents()
    assert overlays.counts["observations"] == n_markers, overlays.counts
    dock.view.wait_idle(30.0)
    block = hb.stop()
    return dock, {
        "construct_s": t_construct,
        "first_paint_s": paints.seen["any"] - t0,
        "image_painted_s": paints.seen["image"] - t0,
        "markers_painted_s": paints.seen["markers"] - t0,
        "gui_block_s": block,
        "full_gc_ms": 1000.0 * gcw.mark(),
    }


class GcWatch:
    """Time spent in Python's full (generation 2) garbage collections since :meth:`mark`."""

    def __init__(self) -> None:
        import gc

        self._t0 = 0.0
        self.full_s = 0.0
        gc.callbacks.append(self._callback)

    def _callback(self, phase, info) -> None:
        if info.get("generation") != 2:
            return
        if phase == "start":
            self._t0 = time.perf_counter()
        else:
            self.full_s += time.perf_counter() - self._t0

    def mark(self) -> float:
        return self.full_s


def _stats(values: list[tuple[float, float]]) -> dict:
    """(duration, full GC time within it) pairs -> median, p90, max (and the GC in the max)."""
    a = np.array([v[0] for v in values])
    k = int(np.argmax(a))
    return {
        "n": int(a.size),
        "median_s": float(np.median(a)),
        "p90_s": float(np.percentile(a, 90)),
        "max_s": float(a[k]),
        "gc_in_max_ms": 1000.0 * values[k][1],
        "full_gc_events": int(sum(v[1] > 0 for v in values)),
    }


def click_latencies(app, dock, files: dict, n_clicks: int) -> dict:
    """Tie clicks on planes, LCP clicks, undo and redo, each timed to the end of the repaint."""
    from qgis.PyQt.QtCore import QPointF, Qt  # noqa: TID251 - a QGIS benchmark
    from qgis.PyQt.QtTest import QTest  # noqa: TID251 - a QGIS benchmark

    view = dock.view
    shown = files["shown"]
    assert dock.current_image == shown, dock.current_image
    proj = dock.picking.projected
    cam = dock.camera
    rings = [
        r for r in proj.rings if len(r) >= 3 and np.isfinite(r).all() and cam.in_frame(r, 50).all()
    ]
    rng = np.random.default_rng(7)
    paints = PaintCounter(view.viewport())
    gcw = GcWatch()
    out: dict = {}

    def timed(action) -> tuple[float, float]:
        """Run ``action`` (a click or a key) and the events it posts, until the view has
        repainted: (seconds, seconds of full GC within)."""
        n_paint, g0 = paints.count, gcw.mark()
        t0 = time.perf_counter()
        action()
        app.processEvents()
        t_end = t0 + 1.0
        while paints.count == n_paint and time.perf_counter() < t_end:
            app.processEvents()  # (the repaint not done yet)
        return time.perf_counter() - t0, gcw.mark() - g0

    def click(pixel):
        p = view.mapFromScene(QPointF(float(pixel[0]), float(pixel[1])))
        return lambda: QTest.mouseClick(
            view.viewport(), Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, p
        )

    # tie clicks: near a roof plane's centre, 100 % zoom centred there
    dock.viewer.type_combo.setCurrentText("tie")
    n0 = len(dock.store.rows)
    times = []
    for i in range(n_clicks):
        centre = rings[i % len(rings)].mean(axis=0) + rng.uniform(-2, 2, 2)
        view.set_zoom(1.0, QPointF(*centre))
        view.wait_idle(30.0, build=False)
        dock.cancel_prediction()
        app.processEvents()
        times.append(timed(click(centre)))
    out["tie"] = _stats(times)
    out["tie_added"] = len(dock.store.rows) - n0
    # LCP clicks: 1 px off a projected control point, the whole image in view
    dock.viewer.type_combo.setCurrentText("lcp")
    lcps = [p for p in proj.lcps if np.isfinite(p).all() and cam.in_frame(p[None], 50)[0]]
    view.fit()
    view.wait_idle(30.0, build=False)
    n0 = len(dock.store.rows)
    times = [timed(click(lcps[i % len(lcps)] + [0.7, -0.4])) for i in range(n_clicks)]
    out["lcp"] = _stats(times)
    out["lcp_added"] = len(dock.store.rows) - n0
    # undo, redo (the keys)
    view.setFocus()
    ctrl, shift = Qt.KeyboardModifier.ControlModifier, Qt.KeyboardModifier.ShiftModifier
    undo = [timed(lambda: QTest.keyClick(view, Qt.Key.Key_Z, ctrl)) for _ in range(n_clicks)]
    redo = [
        timed(lambda: QTest.keyClick(view, Qt.Key.Key_Z, ctrl | shift)) for _ in range(n_clicks)
    ]
    out["undo"], out["redo"] = _stats(undo), _stats(redo)
    out["observations_in_image_after"] = len(dock.store.indices_of_image(shown))
    return out


def markdown(r: dict) -> str:
    """The result as the rows of bench/dock_latency.md."""
    ms = 1000.0
    lines = [
        f"{r['label'] or 'run'}: {r['observations_in_image']} observations in the "
        f"image shown, {r['observations_total']} in the file, {r['images']} images, "
        f"{r['planes']} roof planes; load average {r['load_average_1min']:.1f} on "
        f"{os.cpu_count()} cores",
        "",
        "| what | n | median ms | p90 ms | max ms | full GC in max ms |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    names = {"tie": "tie click", "lcp": "LCP click", "undo": "Ctrl+Z", "redo": "Ctrl+Shift+Z"}
    for key, name in names.items():
        s = r[key]
        lines.append(
            f"| {name} | {s['n']} | {s['median_s'] * ms:.1f} | {s['p90_s'] * ms:.1f} | "
            f"{s['max_s'] * ms:.1f} | {s['gc_in_max_ms']:.0f} |"
        )
    lines += [
        "",
        "| opening | constructor ms | first paint ms | image and control on screen ms | "
        "markers on screen ms | longest GUI block ms | full GC within ms |",
        "| --- | --- | --- | --- | --- | --- | --- |",
    ]
    opens = {
        "open_first_with_import": "first, dock modules imported by it",
        "open_first_preloaded": "first, modules preloaded by the plugin",
        "open_again": "second opening in the session",
    }
    for key, name in opens.items():
        o = r[key]
        lines.append(
            f"| {name} | {o['construct_s'] * ms:.0f} | {o['first_paint_s'] * ms:.0f} | "
            f"{o['image_painted_s'] * ms:.0f} | {o['markers_painted_s'] * ms:.0f} | "
            f"{o['gui_block_s'] * ms:.0f} | {o['full_gc_ms']:.0f} |"
        )
    lines += [
        "",
        f"Peak RSS: {r['peak_rss_mb']:.0f} MB (benchmark process: QGIS, the project, two "
        f"openings, {2 * r['tie']['n']} clicks); the first opening's process "
        f"{r['open_first_with_import']['peak_rss_mb']:.0f} MB.",
    ]
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--in-image", type=int, default=1000)
    ap.add_argument("--other", type=int, default=2000)
    ap.add_argument("--clicks", type=int, default=40)
    ap.add_argument("--data", type=Path, default=None)
    ap.add_argument("--json", type=Path, default=None)
    ap.add_argument("--label", default="")
    ap.add_argument("--child-open", choices=("import", "preloaded"), help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

    from qgis.core import Qgis, QgsApplication, QgsProject  # noqa: TID251 - a QGIS benchmark
    from qgis.PyQt.QtCore import QT_VERSION_STR  # noqa: TID251 - a QGIS benchmark
    from qgis.PyQt.QtWidgets import QWidget  # noqa: TID251 - a QGIS benchmark

    folder = args.data or Path(tempfile.mkdtemp(prefix="lidarphoto_bench_dock_"))
    qgz = folder / "bench.qgz"
    app = QgsApplication([], True)
    app.initQgis()
    parent = QWidget()
    parent.resize(1100, 1000)
    parent.show()  # a dock in a hidden window is never painted
    if args.child_open:  # a fresh process: read the project, open the dock (imports included)
        # QGIS has loaded the plugin at its start: its menu and its Processing provider
        if "/usr/share/qgis/python/plugins" not in sys.path:
            sys.path.append("/usr/share/qgis/python/plugins")
        import lidarphoto

        lidarphoto.classFactory(None).initProcessing()
        if args.child_open == "preloaded":  # what the plugin does once QGIS is idle
            import lidarphoto.plugin.image_dock
        assert QgsProject.instance().read(str(qgz))
        dock, first = open_dock(app, parent, args.in_image)
        assert dock.source is not None and dock.view.wait_idle(30.0)
        first["observations_in_image"] = len(dock.store.indices_of_image(dock.current_image))
        first["peak_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
        print(json.dumps(first))
        sys.stdout.flush()
        os._exit(0)
    t0 = time.perf_counter()
    files = make_project(folder, args.in_image, args.other)
    layers = make_layers(files)
    store_session(files, layers)
    assert QgsProject.instance().write(str(qgz))
    make_s = time.perf_counter() - t0
    cold = {}
    for mode in ("import", "preloaded"):
        cmd = [sys.executable, __file__, "--child-open", mode, "--data", str(folder)]
        cmd += ["--in-image", str(args.in_image), "--other", str(args.other)]
        done = subprocess.run(cmd, capture_output=True, text=True, check=True)
        cold[mode] = json.loads(done.stdout.strip().splitlines()[-1])
        assert cold[mode]["observations_in_image"] == args.in_image, cold
        write_observations(files)  # (the child's dock may have saved it)
    dock, first = open_dock(app, parent, args.in_image)
    assert dock.source is not None and dock.current_image == files["shown"]
    n_obs = len(dock.store.indices_of_image(files["shown"]))
    dock.close()
    dock.deleteLater()
    app.processEvents()
    store_session(files, layers)  # the first dock saved its own (the same) session
    dock, warm = open_dock(app, parent, args.in_image)
    clicks = click_latencies(app, dock, files, args.clicks)
    dock.close()

    import lidarphoto

    result = {
        "label": args.label,
        "date": time.strftime("%Y-%m-%d"),
        "machine": f"{platform.machine()}, {os.cpu_count()} cores",
        "python": platform.python_version(),
        "qgis": Qgis.QGIS_VERSION,
        "qt": QT_VERSION_STR,
        "code": str(Path(lidarphoto.__file__).resolve().parent),
        "project_s": round(make_s, 2),
        "images": len(files["images"]),
        "planes": len(files["sim"].planes),
        "observations_total": args.in_image + args.other,
        "observations_in_image": n_obs,
        "open_first_with_import": cold["import"],
        "open_first_preloaded": cold["preloaded"],
        "open_again": warm,
        **clicks,
        "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
        "load_average_1min": os.getloadavg()[0],  # the machine is shared: how busy it was
    }
    line = json.dumps(result)
    print(line)
    if args.json:
        with open(args.json, "a", encoding="utf-8") as fh:
            fh.write(line + "\n")
    print()
    print(markdown(result))
    sys.stdout.flush()
    os._exit(0)  # (tearing QGIS down from a script may crash after the results are out)


if __name__ == "__main__":
    sys.exit(main())
