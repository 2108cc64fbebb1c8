"""The Bundle tab of the picking dock: a bundle adjustment with self-calibration of the images
the dock has open, in a background ``QgsTask``, and its result (sigma0, the AP table, the
residual RMS per image, the residual vectors on the image).

The dock's rows become a block in the core (:func:`core.photo.dock_bundle.dock_bundle_inputs`:
tie rows, LCP rows as control points with the LCPs' coordinates and sigmas, check rows); the
task writes them (observation and ground point tables) with the dock's orientations of those
images (an EO table: approximate values, or observations with
:data:`~lidarphoto.core.photo.dock_bundle.DEFAULT_EO_SIGMAS`) to a folder next to the
observation file and runs the core job ``bundleadjustment`` (what the toolbox's
``lidarphoto:bundleadjustment`` runs). The dock shows the result object the job returns.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from qgis.PyQt.QtCore import Qt
from qgis.PyQt.QtWidgets import QCheckBox, QComboBox, QFormLayout, QLabel, QPushButton, QWidget

from ..core.i18n import render
from ..core.io.ground_points import write_ground_points_csv
from ..core.io.observations import write_observations_csv
from ..core.io.orientation import write_eo_csv
from ..core.jobs import bundle_adjustment
from ..core.photo.dock_bundle import (
    DEFAULT_EO_SIGMAS,
    DockBundleInputs,
    dock_bundle_inputs,
    orientations_of,
)
from ..core.quality.html_table import escape
from .job_task import JobController

__all__ = ["BUNDLE_ALG", "BundleController", "BundlePanel", "bundle_parameters"]

#: the algorithm (core job) the Bundle button runs
BUNDLE_ALG = "lidarphoto:bundleadjustment"


def _spec_param(name: str):
    return next(p for p in bundle_adjustment.SPEC.params if p.name == name)


def bundle_parameters(
    out_dir: Path,
    camera: str,
    crs: str,
    ap_model: str,
    interior: bool,
    eo_observed: bool,
    ground: bool = True,
) -> dict:
    """Parameters of the core job ``bundleadjustment`` on the tables written to ``out_dir``
    (``ground``: there are control or check points)."""
    return {
        "CAMERA": camera,
        "OBSERVATIONS": str(out_dir / "observations.csv"),
        "GROUND_POINTS": str(out_dir / "ground_points.csv") if ground else None,
        "EO": str(out_dir / "eo_input.csv"),
        "EO_SIGMAS": list(DEFAULT_EO_SIGMAS) if eo_observed else None,
        "CRS": crs,
        "AP_MODEL": ap_model,
        "ESTIMATE_INTERIOR": interior,
        "OUTPUT_EO": str(out_dir / "eo_adjusted.csv"),
        "OUTPUT_CAMERA": str(out_dir / "camera_adjusted.json"),
        "OUTPUT_POINTS": str(out_dir / "points.csv"),
        "OUTPUT_RESIDUALS": str(out_dir / "residuals.csv"),
        "OUTPUT_HTML": str(out_dir / "summary.html"),
    }


def _header_row(*cells: str) -> str:
    """The start of an HTML table with one header row."""
    return "<table><tr>" + "".join(f"<th>{c}</th>" for c in cells) + "</tr>"


class BundlePanel(QWidget):
    """AP model, interior orientation, EO as observations, the Run button and the result."""

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        form = QFormLayout(self)
        ap = _spec_param("AP_MODEL")
        self.ap_combo = QComboBox()
        for value, label in zip(ap.options, ap.labels or ap.options):
            self.ap_combo.addItem(label, value)
        self.ap_combo.setCurrentIndex(list(ap.options).index(ap.default))
        self.interior_check = QCheckBox(_spec_param("ESTIMATE_INTERIOR").label)
        self.interior_check.setChecked(bool(_spec_param("ESTIMATE_INTERIOR").default))
        s = DEFAULT_EO_SIGMAS
        self.eo_check = QCheckBox(
            self.tr("The dock's orientations are observations (σ {} m, {}°)").format(s[0], s[3])
        )
        self.eo_check.setToolTip(
            self.tr("Off: approximate values only (the datum comes from the control points)")
        )
        self.run_button = QPushButton(self.tr("Bundle adjustment of the open images"))
        self.run_button.setObjectName("lidarphotoRunBundle")
        self.run_button.setToolTip(
            self.tr(
                "Runs {} in the background: tie points, LCPs as control points (with their "
                "sigmas) and check points of the images open in the dock"
            ).format(BUNDLE_ALG)
        )
        self.result_label = QLabel()
        self.result_label.setWordWrap(True)
        self.result_label.setTextFormat(Qt.TextFormat.RichText)
        self.result_label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        form.addRow(self.tr("Additional parameters"), self.ap_combo)
        form.addRow(self.interior_check)
        form.addRow(self.eo_check)
        form.addRow(self.run_button)
        form.addRow(self.result_label)

    def ap_model(self) -> str:
        return str(self.ap_combo.currentData())

    def set_running(self, running: bool) -> None:
        self.run_button.setEnabled(not running)
        if running:
            self.result_label.setText(self.tr("Bundle adjustment running…"))

    def show_result(self, res, inputs: DockBundleInputs) -> str:
        """Show a :class:`core.photo.bundle_result.BundleResult`; returns the text shown."""
        a = res.adjustment
        head = self.tr(
            "<b>{}</b>: σ0 {:.3f}, redundancy {}, χ² test {}; {} image(s), {} measurement(s), "
            "{} rejected"
        ).format(
            res.ap_model,
            a.sigma0,
            a.redundancy,
            self.tr("passed") if a.global_test.passed else self.tr("FAILED"),
            len(res.eo),
            len(res.observations),
            int(np.sum(res.rejected)),
        )
        if inputs.left_out:
            head += "<br>" + self.tr("Left out: {}").format(inputs.left_out_text())
        st = res.check.statistics()
        if len(res.check.point_id):
            head += "<br>" + self.tr("Check points ({}): RMS 3D {:.3f} m").format(
                int(st["n"]), st["rms_3d"]
            )
        ap = [_header_row(self.tr("parameter"), self.tr("value"), "σ", "")]
        for p in res.interior:
            if p.status == "estimated":
                flag = self.tr("significant") if p.significant else ""
            else:
                flag = escape(
                    {"dropped": self.tr("dropped"), "fixed": self.tr("fixed")}.get(
                        p.status, p.status
                    )
                    + (": " + render(p.reason, "Report") if p.reason else "")
                )
            ap.append(
                f"<tr><td>{p.name}</td><td>{p.value:.6g}</td><td>"
                f"{p.std:.3g}</td><td>{flag}</td></tr>"
                if math.isfinite(p.std)
                else f"<tr><td>{p.name}</td><td>{p.value:.6g}</td><td>-</td><td>{flag}</td></tr>"
            )
        ap.append("</table>")
        img = [_header_row(self.tr("image"), self.tr("RMS col px"), self.tr("RMS row px"))]
        for image_id, (rc, rr) in res.image_rms.items():
            img.append(f"<tr><td>{escape(image_id)}</td><td>{rc:.2f}</td><td>{rr:.2f}</td></tr>")
        img.append("</table>")
        text = head + "".join(ap) + "".join(img)
        self.result_label.setText(text)
        return text


class BundleController(JobController):
    """The Bundle button of a picking dock: one adjustment at a time in the QGIS task
    manager; its residuals kept in the dock's session (drawn on the image and in the table).

    Signals
    -------
    finished(bool)
        The task ended; on success :attr:`result` is the
        :class:`core.photo.bundle_result.BundleResult`, else :attr:`error` says why.
    """

    def __init__(self, dock) -> None:
        super().__init__(dock, dock.bundle_panel)
        self.inputs: DockBundleInputs | None = None
        self.result = None
        self.text = ""
        self.panel.run_button.clicked.connect(self.start)

    def _refuse(self, text: str) -> bool:
        self.error = text
        self.panel.result_label.setText(text)
        self.dock.message(text, warning=True)
        return False

    def start(self, *_args) -> bool:
        """Adjust the open images in a background task; False (with the reason shown in the
        panel) if it cannot start."""
        dock, store, session = self.dock, self.dock.store, self.dock.session
        if self._busy(self.tr("A bundle adjustment is already running.")):
            return False
        camera = dock.project_panel.camera_edit.filePath()
        if session.eo is None or not camera:
            return self._refuse(self.tr("Choose the camera and the exterior orientation."))
        if store.path is None or not store.save():
            return self._refuse(self.tr("The observations could not be saved."))
        open_ids = set(dock.image_paths) & set(session.eo.image_id)
        try:
            inputs = dock_bundle_inputs(
                session.observations.to_observations(),
                session.control.lcps,
                session.control.lcp_ids,
                open_ids,
            )
        except Exception as exc:  # an InputError of the rows: shown, not raised
            return self._refuse(self.tr("Bundle adjustment refused: {}").format(exc))
        if len(inputs.images) < 2:
            return self._refuse(
                self.tr(
                    "Bundle adjustment refused: tie or control points are measured in {} open "
                    "image(s); a block needs two or more. {}"
                ).format(len(inputs.images), inputs.left_out_text())
            )
        eo = orientations_of(session.eo, inputs.images)
        crs = dock.eo_crs()
        out_dir = store.path.with_name(store.path.stem + "_bundle")
        params = bundle_parameters(
            out_dir,
            camera,
            crs.authid() or crs.toWkt(),
            self.panel.ap_model(),
            self.panel.interior_check.isChecked(),
            self.panel.eo_check.isChecked(),
            len(inputs.ground) > 0,
        )
        self.inputs, self.result, self.text = inputs, None, ""

        def write_block() -> None:
            write_observations_csv(params["OBSERVATIONS"], inputs.observations)
            if params["GROUND_POINTS"]:
                write_ground_points_csv(params["GROUND_POINTS"], inputs.ground)
            write_eo_csv(params["EO"], eo)

        return self._launch(
            self.tr("Bundle adjustment of {} images").format(len(inputs.images)),
            bundle_adjustment,
            params,
            "OUTPUT_EO",
            write_block,
            self.tr("Bundle adjustment cancelled."),
            self.tr("Bundle adjustment failed. {}"),
        )

    def _usable(self, result) -> bool:
        return result.data is not None

    def _show(self, result) -> None:
        dock = self.dock
        res = self.result = result.data
        dock.session.set_bundle(res)
        self.text = self.panel.show_result(res, self.inputs)
        s0 = res.adjustment.sigma0
        dock.message(
            self.tr("Bundle adjustment done: sigma0 {}; {}").format(
                f"{s0:.3f}" if math.isfinite(s0) else "-", self.params["OUTPUT_HTML"]
            )
        )
