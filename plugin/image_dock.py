"""The image point picking dock: measure image points on LiDAR roof planes, lines and control
points (paper 000, section 2.2 and its Fig. 2), with overlays reprojected by the camera and the
exterior orientation, tie-point prediction, undo/redo, autosave and boresight calibration.

The dock assembles its panels and wires them; it holds no science. Data flow: QGIS layers and
files -> core objects in the mapping CRS of the EO, read once (:mod:`.control_layers`) ->
:class:`core.photo.picking_session.PickingSession` (observations with their undo history, the
control, the picking scene, the pending tie point, the last calibration result) -> pixels drawn
by :class:`.overlays.Overlays` (:mod:`.picking_controller`).

Modules: :mod:`.project_panel` (Project tab), :mod:`.calibration_panel` (Calibration tab),
:mod:`.calibration_task` (the core calibration job in a QgsTask), :mod:`.resection_task` (the
Resection tab: the core resection job of the image shown in a QgsTask), :mod:`.bundle_task`
(the Bundle tab: the core bundle adjustment of the open images in a QgsTask), :mod:`.viewer_panel`
(tools, image view, status), :mod:`.observation_table`, :mod:`.picking_controller` (clicks,
image lines and drawing), :mod:`.monoplot_control` (the Monoplot button and its DSM),
:mod:`.footprint` (the image's footprint on the map canvas), :mod:`.observation_store`
(autosave, session).
"""

from __future__ import annotations

import time
from pathlib import Path

from qgis.core import QgsCoordinateReferenceSystem, QgsProject
from qgis.gui import QgsDockWidget
from qgis.PyQt.QtCore import QT_TRANSLATE_NOOP, QCoreApplication, Qt, pyqtSignal
from qgis.PyQt.QtGui import QKeySequence
from qgis.PyQt.QtWidgets import (
    QLabel,
    QSizePolicy,
    QSplitter,
    QStackedWidget,
    QTabWidget,
    QVBoxLayout,
    QWidget,
)

from ..core.photo.picking import PickingScene
from ..core.photo.picking_session import PICK_TYPES, PickingSession
from .auto_calibration_task import AutoCalibrationController
from .bundle_task import BundleController, BundlePanel
from .calibration_panel import CALIBRATION_ALG, CalibrationPanel
from .calibration_task import CalibrationController
from .footprint import CanvasFootprint
from .image_view import view_help
from .monoplot_control import MonoplotController
from .monoplot_tool import MonoplotTool
from .observation_store import ObservationStore
from .observation_table import ObservationTable
from .picking_controller import PickingController
from .project_loader import ProjectLoader
from .project_panel import ProjectPanel
from .resection_task import ResectionController, ResectionPanel
from .viewer_panel import ViewerPanel

__all__ = ["CALIBRATION_ALG", "DOCK_HELP", "ImagePickingDock", "dock_help"]

_TYPE_KEYS = dict(zip("TPLCK", PICK_TYPES))

DOCK_HELP = QT_TRANSLATE_NOOP(
    "ImagePickingDock",
    "<b>Picking</b>: choose the type, then left-click in the image. <i>tie</i> and "
    "<i>paper</i> points take the roof plane under the cursor (a menu asks when outlines "
    "overlap); <i>line</i>: two clicks, the image line's ends, on the LiDAR line nearest to "
    "the first (drawn solid while measuring; Esc cancels, Ctrl+Z removes both ends; the "
    "Resection tab can refine the ends onto the image's edge); "
    "<i>lcp</i>/<i>check</i> take the nearest control point. <b>Resect</b> (Resection tab) "
    "orients the image shown from its lines and control points; <b>Bundle</b> (Bundle tab) "
    "adjusts the open images from their tie, control (lcp) and check points. "
    "After a tie point the other images show its prediction (yellow x): Enter accepts it, a "
    "click puts it where you see it, Esc drops it.<br>"
    "<b>Monoplot</b> (needs a DSM in the Project tab): while the button is on, a click makes a "
    "3D point on the DSM, or a vertex of a 3D line (Enter, a double click or <i>Finish "
    "line</i> ends it); they appear on the map at once, and the save button writes them to a "
    "GeoPackage. Off: clicks measure observations again.<br>"
    "<b>Keys</b>: PgDown/PgUp next/previous image · Enter accept prediction · Esc cancel "
    "prediction · Delete delete selected point · Ctrl+Z undo · Ctrl+Shift+Z / Ctrl+Y redo · "
    "T/P/L/C/K picking type · ",
)


