"""What the picking dock's Project and Calibration tabs name, loaded into its core session once:
the camera and exterior orientation (the picking scene), the control of the layers and tables,
the observation file; and the tabs kept in the QGIS project (the session, restored on reading
the project)."""

from __future__ import annotations

from collections import deque

from qgis.core import QgsCoordinateReferenceSystem
from qgis.PyQt import sip
from qgis.PyQt.QtCore import QCoreApplication, QObject, QTimer

from ..core.errors import InputError
from ..core.geometry.projection import PROJECTIONS
from ..core.io.camera import read_camera_json
from ..core.io.orientation import read_eo_csv
from .control_layers import ControlLinks, read_control, read_tables
from .observation_store import SESSION_SCOPE, gc_deferred, load_session, save_session

__all__ = ["ProjectLoader"]


class ProjectLoader(QObject):
    """Loads the inputs of a picking dock into ``dock.session`` and keeps its session."""

    def __init__(self, dock) -> None:
        super().__init__(dock)
        self.dock = dock
        self.session, self.store = dock.session, dock.store
        self.inputs, self.settings = dock.project_panel, dock.calibration_panel
        #: the layer feature of each target id (map selection)
        self.links = ControlLinks()
        self.restoring = False
        self._steps: deque = deque()
        self._generation = 0
        self._holding = False  # the markers wait for the last step of a restore

    def tr(self, text: str) -> str:
        return QCoreApplication.translate("ProjectLoader", text)  # the context lupdate gives it

    # -- orientation and control --------------------------------------------------------------
    def set_project_files(self, camera="", eo="", crs="", images=(), observations="") -> None:
        """Set the main inputs in one go (what the widgets do one by one)."""
        p = self.inputs
        p.blockSignals(True)
        try:
            if crs:
                p.crs_widget.setCrs(QgsCoordinateReferenceSystem(crs))
            p.camera_edit.setFilePath(str(camera))
            p.eo_edit.setFilePath(str(eo))
        finally:
            p.blockSignals(False)
        self.reload_orientation()
        if images:
            self.dock.set_images(images)
        if observations:
            p.obs_edit.setFilePath(str(observations))

    def reload_orientation(self) -> None:
        """Read the camera and the EO table; rebuild the picking scene (then the control and
        the image shown)."""
        if self.restoring:
            return
        self.read_orientation()
        self.reload_control()
        self.show_images()

    def show_images(self) -> None:
        """Fill the image selector and show the current image (with its overlays)."""
        self.dock.fill_images()
        self.check_foreign_observations()
        self.save()

    def read_orientation(self) -> None:
        """Read the camera and the EO table into the session (its picking scene)."""
        cam_path, eo_path = self.inputs.camera_edit.filePath(), self.inputs.eo_edit.filePath()
        crs = self.inputs.crs()
        self.session.set_orientation(None, None)
        try:
            # perspective or fisheye: a fisheye's lines and outlines are drawn as the curves
            # they image as (core.photo.picking), image lines measured as points on those
            # curves (PickingSession.lines_curved)
            camera = read_camera_json(cam_path, projections=PROJECTIONS) if cam_path else None
            eo = read_eo_csv(eo_path, crs.toWkt()) if eo_path else None
            # keeps the camera and the table when the scene cannot be made (e.g. no CRS)
            self.session.set_orientation(camera, eo, crs.authid() or crs.toWkt())
        except (InputError, OSError, ValueError) as exc:
            self.dock.message(self.tr("Orientation not loaded: {}").format(exc), warning=True)

    def use_orientation(self, eo, path: str) -> None:
        """Take an exterior orientation table already in memory (the calibrated one); the
        Project tab names ``path``, the file it was written to."""
        p = self.inputs
        p.blockSignals(True)
        try:
            p.eo_edit.setFilePath(str(path))
        finally:
            p.blockSignals(False)
        crs = p.crs()
        try:
            self.session.set_orientation(self.session.camera, eo, crs.authid() or crs.toWkt())
        except InputError as exc:
            self.dock.message(self.tr("Orientation not loaded: {}").format(exc), warning=True)
        self.dock.fill_images()
        self.save()

    def reload_control(self) -> None:
        """Read the plane, line and LCP layers (and tables) into the session's control."""
        try:
            tables = read_tables(*self.settings.table_paths())
        except (InputError, OSError) as exc:
            self.dock.message(self.tr("Control table not read: {}").format(exc), warning=True)
            tables = (None, None, None)
        layers = self.inputs.layers()
        control, self.links = read_control(layers, tables, self.inputs.crs(), self.dock.project)
        self.session.control = control
        skipped = control.skipped.get("planes", 0)
        if skipped:
            text = self.tr("{} plane(s) of {} have no heights and no a,b,c,d fields: skipped.")
            self.dock.message(text.format(skipped, layers["planes"].name()), warning=True)
        for layer in (layers["planes"], layers["lcps"]):
            if layer is not None:
                try:
                    layer.selectionChanged.disconnect(self.dock.picking.selection_changed)
                except TypeError:
                    pass
                layer.selectionChanged.connect(self.dock.picking.selection_changed)
        self.dock.picking.refresh()
        self.save()

    # -- observations -------------------------------------------------------------------------
    def open_observations(self, path: str) -> None:
        """Open (or create) the observation file; it is autosaved after every change."""
        if not path:
            return
        try:
            n = self.store.load(path)
        except InputError as exc:
            self.dock.message(self.tr("Observations not loaded: {}").format(exc), warning=True)
            return
        self.session.set_calibration(None)  # its residuals were of the rows before
        self.dock.picking.store_changed()
        self.dock.message(self.tr("{} observation(s) in {}.").format(n, path))
        self.check_foreign_observations()
        self.save()

    def check_foreign_observations(self) -> None:
        eo = self.session.eo
        if eo is None or not self.store.rows:
            return
        unknown = sorted(self.store.image_ids() - set(eo.image_id))
        if unknown:
            n = sum(o.image_id in unknown for o in self.store.rows)
            self.dock.message(
                self.tr(
                    "{} observation row(s) name image(s) not in the exterior "
                    "orientation ({}…): is the file from another project? They "
                    "are kept in the file but not shown."
                ).format(n, ", ".join(unknown[:3])),
                warning=True,
            )

    # -- the session in the QGIS project ------------------------------------------------------
    def values(self) -> dict:
        values = self.inputs.values()
        values.update(self.settings.values())
        values["current_image"] = self.dock.current_image
        return values

    def save(self) -> None:
        if self.restoring:
            return
        values = self.values()
        project = self.dock.project
        save_session(project, values)
        project.writeEntry(SESSION_SCOPE, "crs", values["crs"])

    def restore(self) -> None:
        """Restore the session saved in the current QGIS project (if any).

        The tabs are filled at once; the files are read in steps, each in its own turn of
        the event loop, so that QGIS never waits for all of them together (the dock is on
        screen after the first): the observation file, the orientation, the control, the
        image with its overlays, then the observation markers (:attr:`steps_left` counts
        the steps not run yet; :meth:`ImagePickingDock.wait_restored` waits for them).
        """
        project = self.dock.project
        s = load_session(project)
        crs, ok = project.readEntry(SESSION_SCOPE, "crs", "")
        self._generation += 1  # (the steps of an earlier restore are dropped)
        self._steps.clear()
        if not s:
            self._finish_steps()
            return
        panels = (self.inputs, self.settings)
        self.restoring = True
        for panel in panels:
            panel.blockSignals(True)
        try:
            self.inputs.restore(s, project, crs if ok else "")
            self.settings.restore(s)
            self.dock.current_image = s.get("current_image", "")
        finally:
            for panel in panels:
                panel.blockSignals(False)
            self.restoring = False
        if s.get("observations"):
            self._steps.append(lambda: self.open_observations(s["observations"]))
        self._steps += [self.read_orientation, self.reload_control, self.show_images]
        if not self._holding:
            self._holding = True
            self.dock.picking.hold_markers()  # drawn after the last step, in its own turn
        QTimer.singleShot(0, lambda gen=self._generation: self._next_step(gen))

    @property
    def steps_left(self) -> int:
        """Steps of a restore not run yet (0: restored)."""
        return len(self._steps)

    def _next_step(self, generation: int) -> None:
        if generation != self._generation or not self._steps:
            return
        if sip.isdeleted(self.dock) or sip.isdeleted(self):  # closed and deleted meanwhile
            self._steps.clear()
            return
        step = self._steps.popleft()
        try:
            with gc_deferred():  # (many short-lived objects: see gc_deferred)
                step()
        except Exception as exc:  # a slot must not raise: say it, go on with the next step
            self.dock.message(
                self.tr("The session was not fully restored: {}").format(exc), warning=True
            )
        if self._steps:
            QTimer.singleShot(0, lambda: self._next_step(generation))
        else:
            self._finish_steps()

    def _finish_steps(self) -> None:
        if self._holding:
            self._holding = False
            self.dock.picking.release_markers()
