"""lidarphoto:tlscalibration - TLS station registration and scanner self-calibration."""

from __future__ import annotations

from ...core.jobs import tls_calibration
from ..base import BaseAlgorithm


class TlsCalibrationAlgorithm(BaseAlgorithm):
    """Adapter of ``core.jobs.tls_calibration``: every output is a file (CSV tables in the
    object frame of the network, which has no CRS, and the HTML report)."""

    JOB = tls_calibration
