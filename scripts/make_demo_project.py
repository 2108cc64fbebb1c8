"""Write the demo's QGIS project, demo_output/lidarphoto_demo.qgz, from the files of ``make demo``.

Runs with a Python that has QGIS (the Debian system Python or .venv-qgis), headless::

    QT_QPA_PLATFORM=offscreen /usr/bin/python3 scripts/make_demo_project.py [--demo demo_output]

The project holds, in EPSG:28992 (the tile's RD New, heights taken as ellipsoidal as in the
demo):

- demo_output/demo_layers.gpkg: the roof planes (PolygonZ outlines with a, b, c, d and the
  plane statistics), the LiDAR lines (LineStringZ), the LiDAR control points (PointZ), the
  image centres of the exterior orientation given to the dock (PointZ) and the check points
  (the simulation's truth);
- the DSM (lidar/dsm.tif, 0.5 m, hillshade);
- the orthomosaic of the images' true orthophotos (ortho/orthomosaic.tif, RGB as it is) and
  its seamlines (the region each image fills, outlines; in demo_layers.gpkg);
- the image point picking dock's session (plugin.observation_store.save_session): camera,
  exterior orientation (by default the INS one with the boresight not yet calibrated:
  flight/eo_initial.csv), the rendered images (flight/images/), the three layers, the
  calibration inputs (trajectory, lever arm, mount, plane/line/LCP tables), the monoplotting
  DSM, and a new observation file picking/observations.csv (by default the simulated
  measurements of tie, line and LCP points, so that a calibration can be run at once; with
  ``--observations empty`` a file with only the header).

Opening the project and the dock (menu LiDAR Photogrammetry > Image Point Picking) restores
all of it: docs/demo_project.md.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import sys
import tempfile
from pathlib import Path

import qgis.core as qgc

ROOT = Path(__file__).resolve().parents[1]
CRS = "EPSG:28992"
PROJECT_NAME = "lidarphoto_demo.qgz"
LAYERS_NAME = "demo_layers.gpkg"
OBSERVATION_HEADER = "image_id,point_id,col,row,sigma_px,type,target_id\n"


def _import_plugin():
    """``lidarphoto`` (the repository root): installed in .venv-qgis; for another Python, a
    temporary folder with a link named lidarphoto is put on the path (as QGIS would)."""
    try:
        import lidarphoto  # noqa: F401
    except ImportError:
        folder = Path(tempfile.mkdtemp(prefix="lidarphoto-"))
        (folder / "lidarphoto").symlink_to(ROOT, target_is_directory=True)
        sys.path.insert(0, str(folder))
    from lidarphoto.plugin.observation_store import save_session

    return save_session


def _rows(path: Path) -> list[dict[str, str]]:
    with open(path, newline="", encoding="utf-8-sig") as fh:
        return list(csv.DictReader(fh))


#: Memory-layer field types as declared: a bare "double" gets length 20 and precision 5 in
#: QGIS 3.22, which the GeoPackage writer then rounds every value to (0.12345678901234566 ->
#: 0.12346); "double(0,0)" leaves the precision unset: full doubles in the layer and the file.
_FIELD_TYPES = {"double": "double(0,0)"}


def _memory_layer(geometry: str, name: str, fields: list[tuple[str, str]]):

    spec = "&".join(f"field={n}:{_FIELD_TYPES.get(t, t)}" for n, t in fields)
    layer = qgc.QgsVectorLayer(f"{geometry}?crs={CRS}&{spec}", name, "memory")
    if not layer.isValid():
        raise RuntimeError(f"cannot make the memory layer {name}")
    return layer


def _fill(layer, rows: list[dict[str, str]], geometry_of) -> None:

    fields = layer.fields()
    feats = []
    for row in rows:
        f = qgc.QgsFeature(fields)
        f.setGeometry(geometry_of(row))
        values = []
        for field in fields:
            text = row.get(field.name(), "")
            if field.typeName().lower() in ("integer", "int"):
                values.append(int(float(text)) if text not in ("", None) else None)
            elif field.typeName().lower() in ("double", "real"):
                values.append(float(text) if text not in ("", None) else None)
            else:
                values.append(text)
        f.setAttributes(values)
        feats.append(f)
    ok, _ = layer.dataProvider().addFeatures(feats)
    if not ok:
        raise RuntimeError(f"cannot add features to {layer.name()}")
    layer.updateExtents()


def _point(x: str, y: str, z: str):

    return qgc.QgsGeometry(qgc.QgsPoint(float(x), float(y), float(z)))


def _line(row: dict[str, str]):

    a = qgc.QgsPoint(float(row["x1"]), float(row["y1"]), float(row["z1"]))
    b = qgc.QgsPoint(float(row["x2"]), float(row["y2"]), float(row["z2"]))
    return qgc.QgsGeometry(qgc.QgsLineString([a, b]))


def _write_gpkg(layers: list, path: Path) -> None:
    """Write memory layers as the tables of one GeoPackage (overwritten)."""

    if path.exists():
        path.unlink()
    for k, layer in enumerate(layers):
        options = qgc.QgsVectorFileWriter.SaveVectorOptions()
        options.driverName = "GPKG"
        options.layerName = layer.name()
        options.actionOnExistingFile = (
            qgc.QgsVectorFileWriter.ActionOnExistingFile.CreateOrOverwriteFile
            if k == 0
            else qgc.QgsVectorFileWriter.ActionOnExistingFile.CreateOrOverwriteLayer
        )
        ctx = qgc.QgsCoordinateTransformContext()
        if hasattr(qgc.QgsVectorFileWriter, "writeAsVectorFormatV3"):
            result = qgc.QgsVectorFileWriter.writeAsVectorFormatV3(layer, str(path), ctx, options)
        else:  # pragma: no cover - QGIS < 3.20
            result = qgc.QgsVectorFileWriter.writeAsVectorFormatV2(layer, str(path), ctx, options)
        if result[0] != qgc.QgsVectorFileWriter.WriterError.NoError:
            raise RuntimeError(f"writing {layer.name()} to {path}: {result[1]}")


def _style(layer, kind: str) -> None:

    if kind == "planes":
        sym = qgc.QgsFillSymbol.createSimple(
            {"color": "0,200,255,40", "outline_color": "0,200,255", "outline_width": "0.4"}
        )
    elif kind == "lines":
        sym = qgc.QgsLineSymbol.createSimple({"color": "255,90,200", "width": "0.6"})
    elif kind == "lcps":
        sym = qgc.QgsMarkerSymbol.createSimple(
            {"name": "square", "color": "255,60,60", "size": "2.4", "outline_color": "0,0,0"}
        )
    elif kind == "centres":
        sym = qgc.QgsMarkerSymbol.createSimple(
            {"name": "triangle", "color": "255,212,0", "size": "3", "outline_color": "0,0,0"}
        )
    elif kind == "seams":
        sym = qgc.QgsFillSymbol.createSimple(
            {"color": "0,0,0,0", "outline_color": "255,230,0", "outline_width": "0.5"}
        )
    else:
        sym = qgc.QgsMarkerSymbol.createSimple(
            {"name": "cross2", "color": "60,255,60", "size": "2.6", "outline_color": "60,255,60"}
        )
    layer.setRenderer(qgc.QgsSingleSymbolRenderer(sym))


def _inputs(demo: Path, eo: str) -> tuple[Path, list[Path]]:
    """The EO file given to the dock (``eo``: initial, calibrated or true) and the rendered
    images; FileNotFoundError naming what ``make demo`` did not write."""
    lidar, flight, cal = demo / "lidar", demo / "flight", demo / "calibration"
    eo_files = {
        "initial": cal / "eo_initial.csv",
        "calibrated": cal / "eo.csv",
        "true": flight / "eo_true.csv",
    }
    if eo not in eo_files:
        raise ValueError(f"eo must be one of {', '.join(eo_files)}")
    eo_csv = eo_files[eo]
    if not eo_csv.is_file():  # a demo run without the calibration step
        eo_csv = flight / "eo_true.csv" if eo == "calibrated" else eo_csv
    needed = [
        *(lidar / n for n in ("plane_outlines.csv", "lines.csv", "lcps.csv", "dsm.tif")),
        flight / "camera.json",
        flight / "trajectory.csv",
        eo_csv,
    ]
    missing = [str(p) for p in needed if not p.is_file()]
    if missing:
        raise FileNotFoundError("run `make demo` first; missing: " + ", ".join(missing))
    return eo_csv, sorted((flight / "images").glob("*.tif"))


def _vector_tables(demo: Path, eo_csv: Path) -> list:
    """The demo's vector layers as memory layers (planes, lines, LCPs, image centres, and
    the check points and seamlines where the demo has them)."""
    lidar, flight = demo / "lidar", demo / "flight"
    planes = _memory_layer("PolygonZ", "roof_planes", [
        ("id", "integer"), ("a", "double"), ("b", "double"), ("c", "double"), ("d", "double"),
        ("slope_deg", "double"), ("aspect_deg", "double"), ("n_points", "integer"),
        ("rms", "double"), ("sigma_d", "double"),
    ])  # fmt: skip

    _fill(planes, _rows(lidar / "plane_outlines.csv"), lambda r: qgc.QgsGeometry.fromWkt(r["wkt"]))
    lines = _memory_layer("LineStringZ", "lidar_lines", [
        ("id", "integer"), ("plane_1", "integer"), ("plane_2", "integer"), ("kind", "string"),
        ("length", "double"), ("sigma_perpendicular", "double"), ("dihedral_deg", "double"),
    ])  # fmt: skip
    _fill(lines, _rows(lidar / "lines.csv"), _line)
    lcps = _memory_layer("PointZ", "lidar_control_points", [
        ("id", "integer"), ("sigma_x", "double"), ("sigma_y", "double"), ("sigma_z", "double"),
        ("plane_1", "integer"), ("plane_2", "integer"), ("plane_3", "integer"),
    ])  # fmt: skip
    _fill(lcps, _rows(lidar / "lcps.csv"), lambda r: _point(r["X"], r["Y"], r["Z"]))
    centres = _memory_layer("PointZ", "image_centres", [
        ("image_id", "string"), ("group", "string"), ("omega_deg", "double"),
        ("phi_deg", "double"), ("kappa_deg", "double"),
    ])  # fmt: skip
    _fill(centres, _rows(eo_csv), lambda r: _point(r["X"], r["Y"], r["Z"]))
    tables = [planes, lines, lcps, centres]
    if (flight / "check_points.csv").is_file():
        checks = _memory_layer("PointZ", "check_points_truth", [("id", "string")])
        _fill(checks, _rows(flight / "check_points.csv"), lambda r: _point(r["e"], r["n"], r["h"]))
        tables.append(checks)
    ortho = demo / "ortho"
    if (ortho / "seamlines.csv").is_file():
        seams = _memory_layer("MultiPolygon", "seamlines", [
            ("image_id", "string"), ("cells", "integer"), ("area", "double"),
        ])  # fmt: skip
        _fill(seams, _rows(ortho / "seamlines.csv"), lambda r: qgc.QgsGeometry.fromWkt(r["wkt"]))
        tables.append(seams)
    return tables


def _add_layers(project, tables: list, gpkg: Path, demo: Path, eo_csv: Path) -> tuple[dict, object]:
    """The GeoPackage's tables (styled), the hillshaded DSM and the orthomosaic in the project;
    returns the vector layers by table name and the DSM layer."""
    lidar, ortho = demo / "lidar", demo / "ortho"
    titles = {
        "roof_planes": ("Roof planes", "planes"),
        "lidar_lines": ("LiDAR lines", "lines"),
        "lidar_control_points": ("LiDAR control points", "lcps"),
        "image_centres": (f"Image centres ({eo_csv.name})", "centres"),
        "check_points_truth": ("Check points (truth)", "checks"),
        "seamlines": ("Orthomosaic seamlines", "seams"),
    }
    layers = {}
    for table in tables:
        title, kind = titles[table.name()]
        layer = qgc.QgsVectorLayer(f"{gpkg}|layername={table.name()}", title, "ogr")
        if not layer.isValid():
            raise RuntimeError(f"cannot read {table.name()} back from {gpkg}")
        _style(layer, kind)
        layers[table.name()] = layer
    dsm = qgc.QgsRasterLayer(str(lidar / "dsm.tif"), "DSM 0.5 m (highest return)")
    if not dsm.isValid():
        raise RuntimeError(f"cannot read {lidar / 'dsm.tif'}")
    dsm.setRenderer(qgc.QgsHillshadeRenderer(dsm.dataProvider(), 1, 315.0, 45.0))
    project.addMapLayer(dsm)
    mosaic_tif = ortho / "orthomosaic.tif"
    if mosaic_tif.is_file():
        mosaic = qgc.QgsRasterLayer(str(mosaic_tif), "Orthomosaic (true orthophotos)")
        if not mosaic.isValid():
            raise RuntimeError(f"cannot read {mosaic_tif}")
        # 8-bit RGB as it is (QGIS would stretch each band), the mask as transparency
        rgb = qgc.QgsMultiBandColorRenderer(mosaic.dataProvider(), 1, 2, 3)
        rgb.setAlphaBand(mosaic.renderer().alphaBand())
        mosaic.setRenderer(rgb)
        project.addMapLayer(mosaic)
    for name in ("seamlines", "check_points_truth", "image_centres", "roof_planes",
                 "lidar_lines", "lidar_control_points"):  # fmt: skip
        if name in layers:
            project.addMapLayer(layers[name])
    extent = dsm.extent()
    extent.grow(10.0)
    project.viewSettings().setDefaultViewExtent(
        qgc.QgsReferencedRectangle(extent, qgc.QgsCoordinateReferenceSystem(CRS))
    )
    return layers, dsm


def _observation_file(demo: Path, observations: str) -> Path:
    """The dock's new observation file: the simulated tie, line and LCP measurements, or
    only the header (``observations``: simulated or empty)."""
    flight, picking = demo / "flight", demo / "picking"
    picking.mkdir(exist_ok=True)
    obs_csv = picking / "observations.csv"
    if observations == "simulated":
        rows = _rows(flight / "observations.csv")
        keep = [r for r in rows if r["type"] in ("tie", "line", "lcp")]
        with open(obs_csv, "w", newline="", encoding="utf-8") as fh:
            writer = csv.DictWriter(fh, OBSERVATION_HEADER.strip().split(","))
            writer.writeheader()
            writer.writerows(keep)
    elif observations == "empty":
        obs_csv.write_text(OBSERVATION_HEADER, encoding="utf-8")
    else:
        raise ValueError("observations must be 'simulated' or 'empty'")
    return obs_csv


def _session(demo: Path, eo_csv: Path, obs_csv: Path, images: list[Path], layers: dict,
             dsm) -> dict:
    """The picking dock's session (plugin.observation_store.save_session)."""
    lidar, flight = demo / "lidar", demo / "flight"
    truth = json.loads((flight / "truth.json").read_text(encoding="utf-8"))
    session = {
        "camera": str(flight / "camera.json"),
        "eo": str(eo_csv),
        "observations": str(obs_csv),
        "planes_layer": layers["roof_planes"].id(),
        "lines_layer": layers["lidar_lines"].id(),
        "lcps_layer": layers["lidar_control_points"].id(),
        "trajectory": str(flight / "trajectory.csv"),
        "planes_csv": str(lidar / "planes.csv"),
        "lines_csv": str(lidar / "lines.csv"),
        "lcps_csv": str(lidar / "lcps.csv"),
        "lever_arm": ",".join(repr(float(v)) for v in truth["lever_arm_m"]),
        "mount": truth["mount"],
        "boresight": ",".join(repr(float(v)) for v in truth["initial_boresight_deg"]),
        "current_image": images[0].stem if images else "",
        "images": [str(p) for p in images],
        "crs": CRS,
        "dsm_layer": dsm.id(),
        "dsm_file": "",
        "dsm_cell": "0.5",
    }
    return session


