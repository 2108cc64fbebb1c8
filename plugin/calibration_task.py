"""The boresight calibration of the picking dock, run in a background ``QgsTask``.

The task writes the control the dock shows (the core objects of its
:class:`~lidarphoto.core.photo.picking_session.ControlSet`) to plane, line and LCP tables in the
calibration folder, then runs the core job ``boresight_calibration`` (what the toolbox's
``lidarphoto:boresightcalibration`` runs) on them and the saved observation file. The job writes
``boresight.csv``, ``eo_calibrated.csv``, ``residuals.csv`` and ``summary.html``; the dock
displays the result object it returns
(:class:`~lidarphoto.core.photo.boresight_result.BoresightRun`), not those files.
"""

from __future__ import annotations

from pathlib import Path

from ..core.io.control import write_lcps_csv, write_lines_csv
from ..core.io.planes import write_planes_csv
from ..core.jobs import boresight_calibration
from ..core.jobs.runner import JobResult
from .job_task import JobController

__all__ = ["CalibrationController", "calibration_parameters", "flight_parameters"]

#: observation type -> the control list it needs ("paper" needs the cloud: not from the dock)
_NEEDS = {"tie": 0, "line": 1, "lcp": 2}


def flight_parameters(settings: dict, crs: str) -> dict:
    """The parameters both calibrations of the dock share: the camera file, the Calibration
    tab's trajectory, lever arm, mount and approximate boresight, the mapping CRS."""
    return {
        "CAMERA": settings["camera"],
        "TRAJECTORY": settings["trajectory"],
        "CRS": crs,
        "LEVER_ARM": settings["lever_arm"],
        "MOUNT": settings["mount"],
        "BORESIGHT": settings["boresight"],
    }


def calibration_parameters(
    out_dir: Path, settings: dict, observations: Path, crs: str, control: tuple, kinds: set
) -> dict:
    """Parameters of the core job ``boresight_calibration``.

    Parameters
    ----------
    out_dir : Path
        Folder of the outputs and of the control tables written for the job.
    settings : dict
        The Calibration tab's values (``trajectory``, ``lever_arm``, ``mount``,
        ``boresight``) and the ``camera`` file.
    observations : Path
        The (saved) observation file.
    crs : str
        Mapping CRS, authority id or WKT.
    control : tuple of list
        Planes, lines, LCPs (``ControlSet.for_calibration``).
    kinds : set of str
        The observation types present.
    """
    names = ("control_planes.csv", "control_lines.csv", "control_lcps.csv")
    tables = [str(out_dir / n) if items else None for n, items in zip(names, control)]
    return {
        **flight_parameters(settings, crs),
        "OBSERVATIONS": str(observations),
        "PLANES": tables[0],
        "LINES": tables[1],
        "LCPS": tables[2],
        "CONTROL_TYPES": [t for t, k in _NEEDS.items() if t in kinds and control[k]],
        "OUTPUT_TABLE": str(out_dir / "boresight.csv"),
        "RESIDUALS_CSV": str(out_dir / "residuals.csv"),
        "OUTPUT_EO": str(out_dir / "eo_calibrated.csv"),
        "OUTPUT_HTML": str(out_dir / "summary.html"),
    }


class CalibrationController(JobController):
    """The Run button of a picking dock: one calibration at a time in the QGIS task manager,
    its result kept in the dock's session.

    Signals
    -------
    finished(bool)
        The task ended; on success the session holds the BoresightRun, else :attr:`error`
        says why.
    """

    def __init__(self, dock) -> None:
        super().__init__(dock, dock.calibration_panel)
        self.result: JobResult | None = None
        self.panel.run_button.clicked.connect(self.run)
        self.panel.use_eo_button.clicked.connect(self.use_orientation)

    def run(self) -> bool:
        """Start the calibration in a background task; False (with a message) if it cannot."""
        dock, store = self.dock, self.dock.store
        if self._busy(self.tr("A calibration is already running.")):
            return False
        if store.path is None or not store.rows:
            dock.message(self.tr("No observations to calibrate with."), warning=True)
            return False
        if not store.save():
            return False
        control = dock.session.control.for_calibration()
        settings = self.panel.values()
        settings["camera"] = dock.project_panel.camera_edit.filePath()
        crs = dock.eo_crs()
        out_dir = store.path.with_name(store.path.stem + "_calibration")
        kinds = {o.type for o in store.rows}
        params = calibration_parameters(
            out_dir, settings, store.path, crs.authid() or crs.toWkt(), control, kinds
        )
        if not params["CONTROL_TYPES"]:
            dock.message(
                self.tr("Choose the plane, line or LCP layer of the observed types."),
                warning=True,
            )
            return False
        self.result = None

        def write_control() -> None:
            for key, write, items in zip(
                ("PLANES", "LINES", "LCPS"),
                (write_planes_csv, write_lines_csv, write_lcps_csv),
                control,
            ):
                if params[key]:
                    write(params[key], items)

        return self._launch(self.tr("Boresight calibration"), boresight_calibration, params,
                            "OUTPUT_TABLE", write_control, self.tr("Calibration cancelled."),
                            self.tr("Calibration failed. {}"))  # fmt: skip

    def _show(self, result: JobResult) -> None:
        dock, panel = self.dock, self.panel
        self.result = result
        session = dock.session
        session.set_calibration(result.data)
        panel.show_result(session.boresight_summary(), session.residual_stats())
        dock.message(self.tr("Calibration done: {}").format(self.params["OUTPUT_HTML"]))
        panel.use_eo_button.setEnabled(True)

    def use_orientation(self) -> None:
        """Show the images with the calibrated exterior orientation (the result's, in
        memory); the Project tab names its file."""
        run = self.dock.session.calibration
        if run is not None:
            self.dock.loader.use_orientation(run.result.eo, self.params["OUTPUT_EO"])
