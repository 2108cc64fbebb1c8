"""The plugin is found, loaded, started and unloaded exactly as QGIS does it (qgis.utils)."""

from __future__ import annotations

import sys
from pathlib import Path

from qgis.core import QgsApplication
from qgis.PyQt.QtCore import QCoreApplication, QEvent
from qgis.PyQt.QtWidgets import QAction, QMenu, QToolBar
from qgis_helpers import PLUGIN


def _flush_deletes() -> None:
    QCoreApplication.sendPostedEvents(None, QEvent.Type.DeferredDelete)
    QCoreApplication.processEvents()


def _our_menus(window) -> list[QMenu]:
    return [
        a.menu()
        for a in window.menuBar().actions()
        if a.menu() is not None and a.menu().objectName() == "lidarphotoMenu"
    ]


def _our_toolbars(window) -> list[QToolBar]:
    return [tb for tb in window.findChildren(QToolBar) if tb.objectName() == "lidarphotoToolBar"]


def test_discovered_with_metadata(qgis_plugin_paths, plugin_dir):
    import qgis.utils

    qgis_plugin_paths(plugin_dir)
    assert PLUGIN in qgis.utils.available_plugins
    meta = qgis.utils.pluginMetadata
    assert meta(PLUGIN, "name") == "LiDAR Photogrammetry Toolkit"
    assert meta(PLUGIN, "hasProcessingProvider") == "yes"
    assert meta(PLUGIN, "qgisMinimumVersion") == "3.22"
    assert meta(PLUGIN, "supportsQt6").lower() == "true"
    assert (plugin_dir / PLUGIN / meta(PLUGIN, "icon")).is_file()


def test_processing_start_and_unload(qgis_plugin_paths, plugin_dir, qgis_processing):
    """startProcessingPlugin is what qgis_process and QGIS (hasProcessingProvider=yes) call."""
    import qgis.utils

    qgis_plugin_paths(plugin_dir)
    registry = QgsApplication.processingRegistry()
    assert qgis.utils.loadPlugin(PLUGIN)
    # imported from the plugin folder (the symlink), not from anywhere else
    assert Path(sys.modules[PLUGIN].__file__).parent == plugin_dir / PLUGIN
    assert qgis.utils.startProcessingPlugin(PLUGIN)
    assert PLUGIN in qgis.utils.active_plugins

    provider = registry.providerById("lidarphoto")
    assert provider is not None
    assert provider.name() == "LiDAR Photogrammetry"
    assert not provider.icon().isNull()
    names = [alg.name() for alg in provider.algorithms()]
    assert "trajectorytoeo" in names
    alg = registry.algorithmById("lidarphoto:trajectorytoeo")
    assert alg is not None and alg.groupId() == "aerotriangulation"
    assert alg.group() == "Aerotriangulation"

    assert qgis.utils.unloadPlugin(PLUGIN)
    assert registry.providerById("lidarphoto") is None
    assert registry.algorithmById("lidarphoto:trajectorytoeo") is None
    assert PLUGIN not in sys.modules


def test_gui_start_adds_menu_toolbar_and_unload_removes_them(
    qgis_plugin_paths, plugin_dir, qgis_iface, qgis_processing
):
    import qgis.utils

    qgis_plugin_paths(plugin_dir)
    window = qgis_iface.mainWindow()
    registry = QgsApplication.processingRegistry()
    assert qgis.utils.loadPlugin(PLUGIN)
    assert qgis.utils.startPlugin(PLUGIN)  # classFactory(iface) + initGui()
    plugin = qgis.utils.plugins[PLUGIN]
    assert plugin.iface is qgis_iface

    assert registry.providerById("lidarphoto") is not None
    menus = _our_menus(window)
    assert len(menus) == 1
    assert menus[0].title().replace("&", "") == "LiDAR Photogrammetry"
    toolbars = _our_toolbars(window)
    assert len(toolbars) == 1
    names = {a.objectName() for a in menus[0].actions()}
    assert {"lidarphotoTrajectoryToEo", "lidarphotoShowToolbox"} <= names
    assert {a.objectName() for a in toolbars[0].actions()} == names
    actions = list(plugin.actions)
    assert all(not a.icon().isNull() for a in actions)
    images = [a.icon().pixmap(32, 32).toImage() for a in actions]
    assert all(images[i] != images[j] for i in range(len(images)) for j in range(i))  # distinct

    assert qgis.utils.unloadPlugin(PLUGIN)
    _flush_deletes()
    assert _our_menus(window) == []
    assert _our_toolbars(window) == []
    assert not [a for a in window.findChildren(QAction) if a.objectName().startswith("lidarphoto")]
    assert registry.providerById("lidarphoto") is None


def test_factory_without_iface_like_qgis_process(qgis_processing):
    """qgis_process passes iface=None: initProcessing and initGui must cope, unload cleans up."""
    import lidarphoto

    registry = QgsApplication.processingRegistry()
    plugin = lidarphoto.classFactory(None)
    plugin.initGui()
    plugin.initProcessing()  # idempotent
    assert registry.providerById("lidarphoto") is not None
    assert plugin.menu is None and plugin.toolbar is None and plugin.actions == []
    plugin.unload()
    assert registry.providerById("lidarphoto") is None
    plugin.unload()  # twice is harmless


def test_trajectory_action_opens_the_algorithm_dialog(qgis_iface, qgis_processing, monkeypatch):
    import lidarphoto
    from qgis.gui import QgsBrowserGuiModel

    # pytest-qgis's iface has no browser model; the Processing dialog wants a real one
    browser = QgsBrowserGuiModel()
    monkeypatch.setattr(qgis_iface, "browserModel", lambda: browser, raising=False)
    plugin = lidarphoto.classFactory(qgis_iface)
    plugin.initGui()
    try:
        dialog = plugin.open_trajectory_dialog()
        assert dialog is not None
        assert dialog.algorithm().id() == "lidarphoto:trajectorytoeo"
        assert dialog.isVisible()
    finally:
        plugin.unload()
        _flush_deletes()


def test_toolbox_action_without_processing_gui_warns(qgis_iface, qgis_processing):
    """Without the Processing plugin's toolbox (no GUI here) the action warns, never raises."""
    import lidarphoto
    from qgis.core import Qgis

    plugin = lidarphoto.classFactory(qgis_iface)
    plugin.initGui()
    try:
        qgis_iface.messageBar().clear_messages()
        assert plugin.show_toolbox() is False
        warnings = qgis_iface.messageBar().get_messages(Qgis.MessageLevel.Warning)
        assert len(warnings) == 1 and "Processing" in warnings[0]
    finally:
        plugin.unload()
        _flush_deletes()
