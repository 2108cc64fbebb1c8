"""scripts/package.sh builds a zip that QGIS installs and loads."""

from __future__ import annotations

import configparser
import importlib.util
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
from qgis.core import QgsApplication
from qgis_helpers import PLUGIN, QGIS_PROCESS, ROOT

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
        "lidarphoto/i18n/lidarphoto_pt_BR.ts",  # the core's catalogue (CLI, HTML reports)
        "lidarphoto/i18n/lidarphoto_pt_BR.qm",  # Qt's, built by lrelease at packaging
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


def test_metadata_is_complete(package):
    """What plugins.qgis.org asks for, in the zip's metadata.txt (addresses: empty, not fake)."""
    meta = configparser.ConfigParser()
    meta.read_string(zipfile.ZipFile(package).read("lidarphoto/metadata.txt").decode("utf-8"))
    general = meta["general"]
    for key in (
        "name", "qgisMinimumVersion", "qgisMaximumVersion", "description", "about", "version",
        "author", "tags", "changelog", "icon", "category", "experimental",
        "hasProcessingProvider", "supportsQt6",
    ):  # fmt: skip
        assert general.get(key, "").strip(), key
    assert (
        general["icon"] and f"lidarphoto/{general['icon']}" in zipfile.ZipFile(package).namelist()
    )
    # not published yet: empty until the project has real addresses, never a placeholder
    for url in ("homepage", "repository", "tracker"):
        assert general[url] == "" or general[url].startswith("https://"), url
        assert "example." not in general[url], url
    email = general["email"]
    assert email == "" or ("@" in email and "example." not in email)
    assert general["experimental"] in ("True", "False")
    assert general["version"] in general["changelog"]
    about = general["about"].lower()
    for capability in (
        "ground filter", "roof planes", "control points", "boresight", "bundle adjustment",
        "resection", "orthophotos", "laser scanning", "monoplotting", "accuracy reports",
    ):  # fmt: skip
        assert capability in about, capability


@pytest.mark.skipif(not os.path.exists(QGIS_PROCESS), reason="no qgis_process")
def test_zip_in_a_clean_profile_under_qgis_process(package, tmp_path):
    """The zip unpacked into the python/plugins folder of a new QGIS profile (nothing else on
    the plugin path), enabled in that profile with the user locale pt_BR: QGIS itself finds
    it, registers every algorithm and shows them in Portuguese (the zip's .qm)."""
    from lidarphoto.core.jobs import ALGORITHMS

    config = tmp_path / "qgis-config"
    profile = config / "profiles" / "default"
    plugins = profile / "python" / "plugins"
    plugins.mkdir(parents=True)
    _qgis_unzip()(str(package), str(plugins))
    ini = profile / "QGIS" / "QGIS3.ini"
    ini.parent.mkdir(parents=True)
    ini.write_text(
        f"[PythonPlugins]\n{PLUGIN}=true\n[locale]\noverrideFlag=true\nuserLocale=pt_BR\n",
        encoding="utf-8",
    )
    env = {k: v for k, v in os.environ.items() if k not in ("QGIS_OPTS", "QGIS_PLUGINPATH")}
    env.update(
        QT_QPA_PLATFORM="offscreen",
        QGIS_CUSTOM_CONFIG_PATH=str(config),
        PROJ_DATA=os.environ.get("PROJ_DATA", "/usr/share/proj"),
        PYTHONPATH=__import__("sysconfig").get_paths()["purelib"],  # laspy & co. of the venv
    )
    r = subprocess.run([QGIS_PROCESS, "list"], env=env, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    ours = [
        line.strip() for line in r.stdout.splitlines() if line.strip().startswith("lidarphoto:")
    ]
    # the all-methods ground filter is out of the list (hidden from the toolbox), its three
    # one-method forms in it
    assert len(ours) == len(ALGORITHMS) - 1 + 3, r.stdout[-3000:]
    listed = "\n".join(ours)
    assert "lidarphoto:groundfiltersmrf\tFiltro de terreno: SMRF (Pingel et al. 2013)" in listed
    assert "lidarphoto:bundleadjustment\tAjustamento por feixes de raios" in listed
    assert "\nFotogrametria LiDAR\n" in r.stdout  # the provider's name


def test_installed_zip_registers_everything_and_translates(
    package, tmp_path, qgis_plugin_paths, qgis_processing
):
    """Loaded with qgis.utils from a fresh profile folder: every algorithm of the core is
    registered, and the translator of the installed copy loads (its own .qm)."""
    import qgis.utils

    plugins = tmp_path / "profile" / "python" / "plugins"
    _qgis_unzip()(str(package), str(plugins))
    qgis_plugin_paths(plugins)
    assert qgis.utils.loadPlugin(PLUGIN) and qgis.utils.startProcessingPlugin(PLUGIN)
    jobs = sys.modules[f"{PLUGIN}.core.jobs"]  # the installed copy's (imported by the provider)
    assert Path(jobs.__file__).resolve().is_relative_to(plugins.resolve())
    names = {job.SPEC.name for job in jobs.ALGORITHMS}
    assert len(names) >= 13
    registry = QgsApplication.processingRegistry()
    registered = {a.name() for a in registry.providerById("lidarphoto").algorithms()}
    assert registered == names | {f"groundfilter{m}" for m in ("smrf", "pmf", "csf")}
    i18n = sys.modules[f"{PLUGIN}.processing_provider.i18n"]
    assert Path(i18n.__file__).resolve().is_relative_to(plugins.resolve())
    try:
        assert i18n.install_translator("pt_BR") == "pt_BR"
        alg = registry.algorithmById("lidarphoto:createlcps")
        assert alg.displayName() == "Criar pontos e linhas de controle LiDAR"
    finally:
        i18n.remove_translator()
    assert registry.algorithmById("lidarphoto:createlcps").displayName() == (
        "Create LiDAR control points and lines"
    )
    assert qgis.utils.unloadPlugin(PLUGIN)
