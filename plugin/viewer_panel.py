"""The image viewer of the picking dock: the tool row (image selector, picking type, monoplot,
undo/redo, magnifier, help), the overlay switches, the :class:`ImageView` with its
:class:`Overlays` and the status line."""

from __future__ import annotations

from pathlib import Path

from qgis.core import QgsApplication
from qgis.PyQt.QtCore import pyqtSignal
from qgis.PyQt.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDoubleSpinBox,
    QHBoxLayout,
    QLabel,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from ..core.photo.picking_session import PICK_TYPES
from .image_source import ImageSource, ImageSourceError, error_text
from .image_view import ImageView
from .overlays import GROUPS, Overlays

__all__ = ["ViewerPanel"]


def _tool(text: str = "", icon: str = "", tip: str = "", checkable: bool = False) -> QToolButton:
    button = QToolButton()
    if text:
        button.setText(text)
    if icon:
        button.setIcon(QgsApplication.getThemeIcon(icon))
    button.setToolTip(tip)
    button.setCheckable(checkable)
    return button


class ViewerPanel(QWidget):
    """Viewer and its tools.

    Signals
    -------
    imageSelected(str)
        An image was chosen in the selector (or with the arrows): its id.
    """

    imageSelected = pyqtSignal(str)  # noqa: N815 - Qt signal naming

    def __init__(self, help_text: str, parent=None) -> None:
        super().__init__(parent)
        vl = QVBoxLayout(self)
        vl.setContentsMargins(0, 0, 0, 0)
        row = QHBoxLayout()
        self.prev_button = _tool("◀")
        self.next_button = _tool("▶")
        self.image_combo = QComboBox()
        self.image_combo.setMinimumContentsLength(10)
        self.type_combo = QComboBox()
        self.type_combo.addItems(list(PICK_TYPES))
        self.type_combo.setToolTip(self.tr("Type of the next point (T/P/L/C/K)"))
        self.undo_button = _tool(icon="/mActionUndo.svg", tip=self.tr("Undo (Ctrl+Z)"))
        self.redo_button = _tool(icon="/mActionRedo.svg", tip=self.tr("Redo (Ctrl+Shift+Z)"))
        self.magnifier_button = _tool(
            icon="/mActionZoomIn.svg", tip=self.tr("Magnifier (M)"), checkable=True
        )
        self.help_button = _tool("?", tip=help_text)
        self.monoplot_button = _tool(
            self.tr("Monoplot"),
            tip=self.tr(
                "Monoplotting: clicks become 3D points (or line vertices) on the DSM, added to "
                "the map at once; off: clicks measure observations again"
            ),
            checkable=True,
        )
        self.monoplot_button.setObjectName("lidarphotoMonoplot")
        self.monoplot_mode = QComboBox()
        self.monoplot_mode.setObjectName("lidarphotoMonoplotMode")
        self.monoplot_mode.addItem(self.tr("points"), "point")
        self.monoplot_mode.addItem(self.tr("lines"), "line")
        self.monoplot_mode.setToolTip(self.tr("Monoplot points, or lines (finish: Enter)"))
        self.finish_line_button = _tool(
            self.tr("Finish line"),
            tip=self.tr("End the line being digitised (also Enter or a double click)"),
        )
        self.finish_line_button.setEnabled(False)
        self.save_monoplot_button = _tool(
            icon="/mActionFileSave.svg",
            tip=self.tr("Save the monoplotted points and lines to a GeoPackage"),
        )
        self.refine_button = _tool(
            self.tr("Refine"),
            tip=self.tr(
                "Snap the selected point to the least-squares match (6 affine + 2 radiometric "
                "parameters) of the same point measured in another image"
            ),
        )
        self.refine_button.setObjectName("lidarphotoRefineLsm")
        for w in (self.prev_button, self.image_combo, self.next_button, self.type_combo):
            row.addWidget(w)
        row.addWidget(self.refine_button)
        row.addStretch(1)
        for w in (
            self.monoplot_button,
            self.monoplot_mode,
            self.finish_line_button,
            self.save_monoplot_button,
            self.undo_button,
            self.redo_button,
            self.magnifier_button,
            self.help_button,
        ):
            row.addWidget(w)
        vl.addLayout(row)
        toggles = QHBoxLayout()
        self.overlay_checks: dict[str, QCheckBox] = {}
        labels = {  # literal strings: pylupdate cannot collect tr() of a variable
            "planes": self.tr("planes"),
            "lines": self.tr("lines"),
            "lcps": self.tr("lcps"),
            "residuals": self.tr("residuals"),
            "observations": self.tr("observations"),
            "predictions": self.tr("predictions"),
        }
        for name in GROUPS:
            box = QCheckBox(labels[name])
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
        self.overlays = Overlays(self.view.scene())
        self.view.zoomChanged.connect(self.overlays.set_zoom)
        self.source: ImageSource | None = None

        self.image_combo.currentIndexChanged.connect(self._combo_changed)
        self.prev_button.clicked.connect(self.previous_image)
        self.next_button.clicked.connect(self.next_image)
        self.magnifier_button.toggled.connect(self.view.magnifier.setVisible)
        for name, box in self.overlay_checks.items():
            box.toggled.connect(lambda on, n=name: self.overlays.set_visible(n, on))

    # -- the image selector -------------------------------------------------------------------
    def _status_text(self, status: str) -> str:
        """An image status code of the dock ("no orientation", ...) as the user reads it."""
        texts = {
            "no orientation": self.tr("no orientation"),
            "no file": self.tr("no file"),
            "missing on disk": self.tr("missing on disk"),
        }
        return texts.get(status, status)

    def fill_images(self, items: list[tuple[str, str]]) -> None:
        """The selector's images: (id, status) pairs; a status other than "ok" is shown."""
        self.image_combo.blockSignals(True)
        self.image_combo.clear()
        for image_id, status in items:
            label = image_id if status == "ok" else f"{image_id} ({self._status_text(status)})"
            self.image_combo.addItem(label, image_id)
        self.image_combo.blockSignals(False)

    def image_ids(self) -> list[str]:
        return [self.image_combo.itemData(k) for k in range(self.image_combo.count())]

    def select(self, image_id: str) -> None:
        """Show an image id in the selector without signalling."""
        k = self.image_combo.findData(image_id)
        if k >= 0 and k != self.image_combo.currentIndex():
            self.image_combo.blockSignals(True)
            self.image_combo.setCurrentIndex(k)
            self.image_combo.blockSignals(False)

    def _combo_changed(self, index: int) -> None:
        if index >= 0:
            self.imageSelected.emit(self.image_combo.itemData(index))

    def next_image(self) -> None:
        n = self.image_combo.count()
        if n:
            self.image_combo.setCurrentIndex((self.image_combo.currentIndex() + 1) % n)

    def previous_image(self) -> None:
        n = self.image_combo.count()
        if n:
            self.image_combo.setCurrentIndex((self.image_combo.currentIndex() - 1) % n)

    # -- the image ----------------------------------------------------------------------------
    def open(
        self, image_id: str, path: Path | None, oriented: bool, camera
    ) -> tuple[bool, str, bool]:
        """Show an image file in the view: (shown, message, warning)."""
        if self.source is not None:
            self.source.close()
            self.source = None
        if path is None or not path.is_file():
            self.view.set_source(None)
            where = self.tr("file missing on disk") if path else self.tr("no image file")
            hint = path or self.tr("add it with Images > Add")
            return False, self.tr("Image {}: {} ({}).").format(image_id, where, hint), True
        try:
            # the stretch (a whole-image read) is computed by the view's worker thread
            self.source = ImageSource(path, stretch_now=False)
        except ImageSourceError as exc:
            self.view.set_source(None)
            return False, error_text(exc), True
        self.view.set_source(self.source)
        src = self.source
        if not oriented:
            text = self.tr("Image {} has no exterior orientation: no overlays, no picking.")
            return True, text.format(image_id), True
        if camera is not None and (src.width, src.height) != (camera.width_px, camera.height_px):
            text = self.tr("Image {} is {} x {} px but the camera is {} x {} px.").format(
                image_id, src.width, src.height, camera.width_px, camera.height_px
            )
            return True, text, True
        text = self.tr("Image {}: {} x {} px, {} band(s), {}.").format(
            image_id, src.width, src.height, src.bands, src.dtype
        )
        return True, text, False
