"""The QGIS Processing provider ``lidarphoto``."""

from __future__ import annotations

from pathlib import Path

from qgis.core import QgsProcessingProvider
from qgis.PyQt.QtCore import QCoreApplication
from qgis.PyQt.QtGui import QIcon

from .algorithms.accuracy_report import AccuracyReportAlgorithm
from .algorithms.boresight_calibration import BoresightCalibrationAlgorithm
from .algorithms.bundle_adjustment import BundleAdjustmentAlgorithm
from .algorithms.calibrate_camera import CalibrateCameraAlgorithm
from .algorithms.create_lcps import CreateLcpsAlgorithm
from .algorithms.extract_roof_planes import ExtractRoofPlanesAlgorithm
from .algorithms.extract_tls_targets import ExtractTlsTargetsAlgorithm
from .algorithms.ground_filter import GroundFilterAlgorithm
from .algorithms.lidar_block import LidarBlockAlgorithm
from .algorithms.locate_control_points import LocateControlPointsAlgorithm
from .algorithms.make_control_chips import MakeControlChipsAlgorithm
from .algorithms.monoplot import MonoplotAlgorithm
from .algorithms.orthomosaic import OrthomosaicAlgorithm
from .algorithms.orthorectify import OrthorectifyAlgorithm
from .algorithms.resection import ResectionAlgorithm
from .algorithms.tie_points import TiePointsAlgorithm
from .algorithms.tls_calibration import TlsCalibrationAlgorithm
from .algorithms.trajectory_to_eo import TrajectoryToEoAlgorithm
from .i18n import install_translator

ICON_PATH = Path(__file__).resolve().parents[1] / "icon.svg"


class LidarPhotoProvider(QgsProcessingProvider):
    """Provider ``lidarphoto``; its id and the algorithm names are API (models, scripts)."""

    def __init__(self) -> None:
        super().__init__()
        install_translator()  # QGIS's language, also under qgis_process (no initGui)

    def tr(self, text: str) -> str:
        return QCoreApplication.translate("LidarPhotoProvider", text)

    def id(self) -> str:
        return "lidarphoto"

    def name(self) -> str:
        return self.tr("LiDAR Photogrammetry")

    def longName(self) -> str:
        return self.tr("LiDAR Photogrammetry Toolkit")

    def icon(self) -> QIcon:
        return QIcon(str(ICON_PATH))

    def svgIconPath(self) -> str:
        return str(ICON_PATH)

    def loadAlgorithms(self) -> None:
        for alg in (
            TrajectoryToEoAlgorithm(),
            GroundFilterAlgorithm(),
            CreateLcpsAlgorithm(),
            AccuracyReportAlgorithm(),
            ExtractRoofPlanesAlgorithm(),
            BoresightCalibrationAlgorithm(),
            MonoplotAlgorithm(),
            BundleAdjustmentAlgorithm(),
            ResectionAlgorithm(),
            OrthorectifyAlgorithm(),
            OrthomosaicAlgorithm(),
            TlsCalibrationAlgorithm(),
            ExtractTlsTargetsAlgorithm(),
            LocateControlPointsAlgorithm(),
            LidarBlockAlgorithm(),
            CalibrateCameraAlgorithm(),
            TiePointsAlgorithm(),
            MakeControlChipsAlgorithm(),
        ):
            self.addAlgorithm(alg)
