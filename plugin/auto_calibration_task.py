"""The dock's *Calibrate automatically*: the boresight of the open images without picked
observations, the core job ``auto_boresight`` (what the toolbox's
``lidarphoto:autoboresight`` runs) in a background ``QgsTask``.

The task writes the dock's LiDAR lines (and planes, for the observability check) as the
tables the job reads, then runs it on the open images with the Project and Calibration tabs'
camera, trajectory, lever arm, mount and approximate boresight. The job writes
``boresight.csv``, ``eo_calibrated.csv``, ``observations_found.csv`` and ``summary.html``;
the dock then shows the images with the calibrated orientation, so that the LiDAR lines it
draws are a visual check of the result.
"""

from __future__ import annotations

from pathlib import Path

from ..core.io.control import write_lines_csv
from ..core.io.planes import write_planes_csv
from ..core.jobs import auto_boresight
from ..core.jobs.runner import JobResult
from .calibration_task import flight_parameters
from .job_task import JobController

__all__ = ["AutoCalibrationController", "auto_calibration_parameters"]


def auto_calibration_parameters(
    out_dir: Path, settings: dict, images: list[str], crs: str, has_planes: bool
) -> dict:
    """Parameters of the core job ``auto_boresight``: ``settings`` holds the Calibration tab's
    values (``trajectory``, ``lever_arm``, ``mount``, ``boresight``) and the ``camera`` file;
    the lines (and, with ``has_planes``, the planes) are written into ``out_dir``."""
    return {
        "IMAGES": list(images),
        **flight_parameters(settings, crs),
        "LINES": str(out_dir / "control_lines.csv"),
        "PLANES": str(out_dir / "control_planes.csv") if has_planes else None,
        "OUTPUT_TABLE": str(out_dir / "boresight.csv"),
        "OUTPUT_EO": str(out_dir / "eo_calibrated.csv"),
        "OUTPUT_OBSERVATIONS": str(out_dir / "observations_found.csv"),
        "OUTPUT_HTML": str(out_dir / "summary.html"),
    }


class AutoCalibrationController(JobController):
    """The Calibration tab's *Calibrate automatically* button: one automatic calibration at a
    time in the QGIS task manager; on success the images are shown with its orientation."""

    def __init__(self, dock) -> None:
        super().__init__(dock, dock.calibration_panel)
        self.result: JobResult | None = None
        self.panel.auto_button.clicked.connect(self.run)

    def _out_dir(self, trajectory: str) -> Path:
        store = self.dock.store
        if store.path is not None:
            return store.path.with_name(store.path.stem + "_auto_calibration")
        return Path(trajectory).with_name(Path(trajectory).stem + "_auto_calibration")

    def run(self) -> bool:
        """Start the calibration in a background task; False (with a message) if it cannot."""
        dock = self.dock
        if self._busy(self.tr("An automatic calibration is already running.")):
            return False
        planes, lines, _ = dock.session.control.for_calibration()
        images = [str(p) for p in dock.image_paths.values()]
        settings = self.panel.values()
        settings["camera"] = dock.project_panel.camera_edit.filePath()
        missing = [
            name
            for name, ok in (
                (self.tr("images"), images),
                (self.tr("a camera"), settings["camera"]),
                (self.tr("a trajectory"), settings["trajectory"]),
                (self.tr("LiDAR lines"), lines),
            )
            if not ok
        ]
        if missing:
            dock.message(
                self.tr("The automatic calibration needs {}.").format(", ".join(missing)),
                warning=True,
            )
            return False
        crs = dock.eo_crs()
        out_dir = self._out_dir(settings["trajectory"])
        params = auto_calibration_parameters(
            out_dir, settings, images, crs.authid() or crs.toWkt(), bool(planes)
        )
        self.result = None

        def write_control() -> None:
            write_lines_csv(params["LINES"], lines)
            if params["PLANES"]:
                write_planes_csv(params["PLANES"], planes)

        return self._launch(
            self.tr("Automatic boresight calibration"),
            auto_boresight,
            params,
            "OUTPUT_TABLE",
            write_control,
            self.tr("Calibration cancelled."),
            self.tr("Automatic calibration failed. {}"),
        )

    def _show(self, result: JobResult) -> None:
        dock, panel = self.dock, self.panel
        self.result = result
        found = result.data.result
        groups = [
            (g, found.boresight_arcsec[k], float(found.sigma0)) for k, g in enumerate(found.groups)
        ]
        text = panel.show_result(groups, (0, float("nan"), float("nan")))
        counts = self.tr("{} line points, {} tie points on roof planes, {} rounds").format(
            int(result.results["LINE_POINTS"]),
            int(result.results["TIES_ASSOCIATED"]),
            int(result.results["ROUNDS"]),
        )
        panel.result_label.setText(f"{text}\n{counts}")
        dock.session.set_calibration(None)  # the picked rows' residuals are not this run's
        dock.loader.use_orientation(found.eo, self.params["OUTPUT_EO"])
        dock.message(self.tr("Automatic calibration done: {}").format(self.params["OUTPUT_HTML"]))
