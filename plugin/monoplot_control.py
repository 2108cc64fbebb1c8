"""The picking dock's side of monoplotting: the Monoplot button and mode, the DSM of the Project
tab (loaded once per choice), finishing lines (Enter, a double click, the button) and saving.
The clicks themselves are handled by :class:`~.monoplot_tool.MonoplotTool`."""

from __future__ import annotations

from qgis.PyQt.QtCore import QCoreApplication, QEvent, QObject, Qt
from qgis.PyQt.QtWidgets import QApplication, QFileDialog

from ..core.errors import InputError

__all__ = ["MonoplotController"]


class MonoplotController(QObject):
    """Switches the dock's clicks between picking and the monoplotting ``tool``."""

    def __init__(self, dock, tool) -> None:
        super().__init__(dock)
        self.dock, self.tool = dock, tool
        self.inputs, self.viewer = dock.project_panel, dock.viewer
        self._dsm_key: tuple | None = None
        self._dsm_note = ""
        self.inputs.dsmChanged.connect(self._dsm_changed)
        v = self.viewer
        v.monoplot_button.toggled.connect(self.set_monoplot)
        v.monoplot_mode.currentIndexChanged.connect(self._mode_changed)
        v.finish_line_button.clicked.connect(self.finish_line)
        v.save_monoplot_button.clicked.connect(lambda: self.save())
        v.view.viewport().installEventFilter(self)

    def tr(self, text: str) -> str:
        return QCoreApplication.translate(
            "MonoplotController", text
        )  # the context lupdate gives it

    def _dsm_changed(self) -> None:
        self._dsm_key = None  # loaded again at the next start
        if self.tool.mode:
            self.set_monoplot(True)

    def _prepare(self) -> bool:
        """Check the orientation and the DSM (load it once); False with a message."""
        dock = self.dock
        if dock.camera is None or dock.eo is None or dock.scene_geometry is None:
            dock.message(
                self.tr(
                    "Monoplotting needs the camera and the exterior orientation (Project tab)."
                ),
                warning=True,
            )
            return False
        path, cell, layer_crs = self.inputs.dsm_source()
        if not path:
            dock.message(
                self.tr(
                    "Choose a DSM for monoplotting in the Project tab: a raster layer, or a "
                    "GeoTIFF or LAS/LAZ file."
                ),
                warning=True,
            )
            return False
        crs = dock.eo_crs()
        # a raster layer's CRS is the one QGIS uses for it (it may have been set by the user)
        dsm_crs = layer_crs.toWkt() if layer_crs is not None and layer_crs.isValid() else None
        key = (path, cell, dsm_crs, crs.authid() or crs.toWkt())
        if key != self._dsm_key:
            try:
                QApplication.setOverrideCursor(Qt.CursorShape.WaitCursor)
                try:
                    note = self.tool.set_dsm(path, cell, dsm_crs, crs.toWkt())
                finally:
                    QApplication.restoreOverrideCursor()
            except (InputError, OSError, ValueError) as exc:
                dock.message(self.tr("DSM not loaded: {}").format(exc), warning=True)
                return False
            self._dsm_note = note  # told with the next "Monoplotting on" message
            self._dsm_key = key
        return True

    def set_monoplot(self, on: bool) -> bool:
        """Switch the monoplotting tool on (clicks -> 3D features) or off (clicks -> picking);
        returns whether it is on."""
        tool, dock = self.tool, self.dock
        if on and not self._prepare():
            on = False
        if on:
            dock.cancel_prediction()
            mode = self.viewer.monoplot_mode.currentData() or "point"
            if tool.mode == "line":
                self.finish_line()
            tool.start(mode)
            note, self._dsm_note = self._dsm_note, ""
            dock.message(
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
            dock.message(
                self.tr("Monoplotting off: clicks measure observations again.")
                + (self.tr(" The line in progress was added.") if n else "")
            )
        button = self.viewer.monoplot_button
        button.blockSignals(True)
        button.setChecked(on)
        button.blockSignals(False)
        self.viewer.finish_line_button.setEnabled(on and tool.mode == "line")
        return on

    def _mode_changed(self, _index: int) -> None:
        if self.tool.mode:
            self.set_monoplot(True)

    def finish_line(self) -> int:
        """End the line being digitised; returns its number of 3D vertices."""
        try:
            n = self.tool.finish_line()
        except (InputError, RuntimeError, ValueError) as exc:
            self.dock.message(str(exc), warning=True)
            return 0
        if n:
            self.dock.message(self.tr("3D line of {} vertices added.").format(n))
        return n

    def save(self, path: str | None = None) -> list[str]:
        """Write the monoplotted points and lines to a GeoPackage (asked for when no path is
        given); returns the names of the layers written."""
        dock = self.dock
        if path is None:
            start = ""
            obs = dock.store.path
            if obs is not None:
                start = str(obs.with_name(obs.stem + "_monoplot.gpkg"))
            path, _ = QFileDialog.getSaveFileName(
                dock, self.tr("Save monoplotted features"), start, self.tr("GeoPackage (*.gpkg)")
            )
            if not path:
                return []
        try:
            names = self.tool.save(path)
        except (OSError, RuntimeError) as exc:
            dock.message(self.tr("Not saved: {}").format(exc), warning=True)
            return []
        if names:
            dock.message(self.tr("Saved {} to {}.").format(", ".join(names), path))
        else:
            dock.message(self.tr("Nothing monoplotted yet."))
        return names

    def eventFilter(self, watched, event) -> bool:
        """A double click in the image ends the monoplotted line (its first click has already
        added the last vertex)."""
        if (
            event.type() == QEvent.Type.MouseButtonDblClick
            and self.tool.mode == "line"
            and watched is self.viewer.view.viewport()
        ):
            self.finish_line()
            return True
        return super().eventFilter(watched, event)
