"""lidarphoto:extracttlstargets - target centres with covariance from TLS scans."""

from __future__ import annotations

from ...core.jobs import extract_tls_targets
from ..base import BaseAlgorithm


class ExtractTlsTargetsAlgorithm(BaseAlgorithm):
    """Adapter of ``core.jobs.extract_tls_targets``: the output is a CSV table (scanner
    frames, no CRS)."""

    JOB = extract_tls_targets
