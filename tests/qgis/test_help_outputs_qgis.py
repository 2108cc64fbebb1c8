"""Help and outputs as a user meets them in QGIS: ``qgis_process help`` shows each parameter's
default, unit and range and a "How to use"; layer outputs are optional where a file carries
the same content (qgis_process runs without them); HTML reports are HTML outputs (QGIS opens
them in the results viewer)."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest
from lidarphoto.core.jobs import ALGORITHMS
from qgis.core import QgsProcessingOutputHtml
from qgis_helpers import QGIS_PROCESS, ROOT

AHN3 = Path(ROOT) / "tests" / "data" / "ahn3" / "ahn3_delft_crop60.laz"
SPECS = {job.SPEC.name: job.SPEC for job in ALGORITHMS}


def _qgis_process(args, env):
    return subprocess.run(
        [QGIS_PROCESS, *args], env=env, capture_output=True, text=True, timeout=600
    )


def test_qgis_process_help_shows_defaults_units_ranges_and_usage(qp_env):
    r = _qgis_process(["help", "lidarphoto:createlcps"], qp_env)
    assert r.returncode == 0, r.stderr[-2000:]
    args = r.stdout.split("Arguments")[1]
    # under each parameter (the "Arguments" section), not only in the description
    assert (
        "MIN_ANGLE: Minimum angle between normals (degrees)\n"
        "\tdefault: 10; unit: degrees; range: 0 to 90"
    ) in args
    assert (
        "DELTA: Adjacency distance delta (length)\n\tdefault: 1; unit: length (cloud CRS unit, "
        "or m when DISTANCE_UNIT is metre); range: 0.001 to 1000"
    ) in args
    assert "MAX_CONDITION: Maximum condition number\n\tdefault: 50; unit: none" in args
    assert "PLANES: Plane table (CSV)\n\trequired" in args
    assert "default: crs; values: crs | metre" in args
    description = r.stdout.split("Arguments")[0]
    assert "<h3>How to use</h3>" in description
    assert "extractroofplanes -&gt; [createlcps] -&gt; boresightcalibration" in description
    assert "<h3>References</h3>" in description and "Pedrosa &amp; dos Santos (2020)" in (
        description
    )


@pytest.mark.parametrize("name", sorted(SPECS))
def test_layer_outputs_are_optional(provider, name):
    alg = provider.algorithm(name)
    for p in SPECS[name].params:
        if p.kind == "sink":
            d = alg.parameterDefinition(p.name)
            assert d.flags() & d.Flag.FlagOptional, p.name
            assert d.createByDefault(), p.name  # the dialog still makes the layer


@pytest.mark.parametrize("name", sorted(SPECS))
def test_html_reports_are_html_outputs(provider, name):
    alg = provider.algorithm(name)
    html = [
        p.name
        for p in SPECS[name].params
        if p.kind == "file_out" and "html" in p.file_filter.lower()
    ]
    for key in html:
        assert isinstance(alg.outputDefinition(key), QgsProcessingOutputHtml), key


def test_qgis_process_runs_extractroofplanes_without_the_layer(qp_env, tmp_path):
    csv_path, cloud = tmp_path / "planes.csv", tmp_path / "planes.laz"
    r = _qgis_process(
        [
            "--json",
            "run",
            "lidarphoto:extractroofplanes",
            "--",
            f"INPUT={AHN3}",
            "DISTANCE_UNIT=1",
            f"OUTPUT_CSV={csv_path}",
            f"OUTPUT_CLOUD={cloud}",
        ],
        qp_env,
    )
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    results = json.loads(r.stdout)["results"]
    assert results["PLANE_COUNT"] > 30
    from lidarphoto.core.io.planes import read_planes_csv

    assert len(read_planes_csv(csv_path)) == results["PLANE_COUNT"]
    assert cloud.stat().st_size > 1000
    assert not results.get("OUTPUT")  # no layer was made


def test_every_help_button_opens_a_local_page_of_its_algorithm(provider, tmp_path, monkeypatch):
    """helpUrl() of every algorithm is a file URL of an existing page (written from the spec
    into the profile, so it works offline) naming the algorithm and every parameter; the
    pages link to an index of all algorithms. Nothing points to a placeholder address."""
    from lidarphoto.processing_provider import help_docs
    from qgis.PyQt.QtCore import QUrl

    monkeypatch.setattr(help_docs, "help_folder", lambda lang: tmp_path / "help" / lang)
    monkeypatch.setattr(help_docs, "_written", {})
    algs = provider.algorithms()
    variants = {f"groundfilter{m}" for m in ("smrf", "pmf", "csf")}  # the spec's page
    assert sorted(a.name() for a in algs) == sorted({*SPECS, *variants})
    for alg in algs:
        url = QUrl(alg.helpUrl())
        assert url.isLocalFile(), alg.helpUrl()
        page = Path(url.toLocalFile())
        assert page.is_file() and page.parent == tmp_path / "help" / "en", page
        text = page.read_text(encoding="utf-8")
        spec = alg.spec
        assert f"lidarphoto:{spec.name}" in text and alg.spec_tr(spec.title) in text
        for p in spec.params:
            assert f"<b>{p.name}</b>" in text, (alg.name(), p.name)
    assert (tmp_path / "help" / "en" / "index.html").is_file()
    meta = (Path(ROOT) / "metadata.txt").read_text(encoding="utf-8")
    assert "example.org" not in meta and "example.com" not in meta


def test_a_required_crs_defaults_to_the_project_s(provider):
    """Orthorectify and the others open with the project's CRS, not "invalid projection"."""
    from qgis.core import (
        QgsCoordinateReferenceSystem,
        QgsProcessingContext,
        QgsProcessingParameterCrs,
        QgsProject,
    )

    project = QgsProject()
    project.setCrs(QgsCoordinateReferenceSystem("EPSG:28992"))
    context = QgsProcessingContext()
    context.setProject(project)
    required = 0
    for alg in provider.algorithms():
        for d in alg.parameterDefinitions():
            if isinstance(d, QgsProcessingParameterCrs) and not d.flags() & d.FlagOptional:
                required += 1
                assert d.defaultValue() == "ProjectCrs", (alg.name(), d.name())
                crs = alg.parameterAsCrs({}, d.name(), context)
                assert crs.authid() == "EPSG:28992", (alg.name(), d.name())
    assert required >= 5


def test_the_toolbox_groups_follow_the_user_s_work_with_an_icon_each(provider):
    """Seven families (LiDAR, Calibration, Aerotriangulation, Orthophotos, Accuracy, Laser
    scanning, Blocks); each algorithm shows its family's icon, not the generic gear."""
    from qgis.core import QgsApplication

    families = {
        "lidar",
        "calibration",
        "aerotriangulation",
        "orthophotos",
        "accuracy",
        "laserscanning",
        "blocks",
    }
    gear = QgsApplication.getThemeIcon("/processingAlgorithm.svg").pixmap(32, 32).toImage()
    seen = {}
    for alg in provider.algorithms():
        assert alg.groupId() in families, (alg.name(), alg.groupId())
        path = Path(alg.svgIconPath())
        assert path.is_file() and path.name == f"{alg.groupId()}.svg", (alg.name(), path)
        image = alg.icon().pixmap(32, 32).toImage()
        assert not image.isNull() and image != gear, alg.name()
        seen.setdefault(alg.groupId(), image)
    images = list(seen.values())
    assert all(images[i] != images[j] for i in range(len(images)) for j in range(i))
    assert len(seen) == len(families)
