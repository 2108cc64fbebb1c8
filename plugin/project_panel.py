"""The Project tab of the picking dock: camera, exterior orientation and its CRS, images, the
plane/line/LCP layers, the observation file and the monoplotting DSM."""

from __future__ import annotations

from pathlib import Path

from qgis.core import QgsCoordinateReferenceSystem, QgsMapLayerProxyModel
from qgis.gui import QgsFileWidget, QgsMapLayerComboBox, QgsProjectionSelectionWidget
from qgis.PyQt.QtCore import pyqtSignal
from qgis.PyQt.QtWidgets import (
    QDoubleSpinBox,
    QFileDialog,
    QFormLayout,
    QHBoxLayout,
    QListWidget,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

__all__ = ["ProjectPanel"]

_LAYER_KEYS = {"planes": "planes_layer", "lines": "lines_layer", "lcps": "lcps_layer"}


def _layer_combo(filters, allow_empty: bool = True) -> QgsMapLayerComboBox:
    combo = QgsMapLayerComboBox()
    combo.setFilters(filters)
    combo.setAllowEmptyLayer(allow_empty)
    combo.setLayer(None)
    return combo


class ProjectPanel(QWidget):
    """The project inputs.

    Signals
    -------
    orientationChanged()
        The camera, the EO table or its CRS changed.
    layersChanged()
        A plane, line or LCP layer was chosen.
    imagesChosen(list)
        Image files added with the *Add* button (with those already there).
    observationsChosen(str)
        The observation file.
    dsmChanged()
        The DSM layer, file or cell size changed.
    """

    orientationChanged = pyqtSignal()  # noqa: N815 - Qt signal naming
    layersChanged = pyqtSignal()  # noqa: N815
    imagesChosen = pyqtSignal(list)  # noqa: N815
    observationsChosen = pyqtSignal(str)  # noqa: N815
    dsmChanged = pyqtSignal()  # noqa: N815

    def __init__(self, project, parent=None) -> None:
        super().__init__(parent)
        form = QFormLayout(self)
        self.camera_edit = QgsFileWidget()
        self.camera_edit.setFilter(self.tr("Camera JSON (*.json)"))
        self.eo_edit = QgsFileWidget()
        self.eo_edit.setFilter(self.tr("EO CSV (*.csv *.txt)"))
        self.eo_edit.setToolTip(self.tr("Exterior orientation from 'Trajectory to EO'"))
        self.crs_widget = QgsProjectionSelectionWidget()
        self.crs_widget.setCrs(project.crs())
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
        self.planes_combo = _layer_combo(QgsMapLayerProxyModel.Filter.PolygonLayer)
        self.lines_combo = _layer_combo(QgsMapLayerProxyModel.Filter.LineLayer)
        self.lcps_combo = _layer_combo(QgsMapLayerProxyModel.Filter.PointLayer)
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
        self.dsm_combo = _layer_combo(QgsMapLayerProxyModel.Filter.RasterLayer)
        self.dsm_combo.setObjectName("lidarphotoDsmLayer")
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
        self.image_paths: dict[str, Path] = {}

        # the panel's own signals: blocking them (restoring a session) silences the panel
        for w in (self.camera_edit, self.eo_edit):
            w.fileChanged.connect(lambda *_: self.orientationChanged.emit())
        self.crs_widget.crsChanged.connect(lambda *_: self.orientationChanged.emit())
        for combo in self.layer_combos().values():
            combo.layerChanged.connect(lambda *_: self.layersChanged.emit())
        self.obs_edit.fileChanged.connect(self.observationsChosen.emit)
        self.add_images_button.clicked.connect(self._ask_images)
        self.clear_images_button.clicked.connect(lambda: self.imagesChosen.emit([]))
        self.dsm_combo.layerChanged.connect(lambda *_: self.dsmChanged.emit())
        self.dsm_edit.fileChanged.connect(lambda *_: self.dsmChanged.emit())
        self.dsm_cell.editingFinished.connect(self.dsmChanged.emit)

    def layer_combos(self) -> dict[str, QgsMapLayerComboBox]:
        return {"planes": self.planes_combo, "lines": self.lines_combo, "lcps": self.lcps_combo}

    def layers(self) -> dict:
        """The chosen plane, line and LCP layers (None: none)."""
        return {kind: combo.currentLayer() for kind, combo in self.layer_combos().items()}

    def crs(self) -> QgsCoordinateReferenceSystem:
        return self.crs_widget.crs()

    def _ask_images(self) -> None:
        files, _ = QFileDialog.getOpenFileNames(
            self,
            self.tr("Images"),
            "",
            self.tr("Images (*.tif *.tiff *.jpg *.jpeg *.png *.jp2 *.vrt *.img);;All files (*)"),
        )
        if files:
            self.imagesChosen.emit(sorted(set(map(str, self.image_paths.values())) | set(files)))

    def set_images(self, paths) -> dict[str, Path]:
        """Image files by id (each is matched to the EO row whose image_id is its stem)."""
        self.image_paths = {Path(p).stem: Path(p) for p in paths}
        self.images_list.clear()
        for stem, p in self.image_paths.items():
            self.images_list.addItem(f"{stem}  ({p})")
        return self.image_paths

    def dsm_source(self) -> tuple[str, float, QgsCoordinateReferenceSystem | None]:
        """(path, LAS cell size, CRS of a raster layer or None) of the chosen DSM; path ""
        when none is chosen. A file wins over the layer."""
        path = self.dsm_edit.filePath()
        if path:
            return path, float(self.dsm_cell.value()), None
        layer = self.dsm_combo.currentLayer()
        if layer is None:
            return "", 0.0, None
        return layer.source().split("|")[0], float(self.dsm_cell.value()), layer.crs()

    # -- session ------------------------------------------------------------------------------
    def values(self) -> dict:
        """The panel's part of the session (see ``observation_store.SESSION_KEYS``)."""

        def layer_id(combo):
            layer = combo.currentLayer()
            return layer.id() if layer is not None else ""

        out = {
            "camera": self.camera_edit.filePath(),
            "eo": self.eo_edit.filePath(),
            "observations": self.obs_edit.filePath(),
            "images": [str(p) for p in self.image_paths.values()],
            "crs": self.crs().authid(),
            "dsm_layer": layer_id(self.dsm_combo),
            "dsm_file": self.dsm_edit.filePath(),
            "dsm_cell": f"{self.dsm_cell.value():g}",
        }
        for kind, combo in self.layer_combos().items():
            out[_LAYER_KEYS[kind]] = layer_id(combo)
        return out

    def restore(self, s: dict, project, crs: str = "") -> None:
        """Set the widgets from a stored session (call with the panel's signals blocked)."""
        if crs:
            self.crs_widget.setCrs(QgsCoordinateReferenceSystem(crs))
        self.camera_edit.setFilePath(s.get("camera", ""))
        self.eo_edit.setFilePath(s.get("eo", ""))
        for kind, combo in self.layer_combos().items():
            combo.setLayer(project.mapLayer(s.get(_LAYER_KEYS[kind], "")))
        self.set_images(s.get("images", []))
        self.obs_edit.setFilePath(s.get("observations", ""))
        self.dsm_combo.setLayer(project.mapLayer(s.get("dsm_layer", "")))
        self.dsm_edit.setFilePath(s.get("dsm_file", ""))
        try:
            self.dsm_cell.setValue(float(s.get("dsm_cell", "0.5")))
        except ValueError:
            pass
