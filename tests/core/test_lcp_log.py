"""``createlcps``'s log: rejected candidates counted per reason (numbers with units); each
candidate only in verbose mode (``lidarphoto -vv``; debug records, which QGIS forwards as
debug information when the processing log level is Verbose)."""

from __future__ import annotations

import logging

import laspy
import numpy as np
import pyproj
import pytest
from lidarphoto.core.cli import main
from lidarphoto.core.geometry.planes import Plane
from lidarphoto.core.io.planes import write_planes_csv
from lidarphoto.core.lidar.control import (
    REJECT_DUPLICATE,
    REJECT_SUPPORT,
    Rejection,
    rejection_summary,
)
from test_lidar_control import _hip_roof_cloud

E0, N0 = 500000.0, 7450000.0  # a UTM 23S position (EPSG:31983, metres)


@pytest.fixture(scope="module")
def hip_roof_files(tmp_path_factory):
    """The exact hip roof of test_lidar_control as a LAS with plane_id and its plane table:
    two corners, and two triples meeting far from their points (rejected)."""
    pts, lab, faces, _, _ = _hip_roof_cloud()
    shift = np.array([E0, N0, 0.0])
    xyz = pts + shift
    folder = tmp_path_factory.mktemp("hip")
    header = laspy.LasHeader(point_format=6, version="1.4")
    header.offsets, header.scales = np.floor(xyz.min(axis=0)), np.array([1e-4] * 3)
    header.add_crs(pyproj.CRS("EPSG:31983"))
    header.add_extra_dim(laspy.ExtraBytesParams(name="plane_id", type=np.int32))
    las = laspy.LasData(header)
    las.x, las.y, las.z = xyz[:, 0], xyz[:, 1], xyz[:, 2]
    las.plane_id = lab.astype(np.int32)
    las.write(str(folder / "cloud.las"))
    planes = []
    for f in faces:
        d = f.d - float(f.normal @ shift)
        planes.append(Plane(f.id, f.normal, d, f.centroid + shift, int((lab == f.id).sum()),
                            0.0, 1e-3, np.diag([1e-8, 1e-8, 1e-8, 1e-6]), 45.0, 0.0))  # fmt: skip
    write_planes_csv(folder / "planes.csv", planes)
    return folder


def _run(folder, tmp_path, *flags):
    return main([*flags, "createlcps", "--planes", str(folder / "planes.csv"), "--cloud",
                 str(folder / "cloud.las"), "--delta", "0.4", "--points-csv",
                 str(tmp_path / "lcps.csv")])  # fmt: skip


def _reset_logging():
    root = logging.getLogger()
    for h in list(root.handlers):
        root.removeHandler(h)
    logging.getLogger("lidarphoto").setLevel(logging.NOTSET)


def test_rejections_are_counted_and_details_only_with_vv(hip_roof_files, tmp_path, capsys):
    _reset_logging()
    try:
        assert _run(hip_roof_files, tmp_path, "-v") == 0
        err = capsys.readouterr().err
        assert f"2 candidates rejected: 2 {REJECT_SUPPORT}" in err
        assert "from the points of plane" not in err  # no per-candidate line
        _reset_logging()
        (tmp_path / "b").mkdir()
        assert _run(hip_roof_files, tmp_path / "b", "-vv") == 0
        err = capsys.readouterr().err
        detail = [line for line in err.splitlines() if "from the points of plane" in line]
        assert len(detail) == 2, err
        # every number carries its unit: "intersection 6.00 m from ... (> 2 m)"
        for line in detail:
            assert " m from the points of plane " in line and line.rstrip().endswith("(> 2 m)")
            value = float(line.split("intersection ")[1].split(" m ")[0])
            assert value > 2.0
    finally:
        _reset_logging()


def test_summary_orders_reasons_by_count():
    rej = [Rejection((1, 2, 3), "a", REJECT_SUPPORT)] * 3 + [
        Rejection((1, 2, 4), "b", REJECT_DUPLICATE)
    ]
    assert rejection_summary(rej) == (
        f"4 candidates rejected: 3 {REJECT_SUPPORT}, 1 {REJECT_DUPLICATE}"
    )
    assert rejection_summary([]) == ""


def test_summary_in_portuguese_at_the_log_bridge(hip_roof_files, tmp_path):
    """The summary record is a Message: plain English for the command line, Portuguese through
    ``core.i18n.log_text`` (what the Processing provider's log bridge shows in pt_BR QGIS)."""
    from lidarphoto.core.i18n import log_text

    records: list[logging.LogRecord] = []

    class Keep(logging.Handler):
        def emit(self, record):
            records.append(record)

    keep = Keep(logging.INFO)
    _reset_logging()
    logging.getLogger("lidarphoto").addHandler(keep)
    try:
        assert _run(hip_roof_files, tmp_path, "-v") == 0
    finally:
        logging.getLogger("lidarphoto").removeHandler(keep)
        _reset_logging()
    summary = [r for r in records if "candidates rejected" in r.getMessage()]
    assert len(summary) == 1
    assert log_text(summary[0], lang="en") == summary[0].getMessage()
    pt = log_text(summary[0], lang="pt_BR")
    assert pt.startswith("2 candidatos rejeitados: 2 interseção longe dos pontos de um plano")
    assert "(detalhes: lidarphoto -vv;" in pt and "candidates" not in pt and "details" not in pt
