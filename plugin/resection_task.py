"""The Resection tab of the picking dock: resect the image shown from its measured lines and
control points, in a background ``QgsTask``, and show the adjusted pose and its residuals.

The task writes the control the dock shows (the core objects of its
:class:`~lidarphoto.core.photo.picking_session.ControlSet`: LiDAR lines and LCPs) to a line
and an LCP table next to the observation file, then runs the core job ``resection`` (what the
toolbox's ``lidarphoto:resection`` runs) on them and the saved observation file, for the image
shown only. The job writes ``eo.csv``, ``residuals.csv`` and ``summary.html``; the dock shows
the result objects it returns, not those files.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from qgis.PyQt.QtCore import Qt
from qgis.PyQt.QtWidgets import QCheckBox, QLabel, QPushButton, QVBoxLayout, QWidget

from ..core.io.control import write_lcps_csv, write_lines_csv
from ..core.io.observations import write_observations_csv
from ..core.jobs import resection
from ..core.jobs.resection import residual_rows
from ..core.photo.control_features import lines_with_end_sigmas
from ..core.photo.picking_session import residual_summary
from ..core.quality.html_table import escape
from .job_task import JobController

__all__ = ["RESECTION_ALG", "ResectionController", "ResectionPanel", "resection_parameters"]

#: the algorithm (core job) the Resect button runs
RESECTION_ALG = "lidarphoto:resection"


def resection_parameters(
    out_dir: Path, image_id: str, observations: Path, camera: str, crs: str, control: tuple
) -> dict:
    """Parameters of the core job ``resection`` for one image.

    ``control``: the dock's (planes, lines, LCPs) (``ControlSet.for_calibration``); the line
    and LCP tables are written to ``out_dir`` when there are lines or LCPs.
    """
    _planes, lines, lcps = control
    return {
        "CAMERA": camera,
        "OBSERVATIONS": str(observations),
        "CONTROL_POINTS": str(out_dir / "control_lcps.csv") if lcps else None,
        "CONTROL_LINES": str(out_dir / "control_lines.csv") if lines else None,
        "CRS": crs,
        "IMAGES": image_id,
        "OUTPUT_EO": str(out_dir / f"{image_id}_eo.csv"),
        "OUTPUT_RESIDUALS": str(out_dir / f"{image_id}_residuals.csv"),
        "OUTPUT_HTML": str(out_dir / f"{image_id}_summary.html"),
    }


class ResectionPanel(QWidget):
    """The Resect button and the result (pose, sigmas, sigma0, residual per line and point);
    the option refining the line ends on the image's edges."""

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        layout = QVBoxLayout(self)
        self.resect_button = QPushButton(self.tr("Resect the image shown"))
        self.resect_button.setObjectName("lidarphotoResect")
        self.resect_button.setToolTip(
            self.tr(
                "Runs {} in the background: the image's exterior orientation from its "
                "measured lines and control points, no approximate values"
            ).format(RESECTION_ALG)
        )
        self.refine_check = QCheckBox(self.tr("Refine line ends on the image edge"))
        self.refine_check.setToolTip(
            self.tr(
                "Line picking: each click moves across the line to the strongest grey-value "
                "edge within 4 px (sub-pixel)"
            )
        )
        self.result_label = QLabel()
        self.result_label.setWordWrap(True)
        self.result_label.setTextFormat(Qt.TextFormat.RichText)
        self.result_label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        layout.addWidget(self.refine_check)
        layout.addWidget(self.resect_button)
        layout.addWidget(self.result_label, 1)

    def set_running(self, running: bool) -> None:
        self.resect_button.setEnabled(not running)
        if running:
            self.result_label.setText(self.tr("Resection running…"))

    def show_result(self, run, rows: list[tuple]) -> str:
        """Show one image's resection (:class:`core.jobs.resection.ImageRun`) and its
        residual rows; returns the text shown."""
        r, res = run.result, run.result.result
        deg, s = np.degrees(r.opk), r.std
        sd = np.degrees(s[3:])
        head = (
            f"<b>{run.image_id}</b>: X {r.xyz[0]:.3f} ± {s[0]:.3f}, Y {r.xyz[1]:.3f} ± "
            f"{s[1]:.3f}, Z {r.xyz[2]:.3f} ± {s[2]:.3f} m<br>"
            f"ω {deg[0]:.5f} ± {sd[0]:.5f}, φ {deg[1]:.5f} ± {sd[1]:.5f}, κ {deg[2]:.5f} ± "
            f"{sd[2]:.5f}°<br>"
            + self.tr("σ0 {:.3f}, redundancy {}, χ² test {}; {} point(s), {} line(s)").format(
                res.sigma0,
                res.redundancy,
                self.tr("passed") if res.chi2_passed else self.tr("FAILED"),
                run.image.data.n_points,
                run.image.data.n_lines,
            )
        )
        table = [
            "<table><tr><th>"
            + "</th><th>".join(
                (
                    self.tr("type"),
                    self.tr("id"),
                    self.tr("pts"),
                    self.tr("RMS px"),
                    self.tr("max px"),
                    "",
                )
            )
            + "</th></tr>"
        ]
        for kind, target, n, rms, vmax, rejected in residual_summary(rows):
            flag = self.tr("rejected") if rejected else ""
            table.append(
                f"<tr><td>{kind}</td><td>{escape(target)}</td><td>{n}</td><td>{rms:.2f}</td>"
                f"<td>{vmax:.2f}</td><td>{flag}</td></tr>"
            )
        text = head + "".join(table) + "</table>"
        self.result_label.setText(text)
        return text