def build_project(
    demo: Path,
    output: Path | None = None,
    *,
    observations: str = "simulated",
    eo: str = "initial",
) -> Path:
    """Write ``demo/demo_layers.gpkg``, ``demo/picking/observations.csv`` and the project;
    returns the project's path. Needs a running QgsApplication."""

    save_session = _import_plugin()
    demo = Path(demo).resolve()
    output = Path(output) if output else demo / PROJECT_NAME
    eo_csv, images = _inputs(demo, eo)
    tables = _vector_tables(demo, eo_csv)
    gpkg = demo / LAYERS_NAME
    _write_gpkg(tables, gpkg)
    project = qgc.QgsProject()
    project.setCrs(qgc.QgsCoordinateReferenceSystem(CRS))
    project.setTitle("LiDAR Photogrammetry Toolkit: demo (AHN3 Delft, simulated flight)")
    layers, dsm = _add_layers(project, tables, gpkg, demo, eo_csv)
    obs_csv = _observation_file(demo, observations)
    session = _session(demo, eo_csv, obs_csv, images, layers, dsm)
    save_session(project, session)
    project.writeEntry("lidarphoto_picking", "crs", CRS)
    output.parent.mkdir(parents=True, exist_ok=True)
    tmp = output.with_name(output.stem + ".tmp" + output.suffix)
    if not project.write(str(tmp)):
        raise RuntimeError(f"cannot write {tmp}: {project.error()}")
    os.replace(tmp, output)
    return output


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--demo", type=Path, default=ROOT / "demo_output",
                        help="folder written by `make demo` (default: demo_output)")  # fmt: skip
    parser.add_argument("--output", type=Path, default=None,
                        help=f"project file (default: <demo>/{PROJECT_NAME})")  # fmt: skip
    parser.add_argument("--observations", choices=("simulated", "empty"), default="simulated",
                        help="start the observation file with the simulated measurements "
                        "(tie, line, LCP) or empty")  # fmt: skip
    parser.add_argument("--eo", choices=("initial", "calibrated", "true"), default="initial",
                        help="exterior orientation given to the dock: from the INS with the "
                        "boresight not calibrated (default), after the demo's calibration, "
                        "or the simulation's truth")  # fmt: skip
    args = parser.parse_args(argv)
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

    qgc.QgsApplication.setPrefixPath(os.environ.get("QGIS_PREFIX_PATH", "/usr"), True)
    app = qgc.QgsApplication([], False)
    app.initQgis()
    try:
        path = build_project(args.demo, args.output, observations=args.observations, eo=args.eo)
        print(f"wrote {path} (layers in {args.demo.resolve() / LAYERS_NAME})")
    finally:
        app.exitQgis()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
