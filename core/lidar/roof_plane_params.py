"""The parameters of the roof-plane extraction (:mod:`.roof_planes`), in a module of their own
that imports no numerical library, so that the command line's help reads their defaults
without the extraction (tests/core/test_startup.py)."""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import InputError

#: Point selections: non-ground (class != 2), the listed classes, or every point.
SELECTION_CHOICES: tuple[str, ...] = ("non_ground", "classes", "all")


@dataclass(frozen=True)
class RoofPlaneParams:
    """Parameters of :func:`~.roof_planes.extract_roof_planes`; lengths in the cloud's CRS unit.

    Attributes
    ----------
    k_neighbours : int
        K of the local RANSAC (>= 6).
    epsilon : float
        Point-to-plane tolerance (CRS unit): RANSAC inliers, region growing, assignment.
        About 3 x the range noise plus roof roughness; default 0.15 (metres).
    min_support : int
        Minimum inliers of a local plane (the paper's minimum set size t), <= k_neighbours.
    ransac_iterations : int
        Random triplets per point.
    min_slope_deg, max_slope_deg : float
        The paper's alpha and beta: accepted plane slopes, degrees from horizontal.
    angle_tolerance_deg : float
        Largest angle between local normals within one region, and between merged planes.
    min_plane_points : int
        Smallest plane kept (points).
    outline_cell : float
        Raster cell of the outlines (CRS unit); 0 = automatic (about one point spacing).
    seed : int
        No effect, kept so that scripts and models that give it still run: the RANSAC
        triplets are a fixed set (no random draw), so every seed gives the same planes.
    batch_size : int
        Points per batch (memory about batch_size x ransac_iterations x k_neighbours x 4 bytes;
        progress and cancel are checked per batch); no effect on the planes.
    """

    k_neighbours: int = 20
    epsilon: float = 0.15
    min_support: int = 18
    ransac_iterations: int = 15
    min_slope_deg: float = 0.0
    max_slope_deg: float = 70.0
    angle_tolerance_deg: float = 10.0
    min_plane_points: int = 30
    outline_cell: float = 0.0
    seed: int = 0
    batch_size: int = 8192

    def __post_init__(self) -> None:
        checks = (
            (self.k_neighbours >= 6, "k_neighbours must be >= 6"),
            (self.epsilon > 0, "epsilon must be > 0"),
            (
                3 <= self.min_support <= self.k_neighbours,
                "min_support must be between 3 and k_neighbours",
            ),
            (self.ransac_iterations >= 1, "ransac_iterations must be >= 1"),
            (
                0 <= self.min_slope_deg <= self.max_slope_deg <= 90,
                "slopes must satisfy 0 <= min_slope_deg <= max_slope_deg <= 90",
            ),
            (0 < self.angle_tolerance_deg < 90, "angle_tolerance_deg must be in (0, 90)"),
            (self.min_plane_points >= 3, "min_plane_points must be >= 3"),
            (self.outline_cell >= 0, "outline_cell must be >= 0"),
            (self.batch_size >= 1, "batch_size must be >= 1"),
        )
        for ok, message in checks:
            if not ok:
                raise InputError(message)
