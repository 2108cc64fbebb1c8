"""Settings of the LiDAR product accuracy check (:mod:`.lidar_swaths`, :mod:`.lidar_vertical`),
light (standard library only) so that ``lidarphoto lidaraccuracy --help`` stays fast.

The thresholds follow our reading of the ASPRS Positional Accuracy Standards for Digital
Geospatial Data, Edition 2, Version 1.0 (2023), section 7 (vertical accuracy classes and the
relative accuracy of lidar): for a vertical class of ``#`` cm the within-swath smooth-surface
precision (max difference) is at most 0.6 #, the swath-to-swath RMSDz on non-vegetated smooth
surfaces at most 0.8 # and the swath-to-swath max difference at most 1.6 #; NVA is stated as
RMSE (at least 30 check points), VVA is reported only (no pass/fail in Edition 2). docs/formats.md
"LiDAR accuracy" names the sources and what is our reading.
"""

from __future__ import annotations

from dataclasses import dataclass

#: Where the swath (flight line) of each point comes from.
SWATH_SOURCES = ("auto", "point_source_id", "gps_time")
#: ASPRS Ed. 2 relative accuracy, as multiples of the vertical class (our reading of its table
#: of vertical accuracy classes): within-swath max difference, swath-to-swath RMSDz, and
#: swath-to-swath max difference.
WITHIN_SWATH_FACTOR = 0.6
SWATH_RMSDZ_FACTOR = 0.8
SWATH_MAX_FACTOR = 1.6
#: ASPRS Ed. 2: VVA is reported; its table prints it as 1.5 times the NVA class (guidance).
VVA_FACTOR = 1.5
#: Minimum NVA check points (Ed. 2: 30 for any product assessment).
NVA_MIN_CHECKPOINTS = 30
#: Minimum VVA check points: 5, the smallest-project count of Ed. 1 Table C.1 (Ed. 2 keeps VVA
#: as reported only; the count is our reading, uncertain).
VVA_MIN_CHECKPOINTS = 5


@dataclass(frozen=True)
class LidarAccuracyOptions:
    """How swaths are found, which cells are smooth, and the class to test against.

    Lengths in the cloud's units (metres for the standard's classes), angles in degrees.
    """

    #: Grid cell (m). ASPRS/USGS practice: about twice the nominal pulse spacing or more; the
    #: plane fit needs ``min_points`` returns of one swath in a cell.
    cell_size: float = 1.0
    #: Least returns of one swath in a cell for its plane fit.
    min_points: int = 6
    #: Largest slope of a smooth cell (degrees; relative accuracy is tested on flat ground).
    max_slope_deg: float = 10.0
    #: Largest rms of the plane-fit residuals of a smooth cell (m): rejects edges, walls,
    #: rough or mixed surfaces.
    max_residual: float = 0.10
    #: Largest height step to a neighbouring cell of the same swath (m): a cell whose returns
    #: all fell on one side of an edge fits a good plane, but its neighbour across the edge
    #: does not continue it.
    max_step: float = 0.30
    #: A cell holding any return of these classes is not hard (vegetation, LAS 3-5).
    vegetation_classes: tuple[int, ...] = (3, 4, 5)
    #: When given, a cell holding any return of another class is not hard (e.g. (2, 6):
    #: ground and building; class 1 "unclassified" holds cars that move between flights).
    hard_classes: tuple[int, ...] = ()
    #: Returns of these classes are ignored (noise 7, high noise 18).
    ignore_classes: tuple[int, ...] = (7, 18)
    #: Only cells whose returns are all single returns (number of returns 1) are smooth.
    single_returns: bool = True
    #: "auto" (point source id when the cloud has more than one, else GPS time), or one of them.
    swath_source: str = "auto"
    #: A gap in GPS time longer than this starts a new swath (s).
    gps_gap_s: float = 10.0
    #: Least smooth cells for a swath pair's figures to be assessed.
    min_pair_cells: int = 30
    #: Target vertical class (cm); 0 reports the figures and the class they meet.
    v_class_cm: float = 0.0
    #: Check-point survey sigma in height (m), combined with the NVA RMSE as in Ed. 2.
    survey_sigma_v: float = 0.0
    #: LAS classes of the ground returns whose TIN is the LiDAR surface at the check points.
    ground_classes: tuple[int, ...] = (2,)
    #: Ground returns within this distance of a check point (m) make the TIN.
    tin_radius: float = 10.0
    #: Check-point land-cover groups counted as vegetated (VVA), case-insensitive; every
    #: other group is non-vegetated (NVA).
    vegetated_groups: tuple[str, ...] = (
        "vegetated",
        "vva",
        "forest",
        "brush",
        "shrub",
        "tall grass",
        "tall weeds",
        "crops",
    )
