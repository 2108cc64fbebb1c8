"""lidarphoto:monoplot - 3D points and lines from one oriented image and a LiDAR DSM."""

from __future__ import annotations

import math

from qgis.core import (
    QgsCoordinateReferenceSystem,
    QgsLineString,
    QgsPoint,
    QgsProcessingException,
    QgsProcessingOutputNumber,
    QgsProcessingParameterCrs,
    QgsProcessingParameterEnum,
    QgsProcessingParameterFeatureSink,
    QgsProcessingParameterFile,
    QgsProcessingParameterFileDestination,
    QgsProcessingParameterNumber,
    QgsProcessingParameterRasterDestination,
    QgsProcessingParameterString,
)

from ..base import BaseAlgorithm
from ..compat import (
    FIELD_DOUBLE,
    FIELD_INT,
    FIELD_STRING,
    FILE_BEHAVIOR_FILE,
    FLAG_ADVANCED,
    NUMBER_DOUBLE,
    SOURCE_VECTOR_LINE,
    SOURCE_VECTOR_POINT,
    WKB_LINESTRING_Z,
    WKB_POINT_Z,
    WKT_PREFERRED,
)

S, D, N = FIELD_STRING, FIELD_DOUBLE, FIELD_INT
_POINT_FIELDS = (
    ("image_id", S), ("point_id", S), ("type", S), ("target_id", S), ("line", N),
    ("vertex", N), ("col", D), ("row", D), ("sigma_x", D), ("sigma_y", D), ("sigma_z", D),
    ("status", N), ("status_text", S), ("method", S), ("incidence_deg", D),
)  # fmt: skip
_LINE_FIELDS = (
    ("line", N), ("image_id", S), ("target_id", S), ("n_vertices", N), ("status", N),
    ("status_text", S), ("length", D), ("sigma_start", D), ("sigma_end", D),
)  # fmt: skip
METHODS = ("dal_poz", "makarovic")

_HELP = """<p>Monoplotting (paper 001): the ray of each image point is intersected with the \
LiDAR surface. <b>Direct</b> (Dal Poz 1991): the ray walks the DSM's cells in order from the \
camera and meets the two triangles of each cell in the determinant form of Eqs. 6-10; the \
first face hit is the visible point (occlusion). <b>Makarovic</b>: the classical iteration \
height -> position -> height.</p>
<p><b>Observations</b>: the image-observation CSV of the picking dock \
(image_id, point_id, col, row, sigma_px, type, target_id). Rows of type <i>line</i> with the \
same image and target_id form one 3D line (vertices in file order; <b>line step</b> adds \
points every so many pixels along it); other rows are points (their target_id is not \
used). With a <b>plane table</b>, rows of type <i>tie</i> or <i>paper</i> are intersected with \
their roof plane (target_id) instead.</p>
<p><b>DSM</b>: a raster, or a LAS/LAZ rasterised at <b>cell size</b> (highest return per \
cell, gaps filled; optionally saved). A DSM in another CRS than the mapping <b>CRS</b> of the \
exterior orientation is resampled into it, heights transformed too (<b>DSM CRS</b> supplies \
the CRS when the file has none); when PROJ lacks a grid for that (e.g. a geoid), its points \
get the status crs_mismatch.</p>
<p>Each point carries a 3x3 covariance from the image sigma, the <b>EO sigmas</b> \
(X, Y, Z in m; omega, phi, kappa in degrees) and the <b>DSM height sigma</b>, and a status: \
ok, grazing (ray meets the face at less than the minimum angle), outside (the ray leaves the \
DSM), nodata (it crosses a hole first), no_orientation (image not in the EO table), \
crs_mismatch (see DSM), not_converged (Makarovic), parallel / unknown_plane (planes).</p>"""


