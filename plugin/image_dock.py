"""The image point picking dock: measure image points on LiDAR roof planes, lines and control
points (paper 000, section 2.2 and its Fig. 2), with overlays reprojected by the camera and the
exterior orientation, tie-point prediction, undo/redo, autosave and boresight calibration.

Data flow: QGIS layers and files -> numpy arrays in the mapping CRS of the EO (layers in another
CRS are reprojected here with QgsCoordinateTransform) -> :class:`core.picking.PickingScene`
(rigorous local frame) -> pixels drawn by :class:`plugin.overlays.Overlays`.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
from qgis.core import (
    QgsApplication,
    QgsCoordinateReferenceSystem,
    QgsCoordinateTransform,
    QgsGeometry,
    QgsMapLayerProxyModel,
    QgsPointXY,
    QgsProcessingAlgRunnerTask,
    QgsProcessingContext,
    QgsProcessingFeedback,
    QgsProject,
    QgsWkbTypes,
)
from qgis.gui import (
    QgsDockWidget,
    QgsFileWidget,
    QgsMapLayerComboBox,
    QgsProjectionSelectionWidget,
    QgsRubberBand,
)
from qgis.PyQt.QtCore import QEvent, QPointF, Qt, pyqtSignal
from qgis.PyQt.QtGui import QColor, QCursor, QKeySequence
from qgis.PyQt.QtWidgets import (
    QAbstractItemView,
    QApplication,
    QCheckBox,
    QComboBox,
    QDoubleSpinBox,
    QFileDialog,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QListWidget,
    QMenu,
    QPushButton,
    QSplitter,
    QTableWidget,
    QTableWidgetItem,
    QTabWidget,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from ..core.errors import InputError
from ..core.geometry.planes import fit_plane
from ..core.io.camera import read_camera_json
from ..core.io.orientation import read_eo_csv
from ..core.photo.mount import MOUNT_CHOICES
from ..core.photo.picking import PickingScene, nearest_point, nearest_segment
from .image_source import ImageSource, ImageSourceError
from .image_view import VIEW_HELP, ImageView
from .monoplot_tool import MonoplotTool
from .observation_store import Observation, ObservationStore, load_session, save_session
from .overlays import GROUPS, Overlays

__all__ = ["CALIBRATION_ALG", "DOCK_HELP", "ImagePickingDock"]

CALIBRATION_ALG = "lidarphoto:boresightcalibration"
PICK_TYPES = ("tie", "paper", "line", "lcp", "check")
_PREFIX = {"tie": "T", "paper": "P", "line": "R", "lcp": "C", "check": "K"}
_HIT_SCREEN_PX = 10.0
_TYPE_KEYS = dict(zip("TPLCK", PICK_TYPES))
IMAGE_SUFFIXES = (".tif", ".tiff", ".jpg", ".jpeg", ".png", ".jp2", ".ecw", ".vrt", ".img")

DOCK_HELP = (
    "<b>Picking</b>: choose the type, then left-click in the image. <i>tie</i> and "
    "<i>paper</i> points take the roof plane under the cursor (a menu asks when outlines "
    "overlap); <i>line</i> and <i>lcp</i>/<i>check</i> take the nearest line or control point. "
    "After a tie point the other images show its prediction (yellow x): Enter accepts it, a "
    "click puts it where you see it, Esc drops it.<br>"
    "<b>Monoplot</b> (needs a DSM in the Project tab): while the button is on, a click makes a "
    "3D point on the DSM, or a vertex of a 3D line (Enter, a double click or <i>Finish "
    "line</i> ends it); they appear on the map at once, and the save button writes them to a "
    "GeoPackage. Off: clicks measure observations again.<br>"
    "<b>Keys</b>: PgDown/PgUp next/previous image · Enter accept prediction · Esc cancel "
    "prediction · Delete delete selected point · Ctrl+Z undo · Ctrl+Shift+Z / Ctrl+Y redo · "
    "T/P/L/C/K picking type · " + VIEW_HELP
)

if hasattr(QgsWkbTypes, "PolygonGeometry"):  # QGIS 3.22-3.28
    _POLYGON_GEOMETRY = QgsWkbTypes.PolygonGeometry
else:  # pragma: no cover - QGIS >= 3.30 / 4
    from qgis.core import Qgis

    _POLYGON_GEOMETRY = Qgis.GeometryType.Polygon


def _vertices(geometry: QgsGeometry) -> np.ndarray:
    """(M, 3) vertices of a geometry (z = NaN when it has none)."""
    pts = [(v.x(), v.y(), v.z()) for v in geometry.vertices()]
    return np.array(pts, dtype=np.float64).reshape(-1, 3)


def _feature_id_value(feature, field_index: int):
    return str(feature.id()) if field_index < 0 else str(feature.attributes()[field_index])


class ImagePickingDock(QgsDockWidget):
    """Dock: project panel, image viewer with overlays, observation list, calibration."""

    imageChanged = pyqtSignal(str)  # noqa: N815 - Qt signal naming
    calibrationFinished = pyqtSignal(bool)  # noqa: N815 - Qt signal naming

    def __init__(self, iface=None, parent=None) -> None:
        super().__init__(parent)
        self.iface = iface
        self.setObjectName("lidarphotoImagePickingDock")
        self.setWindowTitle(self.tr("Image Point Picking"))
        self.project = QgsProject.instance()
        self.store = ObservationStore(parent=self)
        self.scene_geometry: PickingScene | None = None
        self.camera = None
        self.eo = None
        self.image_paths: dict[str, Path] = {}
        self.current_image = ""
        self.source: ImageSource | None = None
        self.planes: dict = {"ids": [], "fids": [], "rings": [], "normals": None, "points": None}
        self.lines: dict = {"ids": [], "fids": [], "a": np.empty((0, 3)), "b": np.empty((0, 3))}
        self.lcps: dict = {"ids": [], "fids": [], "xyz": np.empty((0, 3))}
        self.projected: dict = {}
        self.pending: dict | None = None
        self.residuals: dict[int, np.ndarray] = {}
        self.calibration_results: dict = {}
        self.selected_index = -1
        self.messages: list[str] = []
        self.choose_candidate = self._choose_candidate_menu
        self._task = None
        self._restoring = False
        self.rubber_band = None
        self._build_ui()
        self.monoplot_tool = MonoplotTool(self, self.project)
        self._dsm_key: tuple | None = None
        self._dsm_note = ""
        self._connect()
        self.restore_session()

    # ================================================================ UI
    def _build_ui(self) -> None:
        root = QWidget(self)
        layout = QVBoxLayout(root)
        layout.setContentsMargins(2, 2, 2, 2)
        split = QSplitter(Qt.Orientation.Vertical, root)
        layout.addWidget(split)

        # -- project and calibration panel
        tabs = QTabWidget()
        self.tabs = tabs
        proj = QWidget()
        form = QFormLayout(proj)
        self.camera_edit = QgsFileWidget()
        self.camera_edit.setFilter(self.tr("Camera JSON (*.json)"))
        self.eo_edit = QgsFileWidget()
        self.eo_edit.setFilter(self.tr("EO CSV (*.csv *.txt)"))
        self.eo_edit.setToolTip(self.tr("Exterior orientation from 'Trajectory to EO'"))
        self.crs_widget = QgsProjectionSelectionWidget()
        self.crs_widget.setCrs(self.project.crs())
        self.crs_widget.setToolTip(self.tr("Mapping CRS of the exterior orientation"))
        images_row = QWidget()
        hl = QHBoxLayout(images_row)
        hl.setContentsMargins(0, 0, 0, 0)
        self.images_list = QListWidget()
        self.images_list.setMaximumHeight(80)
        self.add_images_button = QPushButton(self.tr("Add…"))
        self.clear_images_button = QPushButton(self.tr("Clear"))
        col = QVBoxLayout()
        col.addWidget(self.add_images_button)
        col.addWidget(self.clear_images_button)
        hl.addWidget(self.images_list)
        hl.addLayout(col)
        self.planes_combo = QgsMapLayerComboBox()
        self.planes_combo.setFilters(QgsMapLayerProxyModel.Filter.PolygonLayer)
        self.planes_combo.setAllowEmptyLayer(True)
        self.planes_combo.setLayer(None)
        self.lines_combo = QgsMapLayerComboBox()
        self.lines_combo.setFilters(QgsMapLayerProxyModel.Filter.LineLayer)
        self.lines_combo.setAllowEmptyLayer(True)
        self.lines_combo.setLayer(None)
        self.lcps_combo = QgsMapLayerComboBox()
        self.lcps_combo.setFilters(QgsMapLayerProxyModel.Filter.PointLayer)
        self.lcps_combo.setAllowEmptyLayer(True)
        self.lcps_combo.setLayer(None)
        self.obs_edit = QgsFileWidget()
        self.obs_edit.setStorageMode(QgsFileWidget.StorageMode.SaveFile)
        self.obs_edit.setFilter(self.tr("Observation CSV (*.csv)"))
        self.obs_edit.setToolTip(self.tr("Saved after every change (atomic write)"))
        form.addRow(self.tr("Camera"), self.camera_edit)
        form.addRow(self.tr("Exterior orientation"), self.eo_edit)
        form.addRow(self.tr("Mapping CRS"), self.crs_widget)
        form.addRow(self.tr("Images"), images_row)
        form.addRow(self.tr("Roof planes"), self.planes_combo)
        form.addRow(self.tr("Lines"), self.lines_combo)
        form.addRow(self.tr("Control points"), self.lcps_combo)
        form.addRow(self.tr("Observations"), self.obs_edit)
        # the DSM of the monoplotting tool: a raster layer of the project or a file
        self.dsm_combo = QgsMapLayerComboBox()
        self.dsm_combo.setObjectName("lidarphotoDsmLayer")
        self.dsm_combo.setFilters(QgsMapLayerProxyModel.Filter.RasterLayer)
        self.dsm_combo.setAllowEmptyLayer(True)
        self.dsm_combo.setLayer(None)
        self.dsm_combo.setToolTip(self.tr("DSM raster (heights) for monoplotting"))
        dsm_row = QWidget()
        dl = QHBoxLayout(dsm_row)
        dl.setContentsMargins(0, 0, 0, 0)
        self.dsm_edit = QgsFileWidget()
        self.dsm_edit.setFilter(self.tr("DSM (*.tif *.tiff *.las *.laz);;All files (*)"))
        self.dsm_edit.setToolTip(
            self.tr("Or a DSM file: GeoTIFF, or a LAS/LAZ cloud rasterised at the cell size")
        )
        self.dsm_cell = QDoubleSpinBox()
        self.dsm_cell.setRange(0.01, 100.0)
        self.dsm_cell.setDecimals(2)
        self.dsm_cell.setValue(0.5)
        self.dsm_cell.setSuffix(self.tr(" m"))
        self.dsm_cell.setToolTip(self.tr("Cell of the DSM made from a LAS/LAZ file"))
        dl.addWidget(self.dsm_edit, 1)
        dl.addWidget(self.dsm_cell)
        form.addRow(self.tr("DSM (monoplot)"), self.dsm_combo)
        form.addRow(self.tr("or DSM file"), dsm_row)
        tabs.addTab(proj, self.tr("Project"))

        cal = QWidget()
        cform = QFormLayout(cal)
        self.trajectory_edit = QgsFileWidget()
        self.trajectory_edit.setFilter(self.tr("Trajectory CSV (*.csv *.txt)"))
        self.lever_edit = QLineEdit("0,0,0")
        self.mount_combo = QComboBox()
        self.mount_combo.addItems(list(MOUNT_CHOICES[:-1]))
        self.boresight_edit = QLineEdit("0,0,0")
        self.planes_csv_edit = QgsFileWidget()
        self.lines_csv_edit = QgsFileWidget()
        self.lcps_csv_edit = QgsFileWidget()
        for w in (self.planes_csv_edit, self.lines_csv_edit, self.lcps_csv_edit):
            w.setFilter(self.tr("CSV (*.csv)"))
        self.run_button = QPushButton(self.tr("Run boresight calibration"))
        self.run_button.setObjectName("lidarphotoRunCalibration")
        self.run_button.setToolTip(
            self.tr("Runs {} in the background with the current observations").format(
                CALIBRATION_ALG
            )
        )
        self.result_label = QLabel()
        self.result_label.setWordWrap(True)
        self.result_label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        cform.addRow(self.tr("Trajectory"), self.trajectory_edit)
        cform.addRow(self.tr("Lever arm x,y,z (m)"), self.lever_edit)
        cform.addRow(self.tr("Mount"), self.mount_combo)
        cform.addRow(self.tr("Initial boresight (deg)"), self.boresight_edit)
        cform.addRow(self.tr("Plane table"), self.planes_csv_edit)
        cform.addRow(self.tr("Line table"), self.lines_csv_edit)
        cform.addRow(self.tr("LCP table"), self.lcps_csv_edit)
        cform.addRow(self.run_button)
        cform.addRow(self.result_label)
        tabs.addTab(cal, self.tr("Calibration"))
        help_label = QLabel(DOCK_HELP)
        help_label.setWordWrap(True)
        tabs.addTab(help_label, self.tr("Help"))
        split.addWidget(tabs)

        # -- viewer with its tool row
        viewer = QWidget()
        vl = QVBoxLayout(viewer)
        vl.setContentsMargins(0, 0, 0, 0)
        row = QHBoxLayout()
        self.prev_button = QToolButton()
        self.prev_button.setText("◀")
        self.next_button = QToolButton()
        self.next_button.setText("▶")
        self.image_combo = QComboBox()
        self.image_combo.setMinimumContentsLength(10)
        self.type_combo = QComboBox()
        self.type_combo.addItems(list(PICK_TYPES))
        self.type_combo.setToolTip(self.tr("Type of the next point (T/P/L/C/K)"))
        self.undo_button = QToolButton()
        self.undo_button.setIcon(QgsApplication.getThemeIcon("/mActionUndo.svg"))
        self.undo_button.setToolTip(self.tr("Undo (Ctrl+Z)"))
        self.redo_button = QToolButton()
        self.redo_button.setIcon(QgsApplication.getThemeIcon("/mActionRedo.svg"))
        self.redo_button.setToolTip(self.tr("Redo (Ctrl+Shift+Z)"))
        self.magnifier_button = QToolButton()
        self.magnifier_button.setIcon(QgsApplication.getThemeIcon("/mActionZoomIn.svg"))
        self.magnifier_button.setCheckable(True)
        self.magnifier_button.setToolTip(self.tr("Magnifier (M)"))
        self.help_button = QToolButton()
        self.help_button.setText("?")
        self.help_button.setToolTip(DOCK_HELP)
        self.monoplot_button = QToolButton()
        self.monoplot_button.setObjectName("lidarphotoMonoplot")
        self.monoplot_button.setText(self.tr("Monoplot"))
        self.monoplot_button.setCheckable(True)
        self.monoplot_button.setToolTip(
            self.tr(
                "Monoplotting: clicks become 3D points (or line vertices) on the DSM, added to "
                "the map at once; off: clicks measure observations again"
            )
        )
        self.monoplot_mode = QComboBox()
        self.monoplot_mode.setObjectName("lidarphotoMonoplotMode")
        self.monoplot_mode.addItem(self.tr("points"), "point")
        self.monoplot_mode.addItem(self.tr("lines"), "line")
        self.monoplot_mode.setToolTip(self.tr("Monoplot points, or lines (finish: Enter)"))
        self.finish_line_button = QToolButton()
        self.finish_line_button.setText(self.tr("Finish line"))
        self.finish_line_button.setToolTip(
            self.tr("End the line being digitised (also Enter or a double click)")
        )
        self.finish_line_button.setEnabled(False)
        self.save_monoplot_button = QToolButton()
        self.save_monoplot_button.setIcon(QgsApplication.getThemeIcon("/mActionFileSave.svg"))
        self.save_monoplot_button.setToolTip(
            self.tr("Save the monoplotted points and lines to a GeoPackage")
        )
        for w in (self.prev_button, self.image_combo, self.next_button, self.type_combo):
            row.addWidget(w)
        row.addStretch(1)
        for w in (
            self.monoplot_button,
            self.monoplot_mode,
            self.finish_line_button,
            self.save_monoplot_button,
        ):
            row.addWidget(w)
        for w in (self.undo_button, self.redo_button, self.magnifier_button, self.help_button):
            row.addWidget(w)
        vl.addLayout(row)
        toggles = QHBoxLayout()
        self.overlay_checks: dict[str, QCheckBox] = {}
        for name in GROUPS:
            box = QCheckBox(self.tr(name))
            box.setChecked(True)
            self.overlay_checks[name] = box
            toggles.addWidget(box)
        self.residual_scale = QDoubleSpinBox()
        self.residual_scale.setRange(1.0, 10000.0)
        self.residual_scale.setValue(50.0)
        self.residual_scale.setPrefix("×")
        self.residual_scale.setToolTip(self.tr("Scale of the residual vectors"))
        toggles.addWidget(self.residual_scale)
        toggles.addStretch(1)
        vl.addLayout(toggles)
        self.view = ImageView()
        self.view.setMinimumHeight(200)
        vl.addWidget(self.view, 1)
        self.status = QLabel()
        self.status.setWordWrap(True)
        self.status.setObjectName("lidarphotoPickingStatus")
        vl.addWidget(self.status)
        split.addWidget(viewer)

        # -- observation list
        self.table = QTableWidget(0, 7)
        self.table.setHorizontalHeaderLabels(
            [self.tr(t) for t in ("image", "point", "type", "target", "col", "row", "|v| px")]
        )
        self.table.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        self.table.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        split.addWidget(self.table)
        split.setStretchFactor(1, 4)
        split.setSizes([230, 560, 140])
        self.overlays = Overlays(self.view.scene())
        self.view.hit_test = self._hit_observation
        self.setWidget(root)

    def keyPressEvent(self, event) -> None:
        """The dock's keys (DOCK_HELP); the viewer's own keys are handled by ImageView, and
        what it does not use reaches here."""
        key = event.key()
        std = QKeySequence.StandardKey
        if event.matches(std.Undo):
            self.store.undo()
        elif event.matches(std.Redo) or (
            key == Qt.Key.Key_Y and event.modifiers() & Qt.KeyboardModifier.ControlModifier
        ):
            self.store.redo()
        elif event.matches(std.Delete) or key == Qt.Key.Key_Backspace:
            self.delete_selected()
        elif key == Qt.Key.Key_PageDown:
            self.next_image()
        elif key == Qt.Key.Key_PageUp:
            self.previous_image()
        elif key in (Qt.Key.Key_Return, Qt.Key.Key_Enter):
            if self.monoplot_tool.mode == "line":
                self.finish_monoplot_line()
            else:
                self.accept_prediction()
        elif key == Qt.Key.Key_Escape:
            self.cancel_prediction()
        elif event.text().upper() in _TYPE_KEYS and not event.modifiers() & (
            Qt.KeyboardModifier.ControlModifier | Qt.KeyboardModifier.AltModifier
        ):
            self.type_combo.setCurrentText(_TYPE_KEYS[event.text().upper()])
        else:
            super().keyPressEvent(event)
            return
        event.accept()

    def _connect(self) -> None:
        self.camera_edit.fileChanged.connect(self.reload_orientation)
        self.eo_edit.fileChanged.connect(self.reload_orientation)
        self.crs_widget.crsChanged.connect(self.reload_orientation)
        self.add_images_button.clicked.connect(self._ask_images)
        self.clear_images_button.clicked.connect(lambda: self.set_images([]))
        for combo in (self.planes_combo, self.lines_combo, self.lcps_combo):
            combo.layerChanged.connect(self._layers_changed)
        self.obs_edit.fileChanged.connect(self.open_observations)
        for w in (
            self.trajectory_edit,
            self.planes_csv_edit,
            self.lines_csv_edit,
            self.lcps_csv_edit,
        ):
            w.fileChanged.connect(self.save_session)
        for w in (self.lever_edit, self.boresight_edit):
            w.editingFinished.connect(self.save_session)
        self.mount_combo.currentIndexChanged.connect(self.save_session)
        self.image_combo.currentIndexChanged.connect(self._image_combo_changed)
        self.prev_button.clicked.connect(self.previous_image)
        self.next_button.clicked.connect(self.next_image)
        self.undo_button.clicked.connect(self.store.undo)
        self.redo_button.clicked.connect(self.store.redo)
        self.magnifier_button.toggled.connect(self.view.magnifier.setVisible)
        for name, box in self.overlay_checks.items():
            box.toggled.connect(lambda on, n=name: self.overlays.set_visible(n, on))
        self.residual_scale.valueChanged.connect(lambda _v: self.refresh_overlays())
        self.run_button.clicked.connect(self.run_calibration)
        self.view.pointPicked.connect(self.pick)
        self.view.pointMoved.connect(self._moved)
        self.view.cursorMoved.connect(self._cursor)
        # a large image without overviews: its pyramid is built in the background
        self.view.overviewProgress.connect(
            lambda pct: self.status.setText(
                self.tr("Building the overview pyramid: {:.0f} %").format(pct)
            )
        )
        self.view.overviewFinished.connect(
            lambda ok, msg: self.message(msg, warning=not ok and "cancelled" not in msg)
        )
        self.view.loadFailed.connect(lambda msg: self.message(msg, warning=True))
        self.store.changed.connect(self._store_changed)
        self.store.saveFailed.connect(lambda msg: self.message(msg, warning=True))
        self.table.itemSelectionChanged.connect(self._table_selection)
        # a bound method, not a lambda: PyQt breaks the connection when the dock is deleted
        self.project.readProject.connect(self._project_read)
        self.dsm_combo.layerChanged.connect(self._dsm_changed)
        self.dsm_edit.fileChanged.connect(self._dsm_changed)
        self.dsm_cell.editingFinished.connect(self._dsm_changed)
        self.monoplot_button.toggled.connect(self.set_monoplot)
        self.monoplot_mode.currentIndexChanged.connect(self._monoplot_mode_changed)
        self.finish_line_button.clicked.connect(self.finish_monoplot_line)
        self.save_monoplot_button.clicked.connect(lambda: self.save_monoplot())
        self.monoplot_tool.message.connect(self.message)
        self.view.viewport().installEventFilter(self)

    # ================================================================ messages
    def message(self, text: str, warning: bool = False) -> None:
        """Show a message in the dock (and the QGIS message bar for warnings)."""
        self.messages.append(text)
        self.status.setText(text)
        if warning and self.iface is not None:
            from qgis.core import Qgis

            self.iface.messageBar().pushMessage(
                self.tr("Image picking"), text, Qgis.MessageLevel.Warning, 6
            )

    # ================================================================ project
    def set_project_files(
        self,
        camera: str = "",
        eo: str = "",
        crs: str = "",
        images=(),
        observations: str = "",
    ) -> None:
        """Set the main inputs in one go (what the widgets do one by one)."""
        self._restoring = True
        try:
            if crs:
                self.crs_widget.setCrs(QgsCoordinateReferenceSystem(crs))
            self.camera_edit.setFilePath(str(camera))
            self.eo_edit.setFilePath(str(eo))
        finally:
            self._restoring = False
        self.reload_orientation()
        if images:
            self.set_images(images)
        if observations:
            self.obs_edit.setFilePath(str(observations))

    def eo_crs(self) -> QgsCoordinateReferenceSystem:
        return self.crs_widget.crs()

    def reload_orientation(self, *_args) -> None:
        """Read the camera and the EO table; rebuild the picking scene."""
        if self._restoring:
            return
        self.scene_geometry = None
        cam_path, eo_path = self.camera_edit.filePath(), self.eo_edit.filePath()
        try:
            self.camera = read_camera_json(cam_path) if cam_path else None
            crs = self.eo_crs()
            self.eo = read_eo_csv(eo_path, crs.toWkt()) if eo_path else None
            if self.camera is not None and self.eo is not None:
                if not crs.isValid():
                    raise InputError("choose the mapping CRS of the exterior orientation")
                self.scene_geometry = PickingScene(
                    self.eo, self.camera, crs.authid() or crs.toWkt()
                )
        except (InputError, OSError, ValueError) as exc:
            self.message(self.tr("Orientation not loaded: {}").format(exc), warning=True)
        self._layers_changed()
        self._fill_image_combo()
        self._check_foreign_observations()
        self.save_session()

    def _ask_images(self) -> None:
        files, _ = QFileDialog.getOpenFileNames(
            self,
            self.tr("Images"),
            "",
            self.tr("Images (*.tif *.tiff *.jpg *.jpeg *.png *.jp2 *.vrt *.img);;All files (*)"),
        )
        if files:
            self.set_images(sorted(set(map(str, self.image_paths.values())) | set(files)))

    def set_images(self, paths) -> None:
        """Image files; each is matched to the EO row whose image_id is its file stem."""
        self.image_paths = {Path(p).stem: Path(p) for p in paths}
        self.images_list.clear()
        for stem, p in self.image_paths.items():
            self.images_list.addItem(f"{stem}  ({p})")
        self._fill_image_combo()
        self.save_session()

    def image_status(self, image_id: str) -> str:
        """ "ok", "missing on disk", "no file" or "no orientation"."""
        has_eo = self.eo is not None and image_id in self.eo.image_id
        path = self.image_paths.get(image_id)
        if not has_eo:
            return "no orientation"
        if path is None:
            return "no file"
        return "ok" if path.is_file() else "missing on disk"

    def _fill_image_combo(self) -> None:
        ids = list(self.eo.image_id) if self.eo is not None else []
        ids += [i for i in self.image_paths if i not in ids]
        keep = self.current_image
        self.image_combo.blockSignals(True)
        self.image_combo.clear()
        for i in ids:
            status = self.image_status(i)
            self.image_combo.addItem(i if status == "ok" else f"{i} ({status})", i)
        self.image_combo.blockSignals(False)
        if ids:
            self.show_image(keep if keep in ids else ids[0])

    def _image_combo_changed(self, index: int) -> None:
        if index >= 0:
            self.show_image(self.image_combo.itemData(index))

    def next_image(self) -> None:
        n = self.image_combo.count()
        if n:
            self.image_combo.setCurrentIndex((self.image_combo.currentIndex() + 1) % n)

    def previous_image(self) -> None:
        n = self.image_combo.count()
        if n:
            self.image_combo.setCurrentIndex((self.image_combo.currentIndex() - 1) % n)

    def show_image(self, image_id: str) -> bool:
        """Open an image in the viewer; False (with a message) when it cannot be shown."""
        self.current_image = image_id
        k = self.image_combo.findData(image_id)
        if k >= 0 and k != self.image_combo.currentIndex():
            self.image_combo.blockSignals(True)
            self.image_combo.setCurrentIndex(k)
            self.image_combo.blockSignals(False)
        if self.source is not None:
            self.source.close()
            self.source = None
        status = self.image_status(image_id)
        path = self.image_paths.get(image_id)
        ok = True
        if path is None or not path.is_file():
            self.message(
                self.tr("Image {}: {} ({}).").format(
                    image_id,
                    self.tr("file missing on disk") if path else self.tr("no image file"),
                    path or self.tr("add it with Images > Add"),
                ),
                warning=True,
            )
            self.view.set_source(None)
            ok = False
        else:
            try:
                self.source = ImageSource(path)
            except ImageSourceError as exc:
                self.message(str(exc), warning=True)
                self.view.set_source(None)
                ok = False
            else:
                self.view.set_source(self.source)
                if status == "no orientation":
                    self.message(
                        self.tr(
                            "Image {} has no exterior orientation: no overlays, no picking."
                        ).format(image_id),
                        warning=True,
                    )
                elif self.camera is not None and (
                    (self.source.width, self.source.height)
                    != (self.camera.width_px, self.camera.height_px)
                ):
                    self.message(
                        self.tr("Image {} is {} x {} px but the camera is {} x {} px.").format(
                            image_id,
                            self.source.width,
                            self.source.height,
                            self.camera.width_px,
                            self.camera.height_px,
                        ),
                        warning=True,
                    )
                else:
                    self.message(
                        self.tr("Image {}: {} x {} px, {} band(s), {}.").format(
                            image_id,
                            self.source.width,
                            self.source.height,
                            self.source.bands,
                            self.source.dtype,
                        )
                    )
        self.refresh_overlays()
        self.update_footprint()
        self.imageChanged.emit(image_id)
        self.save_session()
        return ok

    # ================================================================ layers
    def _transform(self, layer) -> QgsCoordinateTransform | None:
        crs = self.eo_crs()
        if not crs.isValid() or layer.crs() == crs:
            return None
        return QgsCoordinateTransform(layer.crs(), crs, self.project)

    @staticmethod
    def _id_field(layer) -> int:
        return layer.fields().indexFromName("id")

    def _layers_changed(self, *_args) -> None:
        """Read the plane, line and LCP layers into arrays in the EO's CRS."""
        self._read_planes(self.planes_combo.currentLayer())
        self._read_lines(self.lines_combo.currentLayer())
        self._read_lcps(self.lcps_combo.currentLayer())
        for layer in (self.planes_combo.currentLayer(), self.lcps_combo.currentLayer()):
            if layer is not None:
                try:
                    layer.selectionChanged.disconnect(self._selection_changed)
                except TypeError:
                    pass
                layer.selectionChanged.connect(self._selection_changed)
        self.refresh_overlays()
        self.save_session()

    def _geometries(self, layer):
        """(feature id, id value, geometry in the EO CRS, feature) of every feature."""
        ct = self._transform(layer)
        idx = self._id_field(layer)
        for f in layer.getFeatures():
            g = QgsGeometry(f.geometry())
            if g.isEmpty():
                continue
            if ct is not None:
                g.transform(ct)
            yield f.id(), _feature_id_value(f, idx), g, f

    def _read_planes(self, layer) -> None:
        ids, fids, rings, normals, points = [], [], [], [], []
        skipped = 0
        if layer is not None:
            same_crs = self._transform(layer) is None
            names = layer.fields().names()
            has_abcd = all(n in names for n in ("a", "b", "c", "d"))
            for fid, pid, g, f in self._geometries(layer):
                parts = g.asGeometryCollection() if g.isMultipart() else [g]
                ring = _vertices(QgsGeometry(parts[0].constGet().exteriorRing().clone()))
                if len(ring) > 1 and np.allclose(ring[0], ring[-1], equal_nan=True):
                    ring = ring[:-1]
                if has_abcd and same_crs:
                    n = np.array([float(f["a"]), float(f["b"]), float(f["c"])])
                    d = float(f["d"])
                    if np.isnan(ring[:, 2]).any() and abs(n[2]) > 1e-9:
                        ring[:, 2] = -(ring[:, :2] @ n[:2] + d) / n[2]
                    point = ring.mean(axis=0)
                    point = point - (point @ n + d) * n
                elif len(ring) >= 3 and np.isfinite(ring).all():
                    plane = fit_plane(ring)
                    n, point = plane.normal, plane.centroid
                else:
                    skipped += 1
                    continue
                ids.append(pid)
                fids.append(fid)
                rings.append(ring)
                normals.append(n)
                points.append(point)
            if skipped:
                self.message(
                    self.tr(
                        "{} plane(s) of {} have no heights and no a,b,c,d fields: skipped."
                    ).format(skipped, layer.name()),
                    warning=True,
                )
        self.planes = {
            "ids": ids,
            "fids": fids,
            "rings": rings,
            "normals": np.array(normals).reshape(-1, 3),
            "points": np.array(points).reshape(-1, 3),
        }

    def _read_lines(self, layer) -> None:
        ids, fids, a, b = [], [], [], []
        if layer is not None:
            for fid, lid, g, _f in self._geometries(layer):
                v = _vertices(g)
                if len(v) >= 2 and np.isfinite(v).all():
                    ids.append(lid)
                    fids.append(fid)
                    a.append(v[0])
                    b.append(v[-1])
        self.lines = {
            "ids": ids,
            "fids": fids,
            "a": np.array(a).reshape(-1, 3),
            "b": np.array(b).reshape(-1, 3),
        }

    def _read_lcps(self, layer) -> None:
        ids, fids, xyz = [], [], []
        if layer is not None:
            for fid, cid, g, _f in self._geometries(layer):
                v = _vertices(g)
                if len(v) and np.isfinite(v[0]).all():
                    ids.append(cid)
                    fids.append(fid)
                    xyz.append(v[0])
        self.lcps = {"ids": ids, "fids": fids, "xyz": np.array(xyz).reshape(-1, 3)}

    def _selected_ids(self, layer, table: dict) -> set[str]:
        if layer is None:
            return set()
        sel = set(layer.selectedFeatureIds())
        return {i for i, f in zip(table["ids"], table["fids"]) if f in sel}

    def _selection_changed(self, *_args) -> None:
        self.refresh_overlays()

    def highlighted(self) -> tuple[set[str], set[str]]:
        """Ids of the planes and LCPs selected on the map."""
        return (
            self._selected_ids(self.planes_combo.currentLayer(), self.planes),
            self._selected_ids(self.lcps_combo.currentLayer(), self.lcps),
        )

    def _select_on_map(self, layer, table: dict, target_id: str) -> None:
        if layer is None or target_id not in table["ids"]:
            return
        layer.selectByIds([table["fids"][table["ids"].index(target_id)]])

    # ================================================================ overlays
    def _oriented(self) -> bool:
        return (
            self.scene_geometry is not None
            and self.scene_geometry.has_image(self.current_image)
            and self.source is not None
        )

    def refresh_overlays(self) -> None:
        """Project every overlay into the current image and redraw them."""
        self.projected = {}
        if not self._oriented():
            self.overlays.clear_all()
            self._fill_table()
            return
        sg, img = self.scene_geometry, self.current_image
        hot_planes, hot_lcps = self.highlighted()
        rings = sg.project_rings(img, self.planes["rings"])
        self.projected["rings"] = rings
        self.overlays.set_planes(rings, self.planes["ids"], hot_planes)
        a, b = sg.project(img, self.lines["a"]), sg.project(img, self.lines["b"])
        self.projected["lines"] = (a, b)
        self.overlays.set_lines(a, b, self.lines["ids"])
        lcp_px = sg.project(img, self.lcps["xyz"])
        self.projected["lcps"] = lcp_px
        self.overlays.set_lcps(lcp_px, self.lcps["ids"], hot_lcps)
        self._draw_observations()
        self._fill_table()

    def _draw_observations(self) -> None:
        rows = self.store.indices_of_image(self.current_image) if self._oriented() else []
        if self.source is None:
            rows = []
        px = np.array([[self.store.rows[k].col, self.store.rows[k].row] for k in rows]).reshape(
            -1, 2
        )
        labels = [self.store.rows[k].point_id for k in rows]
        sel = rows.index(self.selected_index) if self.selected_index in rows else -1
        self.overlays.set_observations(px, labels, sel)
        v = np.array([self.residuals.get(k, (np.nan, np.nan)) for k in rows]).reshape(-1, 2)
        self.overlays.set_residuals(px, v, self.residual_scale.value())
        pred = []
        if self.pending and self.current_image in self.pending["pixels"]:
            pred = [self.pending["pixels"][self.current_image]]
        self.overlays.set_predictions(
            np.array(pred).reshape(-1, 2), [self.pending["point_id"]] if pred else []
        )

    def _fill_table(self) -> None:
        rows = self.store.indices_of_image(self.current_image)
        self.table.blockSignals(True)
        self.table.setRowCount(len(rows))
        for r, k in enumerate(rows):
            o = self.store.rows[k]
            v = self.residuals.get(k)
            vals = (
                o.image_id,
                o.point_id,
                o.type,
                o.target_id,
                f"{o.col:.2f}",
                f"{o.row:.2f}",
                "" if v is None or not np.isfinite(v).all() else f"{math.hypot(*v):.2f}",
            )
            for c, text in enumerate(vals):
                item = QTableWidgetItem(text)
                item.setData(Qt.ItemDataRole.UserRole, k)
                self.table.setItem(r, c, item)
            if k == self.selected_index:
                self.table.selectRow(r)
        self.table.blockSignals(False)

    def _table_selection(self) -> None:
        items = self.table.selectedItems()
        if not items:
            return
        k = items[0].data(Qt.ItemDataRole.UserRole)
        self.selected_index = int(k)
        o = self.store.rows[self.selected_index]
        if o.type in ("tie", "paper"):
            self._select_on_map(self.planes_combo.currentLayer(), self.planes, o.target_id)
        elif o.type in ("lcp", "check"):
            self._select_on_map(self.lcps_combo.currentLayer(), self.lcps, o.target_id)
        self.view.centerOn(QPointF(o.col, o.row))
        self._draw_observations()

    def _store_changed(self) -> None:
        if self.selected_index >= len(self.store.rows):
            self.selected_index = -1
        self._draw_observations() if self._oriented() else self.overlays.clear("observations")
        self._fill_table()

    # ================================================================ footprint on the canvas
    def _ground_height(self) -> float:
        zs = [p[:, 2] for p in self.planes["rings"] if len(p)]
        if zs:
            return float(np.nanmean(np.concatenate(zs)))
        if len(self.lcps["xyz"]):
            return float(np.nanmean(self.lcps["xyz"][:, 2]))
        return 0.0

    def footprint(self) -> np.ndarray | None:
        """(4, 3) ground corners of the current image (EO CRS), or None."""
        sg = self.scene_geometry
        if sg is None or not sg.has_image(self.current_image):
            return None
        return sg.footprint(self.current_image, self._ground_height())

    def update_footprint(self) -> None:
        """Draw the current image's footprint on the map canvas (QgsRubberBand)."""
        canvas = self.iface.mapCanvas() if self.iface is not None else None
        if canvas is None:
            return
        if self.rubber_band is None:
            self.rubber_band = QgsRubberBand(canvas, _POLYGON_GEOMETRY)
            self.rubber_band.setStrokeColor(QColor(255, 212, 0))
            self.rubber_band.setFillColor(QColor(255, 212, 0, 40))
            self.rubber_band.setWidth(2)
        self.rubber_band.reset(_POLYGON_GEOMETRY)
        corners = self.footprint()
        if corners is None or not np.isfinite(corners).all():
            return
        dest = canvas.mapSettings().destinationCrs()
        ct = QgsCoordinateTransform(self.eo_crs(), dest, self.project)
        for k, (x, y, _z) in enumerate(corners):
            self.rubber_band.addPoint(ct.transform(QgsPointXY(x, y)), k == 3)
        self.rubber_band.show()

    def remove_footprint(self) -> None:
        if self.rubber_band is not None and self.iface is not None:
            self.iface.mapCanvas().scene().removeItem(self.rubber_band)
        self.rubber_band = None

    # ================================================================ picking
    def _choose_candidate_menu(self, candidates: list, labels: list[str]):
        """Let the user resolve an ambiguous plane (menu at the cursor); None: cancelled."""
        menu = QMenu(self)
        actions = [menu.addAction(label) for label in labels]
        chosen = menu.exec(QCursor.pos())
        return candidates[actions.index(chosen)] if chosen in actions else None

    def pick(self, col: float, row: float) -> int:
        """Handle a click at a pixel position: add an observation of the current type.

        Returns the index of the new row, or -1 (with a message) when nothing was added.
        """
        if self.source is None:
            self.message(self.tr("No image shown."), warning=True)
            return -1
        if not self._oriented():
            self.message(
                self.tr(
                    "Image {} has no orientation: picking needs the camera and the "
                    "exterior orientation."
                ).format(self.current_image),
                warning=True,
            )
            return -1
        img = self.current_image
        if self.pending is not None and img in self.pending["pixels"]:
            return self._confirm_pending(col, row)  # corrected prediction
        kind = self.type_combo.currentText()
        tol = _HIT_SCREEN_PX / max(self.view.zoom, 1e-9)
        sg = self.scene_geometry
        if kind in ("tie", "paper"):
            cands = sg.planes_under_pixel(
                img, (col, row), self.planes["rings"], self.planes["normals"], self.planes["points"]
            )
            if not cands:
                self.message(self.tr("No roof plane under the cursor."))
                return -1
            cand = cands[0]
            if len(cands) > 1:
                labels = [
                    self.tr("plane {} ({:.1f} m away)").format(
                        self.planes["ids"][c.index], c.range_m
                    )
                    for c in cands
                ]
                cand = self.choose_candidate(cands, labels)
                if cand is None:
                    return -1
            target = self.planes["ids"][cand.index]
            self._select_on_map(self.planes_combo.currentLayer(), self.planes, target)
            point_id = self.store.next_point_id(_PREFIX[kind])
            index = self.store.add(Observation(img, point_id, col, row, kind, target))
            if kind == "tie":
                pred = sg.predict_tie(
                    img,
                    (col, row),
                    self.planes["normals"][cand.index],
                    self.planes["points"][cand.index],
                )
                self.pending = {"point_id": point_id, "target": target, "pixels": pred}
                self.message(
                    self.tr(
                        "Tie {} on plane {}: predicted in {} other image(s) "
                        "(Enter accepts, click corrects)."
                    ).format(point_id, target, len(pred))
                )
            else:
                self.message(self.tr("{} on plane {}.").format(point_id, target))
        elif kind == "line":
            a, b = self.projected.get("lines", (np.empty((0, 2)), np.empty((0, 2))))
            k, _d = nearest_segment((col, row), a, b, tol)
            if k < 0:
                self.message(self.tr("No line within {:.0f} px.").format(_HIT_SCREEN_PX))
                return -1
            target = self.lines["ids"][k]
            index = self.store.add(
                Observation(img, self.store.next_point_id(f"R{target}_"), col, row, "line", target)
            )
        else:
            k, _d = nearest_point((col, row), self.projected.get("lcps", np.empty((0, 2))), tol)
            if k < 0:
                self.message(self.tr("No control point within {:.0f} px.").format(_HIT_SCREEN_PX))
                return -1
            target = self.lcps["ids"][k]
            self._select_on_map(self.lcps_combo.currentLayer(), self.lcps, target)
            prefix = "C" if kind == "lcp" else "K"
            index = self.store.add(Observation(img, f"{prefix}{target}", col, row, kind, target))
        self.selected_index = index
        self._draw_observations()
        return index

    def _confirm_pending(self, col: float, row: float) -> int:
        p = self.pending
        img = self.current_image
        index = self.store.add(Observation(img, p["point_id"], col, row, "tie", p["target"]))
        del p["pixels"][img]
        if not p["pixels"]:
            self.pending = None
        self.selected_index = index
        self._draw_observations()
        return index

    def accept_prediction(self) -> int:
        """Accept the predicted position of the pending tie point in the current image."""
        if self.pending is None or self.current_image not in self.pending["pixels"]:
            return -1
        col, row = self.pending["pixels"][self.current_image]
        return self._confirm_pending(float(col), float(row))

    def cancel_prediction(self) -> None:
        self.pending = None
        self._draw_observations()

    def _hit_observation(self, col: float, row: float, tol: float):
        rows = self.store.indices_of_image(self.current_image)
        if not rows or not self._oriented():
            return None
        px = np.array([[self.store.rows[k].col, self.store.rows[k].row] for k in rows])
        k, _d = nearest_point((col, row), px, tol)
        return rows[k] if k >= 0 else None

    def _moved(self, key, col: float, row: float) -> None:
        self.store.move(int(key), col, row)
        self.selected_index = int(key)

    def delete_selected(self) -> None:
        if 0 <= self.selected_index < len(self.store.rows):
            self.store.delete(self.selected_index)
            self.selected_index = -1

    def _cursor(self, col: float, row: float) -> None:
        if self.source is not None:
            self.status.setText(
                f"{self.current_image}  col {col:.2f}  row {row:.2f}  zoom {self.view.zoom:.3g}"
            )

    # ================================================================ observations file
    def open_observations(self, path: str) -> None:
        """Open (or create) the observation file; it is autosaved after every change."""
        if not path:
            return
        try:
            n = self.store.load(path)
        except InputError as exc:
            self.message(self.tr("Observations not loaded: {}").format(exc), warning=True)
            return
        self.residuals = {}
        self.message(self.tr("{} observation(s) in {}.").format(n, path))
        self._check_foreign_observations()
        self.save_session()

    def _check_foreign_observations(self) -> None:
        if self.eo is None or not self.store.rows:
            return
        unknown = sorted(self.store.image_ids() - set(self.eo.image_id))
        if unknown:
            n = sum(o.image_id in unknown for o in self.store.rows)
            self.message(
                self.tr(
                    "{} observation row(s) name image(s) not in the exterior "
                    "orientation ({}…): is the file from another project? They "
                    "are kept in the file but not shown."
                ).format(n, ", ".join(unknown[:3])),
                warning=True,
            )

    # ================================================================ session
    def session_values(self) -> dict:
        def layer_id(combo):
            layer = combo.currentLayer()
            return layer.id() if layer is not None else ""

        return {
            "camera": self.camera_edit.filePath(),
            "eo": self.eo_edit.filePath(),
            "observations": self.obs_edit.filePath(),
            "planes_layer": layer_id(self.planes_combo),
            "lines_layer": layer_id(self.lines_combo),
            "lcps_layer": layer_id(self.lcps_combo),
            "trajectory": self.trajectory_edit.filePath(),
            "planes_csv": self.planes_csv_edit.filePath(),
            "lines_csv": self.lines_csv_edit.filePath(),
            "lcps_csv": self.lcps_csv_edit.filePath(),
            "lever_arm": self.lever_edit.text(),
            "mount": self.mount_combo.currentText(),
            "boresight": self.boresight_edit.text(),
            "current_image": self.current_image,
            "images": [str(p) for p in self.image_paths.values()],
            "crs": self.eo_crs().authid(),
            "dsm_layer": layer_id(self.dsm_combo),
            "dsm_file": self.dsm_edit.filePath(),
            "dsm_cell": f"{self.dsm_cell.value():g}",
        }

    def save_session(self, *_args) -> None:
        if self._restoring:
            return
        values = self.session_values()
        save_session(self.project, values)
        self.project.writeEntry("lidarphoto_picking", "crs", values["crs"])

    def restore_session(self) -> None:
        """Restore the session saved in the current QGIS project (if any)."""
        s = load_session(self.project)
        crs, ok = self.project.readEntry("lidarphoto_picking", "crs", "")
        if not s:
            return
        self._restoring = True
        try:
            if ok and crs:
                self.crs_widget.setCrs(QgsCoordinateReferenceSystem(crs))
            self.camera_edit.setFilePath(s.get("camera", ""))
            self.eo_edit.setFilePath(s.get("eo", ""))
            for key, combo in (
                ("planes_layer", self.planes_combo),
                ("lines_layer", self.lines_combo),
                ("lcps_layer", self.lcps_combo),
            ):
                combo.setLayer(self.project.mapLayer(s.get(key, "")))
            self.trajectory_edit.setFilePath(s.get("trajectory", ""))
            self.planes_csv_edit.setFilePath(s.get("planes_csv", ""))
            self.lines_csv_edit.setFilePath(s.get("lines_csv", ""))
            self.lcps_csv_edit.setFilePath(s.get("lcps_csv", ""))
            self.lever_edit.setText(s.get("lever_arm", "0,0,0"))
            self.boresight_edit.setText(s.get("boresight", "0,0,0"))
            if s.get("mount"):
                self.mount_combo.setCurrentText(s["mount"])
            self.image_paths = {Path(p).stem: Path(p) for p in s.get("images", [])}
            self.images_list.clear()
            for stem, p in self.image_paths.items():
                self.images_list.addItem(f"{stem}  ({p})")
            self.current_image = s.get("current_image", "")
            self.obs_edit.setFilePath(s.get("observations", ""))
            self.dsm_combo.setLayer(self.project.mapLayer(s.get("dsm_layer", "")))
            self.dsm_edit.setFilePath(s.get("dsm_file", ""))
            try:
                self.dsm_cell.setValue(float(s.get("dsm_cell", "0.5")))
            except ValueError:
                pass
        finally:
            self._restoring = False
        if s.get("observations"):
            self.open_observations(s["observations"])
        self.reload_orientation()

    # ================================================================ monoplotting
    def monoplot_dsm_source(self) -> tuple[str, float, QgsCoordinateReferenceSystem | None]:
        """(path, LAS cell size, CRS of a raster layer or None) of the chosen DSM; path ""
        when none is chosen. A file wins over the layer."""
        path = self.dsm_edit.filePath()
        if path:
            return path, float(self.dsm_cell.value()), None
        layer = self.dsm_combo.currentLayer()
        if layer is None:
            return "", 0.0, None
        return layer.source().split("|")[0], float(self.dsm_cell.value()), layer.crs()

    def _dsm_changed(self, *_args) -> None:
        self._dsm_key = None  # loaded again at the next start
        self.save_session()
        if self.monoplot_tool.mode:
            self.set_monoplot(True)

    def _prepare_monoplot(self) -> bool:
        """Check the orientation and the DSM (load it once); False with a message."""
        if self.camera is None or self.eo is None or self.scene_geometry is None:
            self.message(
                self.tr(
                    "Monoplotting needs the camera and the exterior orientation (Project tab)."
                ),
                warning=True,
            )
            return False
        path, cell, layer_crs = self.monoplot_dsm_source()
        if not path:
            self.message(
                self.tr(
                    "Choose a DSM for monoplotting in the Project tab: a raster layer, or a "
                    "GeoTIFF or LAS/LAZ file."
                ),
                warning=True,
            )
            return False
        crs = self.eo_crs()
        # a raster layer's CRS is the one QGIS uses for it (it may have been set by the user)
        dsm_crs = layer_crs.toWkt() if layer_crs is not None and layer_crs.isValid() else None
        key = (path, cell, dsm_crs, crs.authid() or crs.toWkt())
        if key != self._dsm_key:
            try:
                QApplication.setOverrideCursor(Qt.CursorShape.WaitCursor)
                try:
                    note = self.monoplot_tool.set_dsm(path, cell, dsm_crs, crs.toWkt())
                finally:
                    QApplication.restoreOverrideCursor()
            except (InputError, OSError, ValueError) as exc:
                self.message(self.tr("DSM not loaded: {}").format(exc), warning=True)
                return False
            self._dsm_note = note  # told with the next "Monoplotting on" message
            self._dsm_key = key
        return True

    def set_monoplot(self, on: bool) -> bool:
        """Switch the monoplotting tool on (clicks -> 3D features) or off (clicks -> picking);
        returns whether it is on."""
        tool = self.monoplot_tool
        if on and not self._prepare_monoplot():
            on = False
        if on:
            self.cancel_prediction()
            mode = self.monoplot_mode.currentData() or "point"
            if tool.mode == "line":
                self.finish_monoplot_line()
            tool.start(mode)
            note, self._dsm_note = self._dsm_note, ""
            self.message(
                (note + " " if note else "")
                + self.tr(
                    "Monoplotting {}: click in the image; the 3D features appear on the map "
                    "at once.{}"
                ).format(
                    self.tr("points") if mode == "point" else self.tr("lines"),
                    self.tr(" Finish each line with Enter or a double click.")
                    if mode == "line"
                    else "",
                )
            )
        elif tool.mode:
            n = tool.finish_line() if tool.mode == "line" else 0
            tool.stop()
            self.message(
                self.tr("Monoplotting off: clicks measure observations again.")
                + (self.tr(" The line in progress was added.") if n else "")
            )
        self.monoplot_button.blockSignals(True)
        self.monoplot_button.setChecked(on)
        self.monoplot_button.blockSignals(False)
        self.finish_line_button.setEnabled(on and tool.mode == "line")
        return on

    def _monoplot_mode_changed(self, _index: int) -> None:
        if self.monoplot_tool.mode:
            self.set_monoplot(True)

    def finish_monoplot_line(self) -> int:
        """End the line being digitised; returns its number of 3D vertices."""
        try:
            n = self.monoplot_tool.finish_line()
        except (InputError, RuntimeError, ValueError) as exc:
            self.message(str(exc), warning=True)
            return 0
        if n:
            self.message(self.tr("3D line of {} vertices added.").format(n))
        return n

    def save_monoplot(self, path: str | None = None) -> list[str]:
        """Write the monoplotted points and lines to a GeoPackage (asked for when no path is
        given); returns the names of the layers written."""
        if path is None:
            start = ""
            if self.store.path is not None:
                start = str(self.store.path.with_name(self.store.path.stem + "_monoplot.gpkg"))
            path, _ = QFileDialog.getSaveFileName(
                self, self.tr("Save monoplotted features"), start, self.tr("GeoPackage (*.gpkg)")
            )
            if not path:
                return []
        try:
            names = self.monoplot_tool.save(path)
        except (OSError, RuntimeError) as exc:
            self.message(self.tr("Not saved: {}").format(exc), warning=True)
            return []
        if names:
            self.message(self.tr("Saved {} to {}.").format(", ".join(names), path))
        else:
            self.message(self.tr("Nothing monoplotted yet."))
        return names

    def eventFilter(self, watched, event) -> bool:
        """A double click in the image ends the monoplotted line (its first click has already
        added the last vertex)."""
        if (
            event.type() == QEvent.Type.MouseButtonDblClick
            and self.monoplot_tool.mode == "line"
            and watched is self.view.viewport()
        ):
            self.finish_monoplot_line()
            return True
        return super().eventFilter(watched, event)

    # ================================================================ calibration
    def calibration_parameters(self, out_dir: Path) -> dict:
        """Parameters of lidarphoto:boresightcalibration from the dock's settings."""
        kinds = {o.type for o in self.store.rows}
        tables = {
            "tie": self.planes_csv_edit.filePath(),
            "paper": "",
            "line": self.lines_csv_edit.filePath(),
            "lcp": self.lcps_csv_edit.filePath(),
        }
        types = [
            k for k, t in enumerate(("tie", "line", "lcp", "paper")) if t in kinds and tables[t]
        ]
        out_dir.mkdir(parents=True, exist_ok=True)
        return {
            "CAMERA": self.camera_edit.filePath(),
            "TRAJECTORY": self.trajectory_edit.filePath(),
            "CRS": self.eo_crs(),
            "LEVER_ARM": self.lever_edit.text(),
            "MOUNT": max(0, self.mount_combo.currentIndex()),
            "BORESIGHT": self.boresight_edit.text(),
            "OBSERVATIONS": str(self.store.path),
            "PLANES": self.planes_csv_edit.filePath() or None,
            "LINES": self.lines_csv_edit.filePath() or None,
            "LCPS": self.lcps_csv_edit.filePath() or None,
            "CONTROL_TYPES": types,
            "OUTPUT_TABLE": str(out_dir / "boresight.csv"),
            "OUTPUT_RESIDUALS": "TEMPORARY_OUTPUT",
            "RESIDUALS_CSV": str(out_dir / "residuals.csv"),
            "OUTPUT_EO": str(out_dir / "eo_calibrated.csv"),
            "OUTPUT_HTML": str(out_dir / "summary.html"),
        }

    def run_calibration(self) -> bool:
        """Run the boresight calibration in a background task; False if it cannot start."""
        if self._task is not None:
            self.message(self.tr("A calibration is already running."))
            return False
        if self.store.path is None or not self.store.rows:
            self.message(self.tr("No observations to calibrate with."), warning=True)
            return False
        if not self.store.save():
            return False
        alg = QgsApplication.processingRegistry().createAlgorithmById(CALIBRATION_ALG)
        if alg is None:
            self.message(self.tr("{} is not available.").format(CALIBRATION_ALG), warning=True)
            return False
        out_dir = self.store.path.with_name(self.store.path.stem + "_calibration")
        params = self.calibration_parameters(out_dir)
        if not params["CONTROL_TYPES"]:
            self.message(
                self.tr("Give the plane, line or LCP table of the observed types."), warning=True
            )
            return False
        self._context = QgsProcessingContext()
        self._context.setProject(self.project)
        self._feedback = QgsProcessingFeedback()
        self._task = QgsProcessingAlgRunnerTask(alg, params, self._context, self._feedback)
        self._task.executed.connect(self._calibration_done)
        self._params = params
        self.run_button.setEnabled(False)
        self.result_label.setText(self.tr("Calibration running…"))
        QgsApplication.taskManager().addTask(self._task)
        return True

    def _calibration_done(self, ok: bool, results: dict) -> None:
        self._task = None
        self.run_button.setEnabled(True)
        if not ok:
            log = self._feedback.textLog() if hasattr(self._feedback, "textLog") else ""
            text = self.tr("Calibration failed. {}").format(" ".join(log.strip().splitlines()[-1:]))
            self.result_label.setText(text)
            self.message(text, warning=True)
            self.calibrationFinished.emit(False)
            return
        self.calibration_results = dict(results)
        lines = []
        with open(self._params["OUTPUT_TABLE"], encoding="utf-8") as fh:
            for r in csv.DictReader(fh):
                lines.append(
                    f'{r["group"]}: dω {float(r["d_omega_arcsec"]):.1f}" '
                    f'dφ {float(r["d_phi_arcsec"]):.1f}" dκ {float(r["d_kappa_arcsec"]):.1f}" '
                    f"(σ0 {float(r['sigma0']):.2f})"
                )
        self.residuals = {}
        with open(self._params["RESIDUALS_CSV"], encoding="utf-8") as fh:
            rows = list(csv.DictReader(fh))
        keyed = {}
        for r in rows:
            keyed.setdefault((r["image_id"], r["point_id"], r["type"], r["target_id"]), []).append(
                r
            )
        for k, o in enumerate(self.store.rows):
            cand = keyed.get((o.image_id, o.point_id, o.type, o.target_id))
            if cand:
                r = cand.pop(0)
                try:
                    self.residuals[k] = np.array([float(r["vx_px"]), float(r["vy_px"])])
                except ValueError:
                    continue
        v = np.array([math.hypot(*x) for x in self.residuals.values() if np.isfinite(x).all()])
        if v.size:
            lines.append(
                self.tr("{} residuals: RMS {:.2f} px, max {:.2f} px").format(
                    v.size, float(np.sqrt(np.mean(v**2))), float(v.max())
                )
            )
        self.result_label.setText("\n".join(lines))
        self.message(self.tr("Calibration done: {}").format(self._params["OUTPUT_HTML"]))
        self._draw_observations()
        self._fill_table()
        self.calibrationFinished.emit(True)

    def _project_read(self, _document) -> None:
        self.restore_session()

    def closeEvent(self, event) -> None:
        self.store.save()
        if self.monoplot_tool.mode:
            self.set_monoplot(False)
        super().closeEvent(event)
