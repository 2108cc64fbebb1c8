"""The options of orthophotos (:mod:`.orthophoto`) and orthomosaics (:mod:`.mosaic`), kept
apart from their numba and pyproj code so that the algorithms' specs read their defaults and
choices without importing it (core/jobs/orthorectify.py, core/jobs/orthomosaic.py)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import InputError

#: Resampling of the image into the orthophoto's cells.
RESAMPLING = ("nearest", "bilinear", "cubic")
#: Which orthophoto a mosaic cell takes (:mod:`.mosaic`, module docstring).
MOSAIC_METHODS = ("nadir", "centre")


@dataclass(frozen=True)
class OrthoOptions:
    """How orthophotos are made.

    Attributes
    ----------
    gsd : float
        Cell size of the output, CRS unit; 0: the image's nadir GSD at the median surface
        height, to 2 significant digits (:func:`auto_gsd`).
    resampling : {"nearest", "bilinear", "cubic"}
    true_ortho : bool
        Make occluded ground no data (module docstring, step 5); on by default, as the
        algorithm's title says (off: a plain orthophoto, cheaper on a bare-earth DTM).
    occlusion_tol_m : float
        A surface hit this much (CRS unit, along the ray) before the ground point occludes it.
    tile_px : int
        Side of the tiles processed at once, cells.
    lattice_px : int
        Spacing of the exact projection nodes within a tile, cells.
    workers : int
        Threads (0: one per CPU, at most 4).
    antialias : bool
        Where a cell spans f >= 2 image pixels, resample the image averaged over f x f
        pixels (else the resampling aliases fine texture).
    """

    gsd: float = 0.0
    resampling: str = "bilinear"
    true_ortho: bool = True
    occlusion_tol_m: float = 0.05
    tile_px: int = 512
    lattice_px: int = 64
    workers: int = 0
    antialias: bool = True

    def __post_init__(self) -> None:
        if self.resampling not in RESAMPLING:
            raise InputError(
                f"resampling must be one of {', '.join(RESAMPLING)}, got {self.resampling!r}"
            )
        if not (self.gsd >= 0 and math.isfinite(self.gsd)):
            raise InputError(f"GSD must be >= 0 (0: automatic), got {self.gsd!r}")
        if int(self.tile_px) < 16 or int(self.lattice_px) < 2:
            raise InputError("tile_px must be >= 16 and lattice_px >= 2")
        if not self.occlusion_tol_m >= 0:
            raise InputError(f"occlusion tolerance must be >= 0, got {self.occlusion_tol_m!r}")


@dataclass(frozen=True)
class MosaicOptions:
    """How the mosaic is made (module docstring).

    Attributes
    ----------
    method : {"nadir", "centre"}
    feather_px : float
        Width of the blend across seamlines, cells (0: none, a hard seam).
    tile_px : int
    workers : int
        Threads (0: one per CPU, at most 4).
    """

    method: str = "nadir"
    feather_px: float = 0.0
    tile_px: int = 512
    workers: int = 0

    def __post_init__(self) -> None:
        if self.method not in MOSAIC_METHODS:
            raise InputError(
                f"method must be one of {', '.join(MOSAIC_METHODS)}, got {self.method!r}"
            )
        if not (self.feather_px >= 0 and math.isfinite(self.feather_px)):
            raise InputError(f"feathering must be >= 0 cells, got {self.feather_px!r}")
