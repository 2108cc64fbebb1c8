"""Fixtures of the QGIS tests: real QGIS 3.22+ headless through pytest-qgis (no QGIS mocks).

Run with the QGIS venv (scripts/test.sh): QT_QPA_PLATFORM=offscreen must already be in the
environment, pytest-qgis 5 creates the QgsApplication before this file is imported.
"""

from __future__ import annotations

import importlib.util
import os
import sys
import sysconfig
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))  # qgis_helpers (importlib mode)

if importlib.util.find_spec("qgis") is None:  # e.g. bare `pytest` in the core venv .venv
    collect_ignore_glob = ["test_*.py"]

from qgis_helpers import PLUGIN, ROOT, purge_plugin_modules

os.environ.setdefault("PROJ_DATA", "/usr/share/proj")  # Debian pyproj inside a venv
_PROCESSING_PLUGINS = "/usr/share/qgis/python/plugins"  # `import processing` at module level
if os.path.isdir(_PROCESSING_PLUGINS) and _PROCESSING_PLUGINS not in sys.path:
    sys.path.append(_PROCESSING_PLUGINS)


@pytest.fixture()
def plugin_dir(tmp_path: Path) -> Path:
    """A plugin folder holding a symlink ``lidarphoto`` -> the repository root."""
    plugins = tmp_path / "plugins"
    plugins.mkdir()
    (plugins / PLUGIN).symlink_to(ROOT, target_is_directory=True)
    return plugins


@pytest.fixture()
def qgis_plugin_paths(monkeypatch, qgis_iface):
    """Make qgis.utils look for plugins only where a test says; undo everything afterwards.

    Returns ``use(folder)``: sets ``qgis.utils.plugin_paths`` to [folder], puts the folder on
    sys.path (QGIS does this at start-up) and refreshes the available plugins.
    """
    import qgis.utils

    monkeypatch.setattr(qgis.utils, "plugin_paths", [])
    monkeypatch.setattr(qgis.utils, "available_plugins", list(qgis.utils.available_plugins))
    monkeypatch.setattr(
        qgis.utils, "plugins_metadata_parser", dict(qgis.utils.plugins_metadata_parser)
    )
    monkeypatch.setattr(qgis.utils, "iface", qgis_iface)
    purge_plugin_modules()

    def use(folder: Path) -> None:
        qgis.utils.plugin_paths[:] = [str(folder)]
        monkeypatch.syspath_prepend(str(folder))
        qgis.utils.updateAvailablePlugins()

    yield use
    if PLUGIN in qgis.utils.active_plugins:
        qgis.utils.unloadPlugin(PLUGIN)
    purge_plugin_modules()


@pytest.fixture()
def provider(qgis_processing):
    """The plugin's Processing side, started as qgis_process does (iface=None)."""
    import lidarphoto
    from qgis.core import QgsApplication

    registry = QgsApplication.processingRegistry()
    assert registry.providerById(PLUGIN) is None, "a previous test left the provider registered"
    plugin = lidarphoto.classFactory(None)
    plugin.initProcessing()
    yield registry.providerById(PLUGIN)
    plugin.unload()
    assert registry.providerById(PLUGIN) is None


@pytest.fixture()
def qp_env(tmp_path: Path, plugin_dir: Path) -> dict[str, str]:
    """Environment for qgis_process with the plugin enabled in a throw-away profile."""
    config = tmp_path / "qgis-config"
    ini = config / "profiles" / "default" / "QGIS" / "QGIS3.ini"
    ini.parent.mkdir(parents=True)
    ini.write_text(f"[PythonPlugins]\n{PLUGIN}=true\n", encoding="utf-8")
    env = dict(os.environ)
    env.update(
        QT_QPA_PLATFORM="offscreen",
        QGIS_CUSTOM_CONFIG_PATH=str(config),
        QGIS_PLUGINPATH=str(plugin_dir),
        PYTHONPATH=sysconfig.get_paths()["purelib"],
        PROJ_DATA=os.environ.get("PROJ_DATA", "/usr/share/proj"),
    )
    env.pop("QGIS_OPTS", None)
    return env
