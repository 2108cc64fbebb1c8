"""A local engineering frame: Cartesian coordinates with no CRS (close-range networks,
calibration fields), in metres or millimetres.

The frame stands where a :class:`~.frames.MappingFrame` and its
:class:`~.frames.LocalFrame` stand in an adjustment: the user's X, Y, Z (and omega-phi-kappa
relative to the frame's own axes) are taken as they are, with no projection, no datum and no
earth curvature; only the unit is converted, so that the core still works in metres
(docs/conventions.md, "Units") and a millimetre network gives the same numbers as the metre network
scaled by 1000. The adjustment frame is the user's frame shifted to an origin near the
network (the centre of its points), metres.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError

Array = NDArray[np.float64]

#: Units of an engineering frame and their length in metres.
ENGINEERING_UNITS = {"m": 1.0, "mm": 1e-3}


@dataclass(frozen=True)
class EngineeringFrame:
    """A Cartesian frame with no CRS, coordinates in ``unit`` (``m`` or ``mm``).

    >>> EngineeringFrame("mm").name
    'local engineering frame (mm)'
    """

    unit: str = "m"
    #: no projection: every CRS-dependent check (area of use, degrees) is skipped
    engineering = True

    def __post_init__(self) -> None:
        if self.unit not in ENGINEERING_UNITS:
            raise InputError(
                f"the unit of a local frame must be one of {', '.join(ENGINEERING_UNITS)}, "
                f"got {self.unit!r}"
            )

    @property
    def metres(self) -> float:
        """Length of one unit of the frame, metres."""
        return ENGINEERING_UNITS[self.unit]

    @property
    def name(self) -> str:
        return f"local engineering frame ({self.unit})"

    def to_wkt(self) -> str:
        """No CRS: the empty WKT of the tables written in this frame."""
        return ""


@dataclass(frozen=True)
class EngineeringLocal:
    """The adjustment frame of an :class:`EngineeringFrame`: the same axes, metres, origin
    at ``origin`` (frame units). Mirrors the methods of :class:`~.frames.LocalFrame` that
    the adjustments use.

    >>> loc = EngineeringLocal(EngineeringFrame("mm"), (1000.0, 0.0, 0.0))
    >>> loc.map_to_enu([[1500.0, 0.0, 20.0]]).round(6).tolist()
    [[0.5, 0.0, 0.02]]
    """

    mapping: EngineeringFrame
    origin: tuple[float, float, float]
    _origin: Array = field(init=False, repr=False)
    engineering = True

    def __post_init__(self) -> None:
        object.__setattr__(self, "_origin", np.asarray(self.origin, dtype=np.float64))

    def map_to_enu(self, enh: ArrayLike) -> Array:
        """Frame coordinates (N, 3) -> adjustment frame (N, 3), metres."""
        return (np.asarray(enh, dtype=np.float64) - self._origin) * self.mapping.metres

    def enu_to_map(self, enu: ArrayLike) -> Array:
        """Adjustment frame (N, 3), metres -> frame coordinates (N, 3)."""
        return np.asarray(enu, dtype=np.float64) / self.mapping.metres + self._origin

    def map_to_enu_jacobian(self, enh: ArrayLike, step: float = 1.0) -> tuple[Array, Array]:
        """Frame -> adjustment frame at points (K, 3) and its Jacobian (K, 3, 3)."""
        x = np.asarray(enh, dtype=np.float64).reshape(-1, 3)
        jac = np.broadcast_to(np.eye(3) * self.mapping.metres, (len(x), 3, 3)).copy()
        return self.map_to_enu(x), jac

    def enu_to_map_jacobian(self, enu: ArrayLike, step: float = 1.0) -> tuple[Array, Array]:
        """Adjustment frame -> frame at points (K, 3) and its Jacobian (K, 3, 3)."""
        x = np.asarray(enu, dtype=np.float64).reshape(-1, 3)
        jac = np.broadcast_to(np.eye(3) / self.mapping.metres, (len(x), 3, 3)).copy()
        return self.enu_to_map(x), jac