def dock_help() -> str:
    """The dock's help (picking, monoplotting, keys), in QGIS's language."""
    return QCoreApplication.translate("ImagePickingDock", DOCK_HELP) + view_help()


class ImagePickingDock(QgsDockWidget):
    """Dock: project and calibration tabs, image viewer with overlays, observation list."""

    imageChanged = pyqtSignal(str)  # noqa: N815 - Qt signal naming
    calibrationFinished = pyqtSignal(bool)  # noqa: N815 - Qt signal naming
    autoCalibrationFinished = pyqtSignal(bool)  # noqa: N815
    resectionFinished = pyqtSignal(bool)  # noqa: N815 - Qt signal naming
    bundleFinished = pyqtSignal(bool)  # noqa: N815 - Qt signal naming

    def __init__(self, iface=None, parent=None) -> None:
        super().__init__(parent)
        self.iface = iface
        self.setObjectName("lidarphotoImagePickingDock")
        self.setWindowTitle(self.tr("Image Point Picking"))
        self.project = QgsProject.instance()
        self.session = PickingSession()
        self.store = ObservationStore(parent=self, session=self.session)
        self.current_image = ""
        self.messages: list[str] = []
        self._build_ui()
        self.loader = ProjectLoader(self)
        self.picking = PickingController(self)
        #: (candidates, labels) -> the chosen candidate or None; a menu at the cursor
        self.choose_candidate = self.picking.choose_from_menu
        self.monoplot_tool = MonoplotTool(self, self.project)
        self.monoplot = MonoplotController(self, self.monoplot_tool)
        self.calibration = CalibrationController(self)
        self.auto_calibration = AutoCalibrationController(self)
        self.resection = ResectionController(self)
        self.bundle = BundleController(self)
        self.canvas_footprint = CanvasFootprint(iface, self.project)
        self._connect()
        self.restore_session()

    def _build_ui(self) -> None:
        root = QWidget(self)
        layout = QVBoxLayout(root)
        layout.setContentsMargins(2, 2, 2, 2)
        split = QSplitter(Qt.Orientation.Vertical, root)
        layout.addWidget(split)
        self.tabs = QTabWidget()
        self.project_panel = ProjectPanel(self.project)
        self.calibration_panel = CalibrationPanel()
        self.resection_panel = ResectionPanel()
        self.bundle_panel = BundlePanel()
        help_label = QLabel(dock_help())
        help_label.setWordWrap(True)
        self.tabs.addTab(self.project_panel, self.tr("Project"))
        self.tabs.addTab(self.calibration_panel, self.tr("Calibration"))
        self.tabs.addTab(self.resection_panel, self.tr("Resection"))
        self.tabs.addTab(self.bundle_panel, self.tr("Bundle"))
        self.tabs.addTab(help_label, self.tr("Help"))
        self.viewer = ViewerPanel(dock_help())
        self.table = ObservationTable()
        rows = 4  # the table shows a few rows at least, the image the rest
        self.table.setMinimumHeight(
            rows * self.table.verticalHeader().defaultSectionSize()
            + self.table.horizontalHeader().sizeHint().height()
            + 4
        )
        for w in (self.tabs, self.viewer, self.table):
            split.addWidget(w)
        for k, stretch in enumerate((0, 1, 0)):
            split.setStretchFactor(k, stretch)
            split.setCollapsible(k, False)
        self.split = split
        #: the tab pages are hidden (only the tab bar shows) to give the image the room; a
        #: click on the current tab toggles them, on another tab opens that one
        self.tabs_collapsed = False
        self._tabs_chosen = False
        self.tabs.currentChanged.connect(self._size_tabs_to_page)
        self.tabs.tabBarClicked.connect(self._tab_clicked)
        self._size_tabs_to_page(self.tabs.currentIndex())
        # first layout (scaled to the dock): the tab page, the table's few rows, the image the rest
        split.setSizes([self.tabs.maximumHeight(), 10_000, self.table.minimumHeight()])
        self.setWidget(root)

    # -- the tab panel: as high as its current page, collapsible -----------------------------
    def _size_tabs_to_page(self, index: int) -> None:
        """The tab widget as high as the page shown (a QTabWidget is otherwise as high as its
        highest page, the Project tab, even on the Resection tab's one button)."""
        for i in range(self.tabs.count()):
            page = self.tabs.widget(i)
            vertical = QSizePolicy.Policy.Preferred if i == index else QSizePolicy.Policy.Ignored
            page.setSizePolicy(QSizePolicy.Policy.Preferred, vertical)
        self.set_tabs_collapsed(self.tabs_collapsed)

    def _tab_clicked(self, index: int) -> None:
        self._tabs_chosen = True
        if index == self.tabs.currentIndex():
            self.set_tabs_collapsed(not self.tabs_collapsed)
        else:
            self.set_tabs_collapsed(False)

    def set_tabs_collapsed(self, collapsed: bool) -> None:
        """Hide (or show) the tab pages: the tab bar stays, the image takes the height."""
        self.tabs_collapsed = bool(collapsed)
        stack = self.tabs.findChild(QStackedWidget)
        if stack is not None:
            stack.setVisible(not collapsed)
        bar = self.tabs.tabBar().sizeHint().height()
        page = self.tabs.currentWidget()
        height = bar + (0 if collapsed or page is None else page.sizeHint().height() + 8)
        self.tabs.setMaximumHeight(height)
        sizes = self.split.sizes()
        if len(sizes) == 3 and sum(sizes) > 0:
            free = sum(sizes) - height - sizes[2]
            self.split.setSizes(
                [height, max(free, self.viewer.minimumSizeHint().height()), sizes[2]]
            )

    def _connect(self) -> None:
        p, c, v = self.project_panel, self.calibration_panel, self.viewer
        p.orientationChanged.connect(self.loader.reload_orientation)
        p.layersChanged.connect(self.loader.reload_control)
        p.imagesChosen.connect(self.set_images)
        p.observationsChosen.connect(self.loader.open_observations)
        p.dsmChanged.connect(self.save_session)
        c.tablesChanged.connect(self.loader.reload_control)
        c.settingsChanged.connect(self.save_session)
        self.calibration.finished.connect(self.calibrationFinished)
        self.auto_calibration.finished.connect(self.autoCalibrationFinished)
        self.resection.finished.connect(self.resectionFinished)
        self.bundle.finished.connect(self.bundleFinished)
        v.imageSelected.connect(self.show_image)
        v.undo_button.clicked.connect(self.store.undo)
        v.redo_button.clicked.connect(self.store.redo)
        v.refine_button.clicked.connect(lambda *_: self.picking.refine_selected())
        v.view.pointPicked.connect(self.pick)
        v.view.cursorMoved.connect(self._cursor)
        # a large image without overviews: its pyramid is built in the background
        v.view.overviewProgress.connect(
            lambda pct: v.status.setText(
                self.tr("Building the overview pyramid: {:.0f} %").format(pct)
            )
        )
        v.view.overviewFinished.connect(
            lambda ok, msg: self.message(msg, warning=not ok and not v.view.build_cancelled)
        )
        v.view.loadFailed.connect(lambda msg: self.message(msg, warning=True))
        self.store.saveFailed.connect(lambda msg: self.message(msg, warning=True))
        self.monoplot_tool.message.connect(self.message)
        # a bound method, not a lambda: PyQt breaks the connection when the dock is deleted
        self.project.readProject.connect(self._project_read)

    # -- what the monoplotting tool and the tests use ------------------------------------------
    @property
    def view(self):
        return self.viewer.view

    @property
    def source(self):
        return self.viewer.source

    @property
    def scene_geometry(self) -> PickingScene | None:
        return self.session.scene

    @property
    def camera(self):
        return self.session.camera

    @property
    def eo(self):
        return self.session.eo

    def eo_crs(self) -> QgsCoordinateReferenceSystem:
        return self.project_panel.crs()

    @property
    def image_paths(self) -> dict[str, Path]:
        return self.project_panel.image_paths

    def message(self, text: str, warning: bool = False) -> None:
        """Show a message in the dock (and the QGIS message bar for warnings)."""
        self.messages.append(text)
        self.viewer.status.setText(text)
        if warning and self.iface is not None:
            from qgis.core import Qgis

            self.iface.messageBar().pushMessage(
                self.tr("Image picking"), text, Qgis.MessageLevel.Warning, 6
            )

    def keyPressEvent(self, event) -> None:
        """The dock's keys (DOCK_HELP); the viewer's own keys are handled by ImageView, and
        what it does not use reaches here."""
        key, mods = event.key(), event.modifiers()
        std = QKeySequence.StandardKey
        if event.matches(std.Undo):
            self.store.undo()
        elif event.matches(std.Redo) or (
            key == Qt.Key.Key_Y and mods & Qt.KeyboardModifier.ControlModifier
        ):
            self.store.redo()
        elif event.matches(std.Delete) or key == Qt.Key.Key_Backspace:
            self.picking.delete_selected()
        elif key == Qt.Key.Key_PageDown:
            self.viewer.next_image()
        elif key == Qt.Key.Key_PageUp:
            self.viewer.previous_image()
        elif key in (Qt.Key.Key_Return, Qt.Key.Key_Enter):
            if self.monoplot_tool.mode == "line":
                self.monoplot.finish_line()
            else:
                self.picking.accept_prediction()
        elif key == Qt.Key.Key_Escape:
            self.cancel_prediction()
        elif event.text().upper() in _TYPE_KEYS and not mods & (
            Qt.KeyboardModifier.ControlModifier | Qt.KeyboardModifier.AltModifier
        ):
            self.viewer.type_combo.setCurrentText(_TYPE_KEYS[event.text().upper()])
        else:
            super().keyPressEvent(event)
            return
        event.accept()

    # -- project (the loader's) and images ---------------------------------------------------
    def set_project_files(self, camera="", eo="", crs="", images=(), observations="") -> None:
        """Set the main inputs in one go (what the widgets do one by one)."""
        self.loader.set_project_files(camera, eo, crs, images, observations)

    def highlighted(self) -> tuple[set[str], set[str]]:
        """Ids of the planes and LCPs selected on the map."""
        return self.picking.highlighted()

    def set_images(self, paths) -> None:
        """Image files; each is matched to the EO row whose image_id is its file stem."""
        self.project_panel.set_images(paths)
        self.fill_images()
        self.save_session()

    def image_status(self, image_id: str) -> str:
        """ "ok", "missing on disk", "no file" or "no orientation"."""
        if not self.session.has_orientation(image_id):
            return "no orientation"
        path = self.image_paths.get(image_id)
        if path is None:
            return "no file"
        return "ok" if path.is_file() else "missing on disk"

    def fill_images(self) -> None:
        """The image selector: the EO's images, then the other files; one is shown."""
        ids = list(self.eo.image_id) if self.eo is not None else []
        ids += [i for i in self.image_paths if i not in ids]
        self.viewer.fill_images([(i, self.image_status(i)) for i in ids])
        if ids:
            self.show_image(self.current_image if self.current_image in ids else ids[0])

    def show_image(self, image_id: str) -> bool:
        """Open an image in the viewer; False (with a message) when it cannot be shown."""
        self.current_image = image_id
        self.viewer.select(image_id)
        oriented = self.session.has_orientation(image_id)
        path = self.image_paths.get(image_id)
        ok, text, warning = self.viewer.open(image_id, path, oriented, self.camera)
        self.message(text, warning=warning)
        if ok and not self._tabs_chosen:  # set up: the image gets the room
            self.set_tabs_collapsed(True)
        self.picking.refresh()
        self.update_footprint()
        self.imageChanged.emit(image_id)
        self.save_session()
        return ok

    # -- picking (the controller's), footprint ------------------------------------------------
    def pick(self, col: float, row: float) -> int:
        """A click at a pixel: the index of the observation added, or -1 (with a message)."""
        return self.picking.pick(col, row)

    def cancel_prediction(self) -> None:
        """Esc: drop the half-measured image line, else the pending tie point."""
        if not self.picking.cancel_line():
            self.picking.cancel_prediction()

    def _cursor(self, col: float, row: float) -> None:
        if self.source is not None:
            self.viewer.status.setText(
                self.tr("{image}  col {col:.2f}  row {row:.2f}  zoom {zoom:.3g}").format(
                    image=self.current_image, col=col, row=row, zoom=self.view.zoom
                )
            )

    def footprint(self):
        """(4, 3) ground corners of the current image (EO CRS), or None."""
        return self.session.footprint(self.current_image)

    def update_footprint(self) -> None:
        self.canvas_footprint.show(self.footprint(), self.eo_crs())

    def remove_footprint(self) -> None:
        self.canvas_footprint.remove()

    # -- monoplotting (the controller's) ------------------------------------------------------
    def set_monoplot(self, on: bool) -> bool:
        """Monoplotting on (clicks -> 3D features) or off (clicks -> picking); whether on."""
        return self.monoplot.set_monoplot(on)

    def save_monoplot(self, path: str | None = None) -> list[str]:
        """Write the monoplotted features to a GeoPackage; the layer names written."""
        return self.monoplot.save(path)

    # -- session (the loader's) ----------------------------------------------------------------
    def save_session(self, *_args) -> None:
        """Store the tabs in the QGIS project."""
        self.loader.save()

    def restore_session(self) -> None:
        """Restore the session saved in the current QGIS project (if any)."""
        self.loader.restore()

    def _project_read(self, _document) -> None:
        self.loader.restore()

    def wait_restored(self, timeout_s: float = 30.0) -> bool:
        """Process events until a restored session is all read and drawn (the steps of
        :meth:`ProjectLoader.restore`); for tests and benchmarks. False on timeout."""
        from qgis.PyQt.QtWidgets import QApplication

        t_end = time.perf_counter() + timeout_s
        app = QApplication.instance()
        while self.loader.steps_left or self.picking.markers_held:
            if time.perf_counter() > t_end:
                return False
            app.processEvents()
        return True

    # -- calibration (the controller's) -------------------------------------------------------
    def run_calibration(self) -> bool:
        """Run the boresight calibration in a background task; False if it cannot start."""
        return self.calibration.run()

    def run_resection(self) -> bool:
        """Resect the image shown in a background task; False if it cannot start."""
        return self.resection.start()

    def run_bundle(self) -> bool:
        """Bundle adjustment of the open images in a background task; False if it cannot
        start."""
        return self.bundle.start()

    def closeEvent(self, event) -> None:
        self.store.save()
        if self.monoplot_tool.mode:
            self.set_monoplot(False)
        super().closeEvent(event)