class MonoplotAlgorithm(BaseAlgorithm):
    """Thin adapter of ``core.monoplot.run_monoplot``."""

    GROUP = "Monoplotting"
    GROUP_ID = "monoplotting"
    TAGS = ("monoplotting", "monorestitution", "dsm", "dal poz", "makarovic", "3d lines")

    def name(self) -> str:
        return "monoplot"

    def displayName(self) -> str:
        return self.tr("Monoplot image points and lines on a LiDAR DSM")

    def shortHelpString(self) -> str:
        return self.tr(_HELP)

    def initAlgorithm(self, config=None):
        for key, label, ext, optional in (
            ("OBSERVATIONS", "Image observations (CSV)", "CSV files (*.csv)", False),
            ("CAMERA", "Camera (JSON)", "JSON files (*.json)", False),
            ("EO", "Exterior orientation (CSV)", "CSV files (*.csv)", False),
            ("DSM", "DSM (raster, or LAS/LAZ)",
             "DSM (*.tif *.tiff *.img *.vrt *.asc *.las *.laz *.LAS *.LAZ)", False),
            ("PLANES", "Roof plane table (CSV)", "CSV files (*.csv)", True),
        ):  # fmt: skip
            self.addParameter(
                QgsProcessingParameterFile(key, self.tr(label), behavior=FILE_BEHAVIOR_FILE,
                    fileFilter=self.tr(f"{ext};;All files (*.*)"), optional=optional)
            )  # fmt: skip
        self.addParameter(QgsProcessingParameterCrs("CRS", self.tr("Mapping CRS of the EO")))
        self.addParameter(
            QgsProcessingParameterCrs("DSM_CRS", self.tr("DSM CRS (if the file has none)"),
                                      None, True)
        )  # fmt: skip
        self.addParameter(
            QgsProcessingParameterEnum("METHOD", self.tr("Method"),
                [self.tr("direct (Dal Poz, DDA)"), self.tr("Makarovic iteration")], False, 0)
        )  # fmt: skip
        for key, label, default, advanced in (
            ("CELL_SIZE", "DSM cell size for LAS/LAZ (CRS unit)", 0.5, False),
            ("SIGMA_DSM", "DSM height sigma (m)", 0.10, False),
            ("LINE_STEP", "Points along lines every (pixels, 0 = end points)", 0.0, False),
            ("MIN_INCIDENCE", "Minimum angle ray / face (degrees)", 5.0, True),
        ):
            param = QgsProcessingParameterNumber(key, self.tr(label), NUMBER_DOUBLE, default,
                                                 False, 0.0)  # fmt: skip
            if advanced:
                param.setFlags(param.flags() | FLAG_ADVANCED)
            self.addParameter(param)
        self.addParameter(
            QgsProcessingParameterString(
                "EO_SIGMAS", self.tr("EO sigmas: X, Y, Z (m), omega, phi, kappa (degrees)"),
                "0.05,0.05,0.08,0.005,0.005,0.008",
            )
        )  # fmt: skip
        self.addParameter(QgsProcessingParameterFeatureSink(
            "OUTPUT_POINTS", self.tr("Monoplotted points"), SOURCE_VECTOR_POINT))  # fmt: skip
        self.addParameter(QgsProcessingParameterFeatureSink(
            "OUTPUT_LINES", self.tr("Monoplotted lines"), SOURCE_VECTOR_LINE))  # fmt: skip
        for key, label in (("OUTPUT_CSV", "Point table (CSV)"), ("LINES_CSV", "Line table")):
            self.addParameter(QgsProcessingParameterFileDestination(
                key, self.tr(label), self.tr("CSV files (*.csv)"), optional=True,
                createByDefault=False))  # fmt: skip
        self.addParameter(QgsProcessingParameterRasterDestination(
            "OUTPUT_DSM", self.tr("DSM made from the LAS/LAZ"), optional=True,
            createByDefault=False))  # fmt: skip
        self.addOutput(QgsProcessingOutputNumber("POINT_COUNT", self.tr("Rays monoplotted")))
        self.addOutput(QgsProcessingOutputNumber("HIT_COUNT", self.tr("Rays with a 3D point")))

    def processAlgorithm(self, parameters, context, feedback):
        from ...core.photo.monoplot import STATUS_TEXT, run_monoplot

        def crs(key):
            c = self.parameterAsCrs(parameters, key, context)
            return (c.authid() or c.toWkt(WKT_PREFERRED)) if c.isValid() else None

        files = {k: self.parameterAsFile(parameters, k, context) or None
                 for k in ("OBSERVATIONS", "CAMERA", "EO", "DSM", "PLANES")}  # fmt: skip
        outs = {k: self.parameterAsFileOutput(parameters, k, context) or None
                for k in ("OUTPUT_CSV", "LINES_CSV")}  # fmt: skip
        dsm_out = self.parameterAsOutputLayer(parameters, "OUTPUT_DSM", context) or None
        if crs("CRS") is None:
            raise QgsProcessingException(self.tr("The mapping CRS is required"))
        res = self.run_core(
            run_monoplot, files["OBSERVATIONS"], files["CAMERA"], files["EO"], files["DSM"],
            crs("CRS"), dsm_crs=crs("DSM_CRS"),
            cell_size=self.parameterAsDouble(parameters, "CELL_SIZE", context),
            method=METHODS[self.parameterAsEnum(parameters, "METHOD", context)],
            sigma_dsm=self.parameterAsDouble(parameters, "SIGMA_DSM", context),
            eo_sigmas=self.parameterAsString(parameters, "EO_SIGMAS", context),
            planes=files["PLANES"],
            line_step_px=self.parameterAsDouble(parameters, "LINE_STEP", context),
            min_incidence_deg=self.parameterAsDouble(parameters, "MIN_INCIDENCE", context),
            output_csv=outs["OUTPUT_CSV"], lines_csv=outs["LINES_CSV"], output_dsm=dsm_out,
            feedback=feedback,
        )  # fmt: skip
        feedback.pushInfo(f"status counts: {res.status_counts()}")
        layer_crs = QgsCoordinateReferenceSystem.fromWkt(res.crs_wkt)
        psink, pid = self.field_sink(parameters, context, "OUTPUT_POINTS", _POINT_FIELDS,
                                WKB_POINT_Z, layer_crs)  # fmt: skip
        sig = res.sigmas
        for k, (img, pt, kind, tgt, li, vi, how) in enumerate(res.rows):
            p = res.points[k]
            geom = QgsPoint(*map(float, p)) if all(map(math.isfinite, p)) else None
            st = int(res.status[k])
            values = [img, pt, kind, tgt, li, vi, *res.pixels[k], *sig[k], st, STATUS_TEXT[st],
                      how, res.incidence_deg[k]]  # fmt: skip
            self.add_feature(psink, _POINT_FIELDS, geom, values)
        lsink, lid = self.field_sink(parameters, context, "OUTPUT_LINES", _LINE_FIELDS,
                                WKB_LINESTRING_Z, layer_crs)  # fmt: skip
        for li, ln in enumerate(res.lines):
            v = [QgsPoint(*map(float, p)) for p in ln.vertices if all(map(math.isfinite, p))]
            length = sum(a.distance3D(b) for a, b in zip(v[:-1], v[1:]))
            values = [li, ln.image_id, ln.target_id, len(ln.vertices), ln.status,
                      STATUS_TEXT[ln.status], length, *ln.sigma_ends]  # fmt: skip
            self.add_feature(lsink, _LINE_FIELDS, QgsLineString(v) if len(v) > 1 else None, values)
        return {"OUTPUT_POINTS": pid, "OUTPUT_LINES": lid, **outs, "OUTPUT_DSM": dsm_out,
                "POINT_COUNT": len(res.rows),
                "HIT_COUNT": int(sum(s in (0, 1) for s in res.status))}  # fmt: skip