class ResectionController(JobController):
    """The Resect button of a picking dock: one resection at a time in the QGIS task manager;
    its residuals kept in the dock's session (drawn on the image and in the table).

    Signals
    -------
    finished(bool)
        The task ended; on success :attr:`run` is the image's
        :class:`core.jobs.resection.ImageRun`, else :attr:`error` says why.
    """

    def __init__(self, dock) -> None:
        super().__init__(dock, dock.resection_panel)
        self.run = None
        self.text = ""
        #: the line rows left out of the last resection (fisheye camera), said after it
        self.left_out = ""
        self.panel.resect_button.clicked.connect(self.start)

    def start(self, *_args) -> bool:
        """Resect the image shown in a background task; False (with a message) if it cannot
        start."""
        dock, store = self.dock, self.dock.store
        image = dock.current_image
        if self._busy(self.tr("A resection is already running.")):
            return False
        if not image or not any(o.image_id == image for o in store.rows):
            dock.message(self.tr("No observations in image {}.").format(image), warning=True)
            return False
        if store.path is None or not store.save():
            dock.message(self.tr("The observations could not be saved."), warning=True)
            return False
        planes, lines, lcps = dock.session.control.for_calibration()
        control = (planes, lines_with_end_sigmas(lines), lcps)
        if not control[1] and not control[2]:
            dock.message(self.tr("Choose the line or LCP layer."), warning=True)
            return False
        crs = dock.eo_crs()
        out_dir = store.path.with_name(store.path.stem + "_resection")
        camera = dock.project_panel.camera_edit.filePath()
        # the rows as they are now: the store autosaves every edit made while the task runs,
        # and the residuals are mapped back through the file the job read
        snapshot = store.to_observations()
        # control rows name surveyed points, which the dock's LCP table does not hold
        snapshot = snapshot.subset(~snapshot.mask("control"))
        cam = dock.session.camera
        left_out = ""
        if cam is not None and not cam.is_perspective and snapshot.mask("line").any():
            # the resection from lines holds for the perspective projection only (the job
            # refuses line rows with a fisheye camera): the image's points are used alone
            lines_here = snapshot.mask("line") & (np.asarray(snapshot.image_id) == image)
            n_lines = int(lines_here.sum())
            snapshot = snapshot.subset(~snapshot.mask("line"))
            control = (planes, [], lcps)
            if not np.any(np.asarray(snapshot.image_id) == image):
                dock.message(
                    self.tr(
                        "Image {} has only line rows: camera {} has the {} (fisheye) "
                        "projection, and the resection from lines handles perspective "
                        "cameras only. Measure control points (lcp)."
                    ).format(image, cam.name, cam.projection),
                    warning=True,
                )
                return False
            if n_lines:
                left_out = self.tr(
                    "{} line row(s) of image {} left out: the resection from lines handles "
                    "perspective cameras only (camera {}: {} fisheye projection)."
                ).format(n_lines, image, cam.name, cam.projection)
                dock.message(left_out, warning=True)
        self.left_out = left_out
        params = resection_parameters(
            out_dir, image, out_dir / "observations.csv", camera, crs.authid() or crs.toWkt(),
            control,
        )  # fmt: skip
        self.run, self.text = None, ""

        def write_control() -> None:
            write_observations_csv(params["OBSERVATIONS"], snapshot)
            _planes, lines, lcps = control
            if params["CONTROL_LINES"]:
                write_lines_csv(params["CONTROL_LINES"], lines)
            if params["CONTROL_POINTS"]:
                write_lcps_csv(params["CONTROL_POINTS"], lcps)

        return self._launch(self.tr("Resection of {}").format(image), resection, params,
                            "OUTPUT_EO", write_control, self.tr("Resection cancelled."),
                            self.tr("Resection failed. {}"))  # fmt: skip

    def _usable(self, result) -> bool:
        return bool(result.data)

    def _show(self, result) -> None:
        from ..core.geometry.projection import PROJECTIONS
        from ..core.io.camera import read_camera_json
        from ..core.io.observations import read_observations_csv

        dock = self.dock
        run = self.run = result.data[0]
        camera = read_camera_json(self.params["CAMERA"], projections=PROJECTIONS)
        obs = read_observations_csv(self.params["OBSERVATIONS"], camera=camera)
        rows = residual_rows(run, obs, camera)
        dock.session.set_resection(rows)
        self.text = self.panel.show_result(run, rows)
        s0 = run.result.result.sigma0
        dock.message(
            self.tr("Resection of {} done: sigma0 {}; {}").format(
                run.image_id, f"{s0:.3f}" if math.isfinite(s0) else "-", self.params["OUTPUT_HTML"]
            )
            + (" " + self.left_out if self.left_out else "")
        )
