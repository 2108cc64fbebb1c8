"""Full precision in the layers the scripts create (issue 37): the demo's roof-plane layer
(scripts/make_demo_project.py) carries a, b, c, d from the planes table into its GeoPackage
bit for bit. A memory field declared as a bare ``double`` got QGIS's precision 5, and the
GeoPackage writer rounded every value to it (0.12345678901234566 -> 0.12346)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np
from qgis.core import QgsVectorLayer

ROOT = Path(__file__).resolve().parents[2]


def _make_demo_project():
    spec = importlib.util.spec_from_file_location(
        "lidarphoto_make_demo_project", ROOT / "scripts" / "make_demo_project.py"
    )
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def test_demo_plane_layer_round_trips_its_coefficients(qgis_app, tmp_path):
    make = _make_demo_project()
    rng = np.random.default_rng(5)
    normals = rng.normal(size=(6, 3))
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    d = rng.uniform(-5e6, 5e6, 6)  # RD / UTM-sized offsets: every digit of the double used
    rows = [
        {"id": str(k), "a": repr(float(n[0])), "b": repr(float(n[1])), "c": repr(float(n[2])),
         "d": repr(float(dk)), "slope_deg": repr(float(rng.uniform(0, 60))),
         "aspect_deg": repr(float(rng.uniform(0, 360))), "n_points": "40",
         "rms": repr(float(rng.uniform(0.01, 0.05))),
         "sigma_d": repr(float(rng.uniform(1e-6, 1e-3))),
         "wkt": "POLYGON Z ((0 0 1, 1 0 1, 1 1 2, 0 0 1))"}
        for k, (n, dk) in enumerate(zip(normals, d))
    ]  # fmt: skip
    fields = [("id", "integer"), ("a", "double"), ("b", "double"), ("c", "double"),
              ("d", "double"), ("slope_deg", "double"), ("aspect_deg", "double"),
              ("n_points", "integer"), ("rms", "double"), ("sigma_d", "double")]  # fmt: skip
    layer = make._memory_layer("PolygonZ", "roof_planes", fields)
    assert all(f.precision() == 0 for f in layer.fields() if f.typeName() == "double")
    make._fill(layer, rows, lambda r: make.qgc.QgsGeometry.fromWkt(r["wkt"]))
    gpkg = tmp_path / "layers.gpkg"
    make._write_gpkg([layer], gpkg)
    back = QgsVectorLayer(f"{gpkg}|layername=roof_planes", "back", "ogr")
    assert back.isValid() and back.featureCount() == len(rows)
    names = ("a", "b", "c", "d", "slope_deg", "aspect_deg", "rms", "sigma_d")
    got = {int(f["id"]): [f[n] for n in names] for f in back.getFeatures()}
    for k, row in enumerate(rows):
        assert got[k] == [float(row[n]) for n in names], k
