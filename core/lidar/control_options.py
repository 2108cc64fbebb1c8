"""The thresholds of the LiDAR control extraction (:mod:`.control`), in a module of their own
that imports no numerical library, so that the command line's help reads their defaults
without the extraction (tests/core/test_startup.py)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class ControlOptions:
    """Thresholds, in the cloud's units and degrees.

    delta: adjacency distance between points of two planes; min_boundary: minimum common
    boundary length; min_angle_deg: every pair of normals of a triple (or of a line) must
    differ by at least this; max_condition: condition number limit of the 3 x 3 system;
    max_support_distance: an LCP must lie within this distance of the points of each plane.
    length_unit: the symbol of the cloud's length unit, for the messages ("m", "ft").
    """

    delta: float = 1.0
    min_boundary: float = 2.0
    min_angle_deg: float = 10.0
    max_condition: float = 50.0
    max_support_distance: float = 2.0
    neighbours: int = 12
    length_unit: str = "m"
