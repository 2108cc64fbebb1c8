"""The QGIS plugin class: Processing provider, menu and toolbar."""

from __future__ import annotations

from pathlib import Path

from qgis.core import Qgis, QgsApplication, QgsMessageLog
from qgis.PyQt.QtCore import QCoreApplication, QTimer
from qgis.PyQt.QtGui import QIcon
from qgis.PyQt.QtWidgets import QAction, QMenu

from .dependency_check import LOG_TAG, report_missing

ICON_PATH = Path(__file__).resolve().parents[1] / "icon.svg"
ICONS = ICON_PATH.parent / "icons"
PROVIDER_ID = "lidarphoto"
TRAJECTORY_ALG = "lidarphoto:trajectorytoeo"
MENU_OBJECT_NAME = "lidarphotoMenu"
TOOLBAR_OBJECT_NAME = "lidarphotoToolBar"


class LidarPhotoPlugin:
    """initProcessing (also used by qgis_process, where ``iface`` is None), initGui, unload."""

    def __init__(self, iface) -> None:
        self.iface = iface
        self.provider = None
        self.menu: QMenu | None = None
        self.toolbar = None
        self.actions: list[QAction] = []
        self.missing_modules: list[str] | None = None
        self._dialogs: list = []
        self.image_dock = None

    def tr(self, text: str) -> str:
        return QCoreApplication.translate("LidarPhotoPlugin", text)

    # -- Processing ---------------------------------------------------------------------------
    def initProcessing(self) -> None:
        try:  # first: QGIS's language (locale/userLocale) for every message and widget
            from ..processing_provider import install_translator

            install_translator()
        except ImportError:  # a core package is missing: said below, in English
            pass
        if self.missing_modules is None:  # once per load; never raises
            self.missing_modules = report_missing(self.iface)
        if self.provider is None:
            try:
                from ..processing_provider import LidarPhotoProvider
            except ImportError as exc:  # a core package is missing: the message bar said which
                QgsMessageLog.logMessage(
                    self.tr("The algorithms are not loaded: {}").format(exc),
                    LOG_TAG,
                    Qgis.MessageLevel.Warning,
                )
                return
            self.provider = LidarPhotoProvider()  # keep the Python reference alive
            QgsApplication.processingRegistry().addProvider(self.provider)

    # -- GUI ----------------------------------------------------------------------------------
    def initGui(self) -> None:
        self.initProcessing()
        if self.iface is None:
            return
        window = self.iface.mainWindow()

        self.menu = QMenu(self.tr("&LiDAR Photogrammetry"), window)
        self.menu.setObjectName(MENU_OBJECT_NAME)
        menubar = window.menuBar()
        help_menu = getattr(self.iface, "firstRightStandardMenu", lambda: None)()
        if isinstance(help_menu, QMenu):  # before Help, like QGIS's own plugin menus
            menubar.insertMenu(help_menu.menuAction(), self.menu)
        else:
            menubar.addMenu(self.menu)

        self.toolbar = self.iface.addToolBar(self.tr("LiDAR Photogrammetry"))
        self.toolbar.setObjectName(TOOLBAR_OBJECT_NAME)

        trajectory = QAction(
            QIcon(str(ICONS / "trajectory.svg")),
            self.tr("Trajectory to Exterior Orientation…"),
            window,
        )
        trajectory.setObjectName("lidarphotoTrajectoryToEo")
        trajectory.setToolTip(
            self.tr("Exterior orientation of each image from an INS/GNSS trajectory")
        )
        trajectory.triggered.connect(self.open_trajectory_dialog)

        toolbox = QAction(
            QgsApplication.getThemeIcon("/processingAlgorithm.svg"),
            self.tr("Show the Algorithms in the Processing Toolbox"),
            window,
        )
        toolbox.setObjectName("lidarphotoShowToolbox")
        toolbox.triggered.connect(self.show_toolbox)

        picking = QAction(QIcon(str(ICONS / "picking.svg")), self.tr("Image Point Picking"), window)
        picking.setObjectName("lidarphotoImagePicking")
        picking.setToolTip(self.tr("Measure image points on LiDAR roof planes, lines and LCPs"))
        picking.setCheckable(True)
        picking.triggered.connect(self.toggle_image_dock)

        for action in (trajectory, toolbox, picking):
            self.menu.addAction(action)
            self.toolbar.addAction(action)
            self.actions.append(action)
        # the dock's modules (~45 ms of imports) are loaded once QGIS's event loop runs, so
        # that the first opening of the dock does not wait for them
        QTimer.singleShot(0, self._preload_dock)

    def _preload_dock(self) -> None:
        """Import the picking dock's modules (not while unloaded or once the dock exists)."""
        if not self.actions or self.image_dock is not None:
            return
        try:
            from . import image_dock  # noqa: F401
        except Exception as exc:  # opening the dock will fail again and say why
            QgsMessageLog.logMessage(
                self.tr("The picking dock could not be loaded: {}").format(exc),
                LOG_TAG,
                Qgis.MessageLevel.Warning,
            )

    def toggle_image_dock(self, show: bool = True):
        """Show (creating it once) or hide the image point picking dock."""
        if self.image_dock is None:
            from qgis.PyQt.QtCore import Qt

            from .image_dock import ImagePickingDock

            self.image_dock = ImagePickingDock(self.iface, self.iface.mainWindow())
            self.iface.addDockWidget(Qt.DockWidgetArea.RightDockWidgetArea, self.image_dock)
        if show:
            self.image_dock.setUserVisible(True)
        else:
            self.image_dock.hide()
        return self.image_dock

    def open_trajectory_dialog(self):
        """Open the Processing dialog of the trajectory algorithm (non-modal)."""
        import processing

        dialog = processing.createAlgorithmDialog(TRAJECTORY_ALG, {})
        if dialog is None:
            self._warn(self.tr("The algorithm {} is not available.").format(TRAJECTORY_ALG))
            return None
        self._dialogs = [d for d in self._dialogs if d.isVisible()] + [dialog]
        dialog.show()
        return dialog

    def show_toolbox(self) -> bool:
        """Show the Processing toolbox filtered to this provider's algorithms."""
        from qgis import utils

        toolbox = getattr(utils.plugins.get("processing"), "toolbox", None)
        if toolbox is None:
            self._warn(self.tr("The Processing plugin is not enabled."))
            return False
        if hasattr(toolbox, "setUserVisible"):
            toolbox.setUserVisible(True)
        else:
            toolbox.show()
        search = getattr(toolbox, "searchBox", None)
        if search is not None:
            search.setText(PROVIDER_ID)  # every algorithm of ours carries this tag
        return True

    def _warn(self, text: str) -> None:
        if self.iface is not None:
            from qgis.core import Qgis

            self.iface.messageBar().pushMessage(
                self.tr("LiDAR Photogrammetry"), text, Qgis.MessageLevel.Warning, 5
            )

    # -- unload -------------------------------------------------------------------------------
    def unload(self) -> None:
        if self.image_dock is not None:
            self.image_dock.set_monoplot(False)  # hands the clicks back, ends a line in progress
            self.image_dock.view.shutdown()  # stops the tile reader and any pyramid build
            self.image_dock.store.save()
            self.image_dock.remove_footprint()
            if self.iface is not None:
                self.iface.removeDockWidget(self.image_dock)
            self.image_dock.deleteLater()
            self.image_dock = None
        for dialog in self._dialogs:
            dialog.close()
            dialog.deleteLater()
        self._dialogs = []
        for action in self.actions:
            if self.menu is not None:
                self.menu.removeAction(action)
            if self.toolbar is not None:
                self.toolbar.removeAction(action)
            action.deleteLater()
        self.actions = []
        if self.menu is not None:
            if self.iface is not None:
                self.iface.mainWindow().menuBar().removeAction(self.menu.menuAction())
            self.menu.deleteLater()
            self.menu = None
        if self.toolbar is not None:
            if self.iface is not None:
                self.iface.mainWindow().removeToolBar(self.toolbar)
            self.toolbar.deleteLater()
            self.toolbar = None
        if self.provider is not None:
            QgsApplication.processingRegistry().removeProvider(self.provider)
            self.provider = None
