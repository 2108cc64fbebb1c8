"""scripts/package.sh builds a zip that QGIS installs and loads."""

from __future__ import annotations

import importlib.util
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
from qgis.core import QgsApplication
from qgis_helpers import PLUGIN, ROOT

pytestmark = pytest.mark.skipif(
    shutil.which("git") is None or not (ROOT / ".git").exists(), reason="needs a git work tree"
)


@pytest.fixture(scope="module")
def package(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("pkg") / "lidarphoto.zip"
    r = subprocess.run(
        ["bash", str(ROOT / "scripts" / "package.sh"), str(out)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 0, r.stdout + r.stderr
    return out


def test_zip_layout(package):
    names = zipfile.ZipFile(package).namelist()
    assert all(n.startswith("lidarphoto/") for n in names)
    for required in (
        "lidarphoto/metadata.txt",
        "lidarphoto/__init__.py",
        "lidarphoto/LICENSE",
        "lidarphoto/icon.svg",
        "lidarphoto/core/__init__.py",
        "lidarphoto/core/jobs/trajectory_to_eo.py",
        "lidarphoto/core/geometry/raycast.py",
        "lidarphoto/plugin/plugin.py",
        "lidarphoto/processing_provider/provider.py",
        "lidarphoto/processing_provider/algorithms/trajectory_to_eo.py",
    ):
        assert required in names, required
    for excluded in (
        "tests/", "bench/", ".ci/", "scripts/", "docs/", "sample_data/", ".git",
        "core/simulation/",
    ):  # fmt: skip
        assert not [n for n in names if n.startswith("lidarphoto/" + excluded)], excluded
    for excluded in ("pyproject.toml", "Makefile", "requirements-core.txt", ".gitignore"):
        assert "lidarphoto/" + excluded not in names, excluded
    assert not [n for n in names if "__pycache__" in n or n.endswith(".pyc")]
    license_text = zipfile.ZipFile(package).read("lidarphoto/LICENSE").decode()
    assert "GNU GENERAL PUBLIC LICENSE" in license_text and "Version 2" in license_text


def _qgis_unzip():
    """QGIS's plugin-installer unzip function (pyplugin_installer/unzip.py under pkgDataPath)."""
    path = Path(QgsApplication.pkgDataPath()) / "python" / "pyplugin_installer" / "unzip.py"
    if not path.is_file():
        pytest.skip(f"{path} not found")
    spec = importlib.util.spec_from_file_location("_qgis_installer_unzip", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.unzip


def test_installed_zip_loads_in_qgis(package, tmp_path, qgis_plugin_paths, qgis_processing):
    """Install the zip with QGIS's own unzip (as "Install from ZIP" does) and load it."""
    import qgis.utils

    unzip = _qgis_unzip()
    plugins = tmp_path / "profile" / "python" / "plugins"
    unzip(str(package), str(plugins))
    assert (plugins / PLUGIN / "metadata.txt").is_file()

    qgis_plugin_paths(plugins)
    assert PLUGIN in qgis.utils.available_plugins
    assert qgis.utils.loadPlugin(PLUGIN)
    assert Path(sys.modules[PLUGIN].__file__).resolve().parent == (plugins / PLUGIN).resolve()
    assert qgis.utils.startProcessingPlugin(PLUGIN)
    registry = QgsApplication.processingRegistry()
    alg = registry.algorithmById("lidarphoto:trajectorytoeo")
    assert alg is not None
    assert Path(sys.modules[alg.__class__.__module__].__file__).is_relative_to(plugins)
    assert qgis.utils.unloadPlugin(PLUGIN)
    assert registry.providerById("lidarphoto") is None
