"""Every HTML report also as PDF in real QGIS: printed by QtWebKit beside the HTML after the
run, inline SVG plots included, in processing.run and in qgis_process (offscreen)."""

from __future__ import annotations

import json
import subprocess

import numpy as np
import processing
from osgeo import gdal
from qgis_helpers import CRS, QGIS_PROCESS
from test_accuracy_report_qgis import _write_csv

ALG = "lidarphoto:accuracyreport"


def _pages(pdf) -> int:
    ds = gdal.Open(str(pdf))
    sub = ds.GetMetadata("SUBDATASETS")
    return max(1, len(sub) // 2)


def test_the_report_is_printed_to_pdf_beside_the_html(provider, tmp_path):
    table = _write_csv(tmp_path / "cp.csv")
    html = tmp_path / "report.html"
    processing.run(ALG, {"INPUT": str(table), "CRS": CRS, "OUTPUT": "TEMPORARY_OUTPUT",
                         "OUTPUT_HTML": str(html)})  # fmt: skip
    pdf = tmp_path / "report.pdf"
    assert pdf.read_bytes()[:5] == b"%PDF-"
    assert not list(tmp_path.glob("*.part"))
    # seven SVG plots and ten tables do not fit one A4 page
    assert _pages(pdf) >= 2
    # the first page carries ink (text, tables): rasterised, it is not blank
    page = gdal.Open(f"PDF:1:{pdf}")
    ink = page.ReadAsArray().astype(float)
    assert ink.ndim == 3 and (ink[:3].mean(axis=0) < 128).mean() > 0.002


def test_qgis_process_prints_the_pdf_too(qp_env, tmp_path):
    table = _write_csv(tmp_path / "cp.csv")
    html = tmp_path / "r.html"
    r = subprocess.run(
        [QGIS_PROCESS, "--json", "run", ALG, "--", f"INPUT={table}", f"CRS={CRS}",
         f"OUTPUT={tmp_path / 'cp.gpkg'}", f"OUTPUT_HTML={html}"],
        env=qp_env, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    assert html.is_file() and np.isfinite(json.loads(r.stdout)["results"]["RMSE_3D"])
    pdf = tmp_path / "r.pdf"
    assert pdf.read_bytes()[:5] == b"%PDF-" and _pages(pdf) >= 2
    assert f"Report as PDF: {pdf}" in r.stdout + r.stderr
