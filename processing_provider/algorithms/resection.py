"""lidarphoto:resection - exterior orientation of single images from points and lines."""

from __future__ import annotations

from ...core.jobs import resection
from ..base import BaseAlgorithm


class ResectionAlgorithm(BaseAlgorithm):
    """Adapter of ``core.jobs.resection`` (file outputs only)."""

    JOB = resection
