"""Coordinate frames: mapping CRS <-> geodetic <-> ECEF <-> local ENU adjustment frame.

Every datum and projection step goes through pyproj; only the rigid ECEF <-> ENU rotation,
which is exact linear algebra, is written here with numpy (it is checked against PROJ's own
``topocentric`` conversion in the tests).

Frames (see docs/conventions.md):

- mapping frame m: the user's projected CRS (easting, northing) plus height. The height is
  ellipsoidal for a 2D projected CRS, or in the vertical datum of a compound CRS (the geoid
  grid must then be installed for PROJ; a missing grid raises :class:`CrsError`).
- geodetic: latitude, longitude in degrees and ellipsoidal height in metres on the datum of
  the mapping CRS.
- ECEF: the geocentric Cartesian frame of that datum, metres.
- adjustment frame: local east-north-up (ENU) Cartesian frame tangent to the ellipsoid at an
  origin (usually the project centre), metres.
- local-level NED at a point: north, east, down at that point's own latitude and longitude.
- grid frame at a point: grid east, grid north and the local ellipsoidal up at that point;
  it differs from local ENU by the grid convergence (a rotation about up). Omega-phi-kappa
  "in the mapping CRS" are relative to this frame.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Literal, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pyproj import CRS, Transformer
from pyproj.transformer import TransformerGroup

from ..errors import CrsError

Array = NDArray[np.float64]

# NED -> ENU axis swap: (n, e, d) -> (e, n, u)
NED_TO_ENU = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])


@overload
def parse_crs(crs: CRS | str | int, *, what: str = ..., optional: Literal[False] = ...) -> CRS: ...
@overload
def parse_crs(
    crs: CRS | str | int | None, *, what: str = ..., optional: Literal[True]
) -> CRS | None: ...
def parse_crs(
    crs: CRS | str | int | None, *, what: str = "CRS", optional: bool = False
) -> CRS | None:
    """Read a CRS given as EPSG code, ``"EPSG:xxxx"``, WKT or PROJ string; clear error if not.

    A missing CRS (None or an empty string) is an error, unless ``optional``: then None.

    >>> parse_crs("EPSG:28992").to_epsg(), parse_crs(" ", optional=True)
    (28992, None)
    """
    if isinstance(crs, CRS):
        return crs
    if crs is None or (isinstance(crs, str) and not crs.strip()):
        if optional:
            return None
        raise CrsError(f"{what} is missing: give an EPSG code (e.g. EPSG:32632) or WKT")
    if isinstance(crs, str) and crs.strip().isdigit():
        crs = int(crs)  # a bare EPSG code typed as text
    try:
        return CRS.from_user_input(crs)
    except Exception as exc:  # pyproj raises CRSError with PROJ's words; keep them
        raise CrsError(f"{what} '{str(crs)[:80]}' is not a valid CRS: {exc}") from exc


def enu_rotation(lat_deg: ArrayLike, lon_deg: ArrayLike) -> Array:
    """Rotation ``R`` with rows (east, north, up) expressed in ECEF: ``enu = R @ ecef_vector``.

    Shape ``S + (3, 3)`` for latitude/longitude arrays of shape ``S`` (degrees).
    """
    lat = np.radians(np.asarray(lat_deg, dtype=np.float64))
    lon = np.radians(np.asarray(lon_deg, dtype=np.float64))
    sl, cl = np.sin(lat), np.cos(lat)
    so, co = np.sin(lon), np.cos(lon)
    out = np.empty((*lat.shape, 3, 3))
    out[..., 0, :] = np.stack([-so, co, np.zeros_like(so)], axis=-1)
    out[..., 1, :] = np.stack([-sl * co, -sl * so, cl], axis=-1)
    out[..., 2, :] = np.stack([cl * co, cl * so, sl], axis=-1)
    return out


def ned_to_ecef_rotation(lat_deg: ArrayLike, lon_deg: ArrayLike) -> Array:
    """``R_n^e``: columns are north, east, down at (lat, lon) expressed in ECEF."""
    r_enu = enu_rotation(lat_deg, lon_deg)  # rows e, n, u
    return np.swapaxes(NED_TO_ENU @ r_enu, -1, -2)


def grid_rotation(theta: ArrayLike) -> Array:
    """Rotation from local ENU to the grid frame, given the grid azimuth ``theta`` of true north.

    ``theta`` (radians) is the clockwise angle from grid north to true north. A vector with
    true azimuth ``a`` has grid azimuth ``a + theta``; up is unchanged.
    """
    t = np.asarray(theta, dtype=np.float64)
    c, s = np.cos(t), np.sin(t)
    out = np.zeros((*t.shape, 3, 3))
    out[..., 0, 0], out[..., 0, 1] = c, s
    out[..., 1, 0], out[..., 1, 1] = -s, c
    out[..., 2, 2] = 1.0
    return out


@dataclass(frozen=True)
class MappingFrame:
    """A projected mapping CRS and the transformations the core needs around it.

    Parameters
    ----------
    crs:
        The mapping CRS (projected, optionally compound with a vertical CRS).
    """

    crs: CRS
    geodetic: CRS = field(init=False)
    geocentric: CRS = field(init=False)
    _to_geod: Transformer = field(init=False, repr=False)
    _from_geod: Transformer = field(init=False, repr=False)
    _geod_to_ecef: Transformer = field(init=False, repr=False)
    _ecef_to_geod: Transformer = field(init=False, repr=False)

    def __post_init__(self) -> None:
        crs = self.crs
        horizontal = crs.sub_crs_list[0] if crs.is_compound else crs
        if not horizontal.is_projected:
            raise CrsError(
                f"the mapping CRS must be projected (metres on a map grid); "
                f"'{crs.name}' is {crs.type_name}"
            )
        for axis in horizontal.axis_info[:2]:
            if axis.unit_name not in ("metre", "meter"):
                raise CrsError(
                    f"the mapping CRS '{crs.name}' has {axis.unit_name} units; the core works in "
                    "metres: reproject to a metric CRS first"
                )
        base = horizontal.geodetic_crs
        geodetic = base.to_3d() if base is not None else None
        ellipsoid = geodetic.ellipsoid if geodetic is not None else None
        if geodetic is None or ellipsoid is None:  # pyproj's types allow it, a projected CRS not
            raise CrsError(f"the mapping CRS '{crs.name}' names no geodetic CRS or ellipsoid")
        a, rf = ellipsoid.semi_major_metre, ellipsoid.inverse_flattening
        ell = f"+a={a!r} +rf={rf!r}" if rf else f"+a={a!r} +b={a!r}"  # rf 0: a sphere
        geocentric = CRS.from_proj4(f"+proj=geocent {ell} +units=m +no_defs")
        src = crs if crs.is_compound else horizontal.to_3d()
        object.__setattr__(self, "geodetic", geodetic)
        object.__setattr__(self, "geocentric", geocentric)
        object.__setattr__(self, "_to_geod", _exact_transformer(src, geodetic))
        object.__setattr__(self, "_from_geod", _exact_transformer(geodetic, src))
        # on one ellipsoid these are conversions: PROJ's pipelines directly (the same numbers
        # as TransformerGroup's, tested, without its 40 ms search of the database)
        to_ecef = (
            f"+proj=pipeline +step +proj=unitconvert +xy_in=deg +xy_out=rad +step +proj=cart {ell}"
        )
        from_ecef = (
            f"+proj=pipeline +step +inv +proj=cart {ell} "
            "+step +proj=unitconvert +xy_in=rad +xy_out=deg"
        )
        object.__setattr__(self, "_geod_to_ecef", Transformer.from_pipeline(to_ecef))
        object.__setattr__(self, "_ecef_to_geod", Transformer.from_pipeline(from_ecef))

    @classmethod
    def from_user_input(cls, crs: CRS | str | int) -> MappingFrame:
        return cls(parse_crs(crs, what="mapping CRS"))

    @property
    def name(self) -> str:
        """The CRS's name (the reports'; an engineering frame has one too)."""
        return str(self.crs.name)

    # -- positions -----------------------------------------------------------------------
    def map_to_geodetic(self, enh: ArrayLike) -> Array:
        """(N, 3) easting, northing, height -> (N, 3) latitude, longitude (deg), ellipsoidal h."""
        return _transform(self._to_geod, enh, latlon_in=False, latlon_out=True)

    def geodetic_to_map(self, llh: ArrayLike) -> Array:
        """(N, 3) latitude, longitude (deg), ellipsoidal h -> (N, 3) easting, northing, height."""
        return _transform(self._from_geod, llh, latlon_in=True, latlon_out=False)

    def geodetic_to_ecef(self, llh: ArrayLike) -> Array:
        return _transform(self._geod_to_ecef, llh, latlon_in=True, latlon_out=False)

    def ecef_to_geodetic(self, xyz: ArrayLike) -> Array:
        return _transform(self._ecef_to_geod, xyz, latlon_in=False, latlon_out=True)

    def map_to_ecef(self, enh: ArrayLike) -> Array:
        return self.geodetic_to_ecef(self.map_to_geodetic(enh))

    def ecef_to_map(self, xyz: ArrayLike) -> Array:
        return self.geodetic_to_map(self.ecef_to_geodetic(xyz))

    # -- orientation ---------------------------------------------------------------------
    def grid_north_azimuth(self, llh: ArrayLike, step_deg: float = 1e-4) -> Array:
        """Clockwise angle (radians) from grid north to true north at each point.

        Computed from the projection itself (central differences along the meridian), so it
        holds for any projected CRS; it is the negative of the usual "grid convergence" sign in
        some texts, hence the explicit name.
        """
        lat, lon, h = _columns(llh)
        north = self.geodetic_to_map(np.stack([lat + step_deg, lon, h], axis=-1))
        south = self.geodetic_to_map(np.stack([lat - step_deg, lon, h], axis=-1))
        d = north - south
        return np.arctan2(d[..., 0], d[..., 1])

    def ned_to_grid(self, llh: ArrayLike) -> Array:
        """``R_n^m`` per point: NED at the point -> grid frame (grid E, grid N, up)."""
        return grid_rotation(self.grid_north_azimuth(llh)) @ NED_TO_ENU


def _transform(tr: Transformer, pts: ArrayLike, *, latlon_in: bool, latlon_out: bool) -> Array:
    """(N, 3) points through ``tr``, whose geodetic side is (longitude, latitude, h): the
    core's geodetic triples are (latitude, longitude, h), swapped on the way in or out."""
    a, b, c = _columns(pts)
    u, v, w = tr.transform(b, a, c) if latlon_in else tr.transform(a, b, c)
    return np.stack([v, u, w] if latlon_out else [u, v, w], axis=-1)


def _jacobian(f, xyz: ArrayLike, step: float) -> tuple[Array, Array]:
    """``f`` at points (K, 3) and its Jacobian (K, 3, 3) by central differences."""
    x = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
    k = x.shape[0]
    if k == 0:
        return np.empty((0, 3)), np.empty((0, 3, 3))
    offsets = np.vstack([np.zeros(3), np.eye(3) * step, -np.eye(3) * step])  # (7, 3)
    t = f((x[:, None, :] + offsets[None]).reshape(-1, 3)).reshape(k, 7, 3)
    return t[:, 0], (t[:, 1:4] - t[:, 4:7]).transpose(0, 2, 1) / (2.0 * step)


@dataclass(frozen=True)
class LocalFrame:
    """Local ENU adjustment frame tangent to the ellipsoid at ``origin_llh``.

    ``origin_llh`` is (latitude, longitude in degrees, ellipsoidal height in metres).
    """

    mapping: MappingFrame
    origin_llh: tuple[float, float, float]
    origin_ecef: Array = field(init=False, repr=False)
    rotation: Array = field(init=False, repr=False)  # rows e, n, u in ECEF

    def __post_init__(self) -> None:
        lat, lon, h = (float(v) for v in self.origin_llh)
        object.__setattr__(self, "origin_llh", (lat, lon, h))
        ecef = self.mapping.geodetic_to_ecef(np.array([[lat, lon, h]]))[0]
        object.__setattr__(self, "origin_ecef", ecef)
        object.__setattr__(self, "rotation", enu_rotation(lat, lon))

    @classmethod
    def at_map_point(cls, mapping: MappingFrame, enh: ArrayLike) -> LocalFrame:
        """Frame tangent at a point given in the mapping CRS (e.g. the project centre)."""
        llh = mapping.map_to_geodetic(np.asarray(enh, dtype=np.float64).reshape(1, 3))[0]
        return cls(mapping, (llh[0], llh[1], llh[2]))

    def ecef_to_enu(self, xyz: ArrayLike) -> Array:
        return (np.asarray(xyz, dtype=np.float64) - self.origin_ecef) @ self.rotation.T

    def enu_to_ecef(self, enu: ArrayLike) -> Array:
        return np.asarray(enu, dtype=np.float64) @ self.rotation + self.origin_ecef

    def map_to_enu(self, enh: ArrayLike) -> Array:
        return self.ecef_to_enu(self.mapping.map_to_ecef(enh))

    def enu_to_map(self, enu: ArrayLike) -> Array:
        return self.mapping.ecef_to_map(self.enu_to_ecef(enu))

    def geodetic_to_enu(self, llh: ArrayLike) -> Array:
        return self.ecef_to_enu(self.mapping.geodetic_to_ecef(llh))

    def map_to_enu_jacobian(self, enh: ArrayLike, step: float = 1.0) -> tuple[Array, Array]:
        """Map -> ENU at points (K, 3) and the Jacobian ``d enu / d map`` (K, 3, 3).

        Central differences of ``step`` (CRS unit): the transformation is smooth at that scale,
        so the Jacobian is exact to far below the precision of any covariance it carries.
        """
        return _jacobian(self.map_to_enu, enh, step)

    def enu_to_map_jacobian(self, enu: ArrayLike, step: float = 1.0) -> tuple[Array, Array]:
        """ENU -> map at points (K, 3) and the Jacobian ``d map / d enu`` (K, 3, 3), metres."""
        return _jacobian(self.enu_to_map, enu, step)

    def ned_to_local(self, llh: ArrayLike) -> Array:
        """``R_n^l`` per point: NED at each point -> this ENU frame (curvature included)."""
        lat, lon, _ = _columns(llh)
        return self.rotation @ ned_to_ecef_rotation(lat, lon)

    def grid_to_local(self, llh: ArrayLike) -> Array:
        """Rotation from the grid frame at each point to this ENU frame."""
        r_ng = self.mapping.ned_to_grid(llh)
        return self.ned_to_local(llh) @ np.swapaxes(r_ng, -1, -2)


def _columns(a: ArrayLike) -> tuple[Array, Array, Array]:
    arr = np.asarray(a, dtype=np.float64)
    if arr.shape[-1] != 3:
        raise ValueError(f"expected coordinates with 3 columns, got shape {arr.shape}")
    return arr[..., 0], arr[..., 1], arr[..., 2]


def as_3d(crs: CRS) -> CRS:
    """The CRS with its heights made explicit: compound CRSs as they are, a 2D CRS with
    ellipsoidal heights (the convention of this package, docs/conventions.md)."""
    return crs if crs.is_compound or len(crs.axis_info) > 2 else crs.to_3d()


def transformer_3d(src: CRS, dst: CRS) -> Transformer:
    """(x, y, height) from ``src`` to ``dst`` with heights per :func:`as_3d`; raises
    CrsError instead of dropping a vertical datum change whose grid is not installed."""
    return _exact_transformer(as_3d(src), as_3d(dst))


def _exact_transformer(src: CRS, dst: CRS) -> Transformer:
    """Best transformation, refusing PROJ's silent 'ballpark' fallback when a grid is missing."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # reported below as a CrsError instead
        group = TransformerGroup(src, dst, always_xy=True)
    if not group.transformers:
        raise CrsError(f"no transformation from '{src.name}' to '{dst.name}' is available")
    if not group.best_available:
        missing = sorted(
            {
                grid.short_name
                for op in group.unavailable_operations
                for grid in op.grids
                if not grid.available
            }
        )
        raise CrsError(
            f"transforming '{src.name}' to '{dst.name}' needs grid(s) not installed for PROJ: "
            f"{', '.join(missing) or 'unknown'}; install them (e.g. projsync --file NAME, or copy "
            "the file into the PROJ data folder) or use ellipsoidal heights (a 2D projected CRS)"
        )
    return group.transformers[0]


#: How far (degrees of longitude and latitude) data may lie outside the area of use of its
#: CRS before it is refused: the projection still holds a little beyond the published area
#: (a block across a zone border), a wrong CRS or unit puts the data hundreds of km away.
AREA_MARGIN_DEG = 2.0


def check_area_of_use(
    crs: CRS,
    mins: ArrayLike,
    maxs: ArrayLike,
    *,
    what: str = "the data",
    path: str | None = None,
    margin_deg: float = AREA_MARGIN_DEG,
) -> None:
    """Refuse (CrsError) data whose coordinates cannot be in ``crs``.

    ``mins``/``maxs`` are the (x, y) box of the data in ``crs`` (its horizontal part for a
    compound CRS). Refused: non-finite coordinates; coordinates that look like longitude and
    latitude in degrees (within +-180/+-90 and less than one unit wide) in a projected CRS;
    a box whose corners fall more than ``margin_deg`` outside the CRS's area of use (a wrong
    CRS, a unit mix-up such as feet for metres, or swapped axes). A CRS without an area of
    use, or a geographic one, passes the last test.

    Examples
    --------
    >>> rd = CRS.from_epsg(28992)  # Amersfoort / RD New: the Netherlands
    >>> check_area_of_use(rd, (84000, 446000), (86000, 448000))  # Delft: fine
    >>> try:
    ...     check_area_of_use(rd, (4.35, 52.0), (4.36, 52.01))
    ... except CrsError as exc:
    ...     print(exc)  # doctest: +NORMALIZE_WHITESPACE
    the data (x 4.35 to 4.36, y 52 to 52.01) looks like longitude and latitude in degrees,
    not coordinates of 'Amersfoort / RD New' (projected, metre)
    >>> try:  # coordinates in feet taken as metres: 3.3 times too far from the origin
    ...     check_area_of_use(rd, (275000, 1463000), (282000, 1470000))
    ... except CrsError as exc:
    ...     print(str(exc)[:79])
    the data (x 275000 to 282000, y 1463000 to 1470000 metre) lies outside the area
    """
    lo = np.asarray(mins, dtype=np.float64).ravel()[:2]
    hi = np.asarray(maxs, dtype=np.float64).ravel()[:2]
    if not (np.isfinite(lo).all() and np.isfinite(hi).all()):
        raise CrsError(f"{what} has coordinates that are not finite numbers", path=path)
    horizontal = crs.sub_crs_list[0] if crs.is_compound and crs.sub_crs_list else crs
    if not horizontal.is_projected:
        return
    axes = horizontal.axis_info
    unit = axes[0].unit_name if axes else "unit"
    box = f"x {lo[0]:.10g} to {hi[0]:.10g}, y {lo[1]:.10g} to {hi[1]:.10g} {unit}"
    if (
        np.all(np.abs(np.r_[lo[0], hi[0]]) <= 180.0)
        and np.all(np.abs(np.r_[lo[1], hi[1]]) <= 90.0)
        and np.all(hi - lo < 1.0)
    ):
        plain = f"x {lo[0]:.10g} to {hi[0]:.10g}, y {lo[1]:.10g} to {hi[1]:.10g}"
        raise CrsError(
            f"{what} ({plain}) looks like longitude and latitude in degrees, not coordinates "
            f"of '{horizontal.name}' (projected, {unit})",
            path=path,
        )
    area = crs.area_of_use or horizontal.area_of_use
    if area is None:
        return
    west, south, east, north = area.bounds
    wrap = east < west  # the area crosses the antimeridian
    if wrap:
        east += 360.0
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            to_geo = Transformer.from_crs(horizontal, horizontal.geodetic_crs, always_xy=True)
            xs = np.array([lo[0], hi[0], hi[0], lo[0], 0.5 * (lo[0] + hi[0])])
            ys = np.array([lo[1], lo[1], hi[1], hi[1], 0.5 * (lo[1] + hi[1])])
            lon, lat = to_geo.transform(xs, ys, errcheck=False)
    except Exception:  # PROJ refuses points far outside the projection's domain
        lon = lat = np.full(5, np.nan)
    lon, lat = np.asarray(lon, dtype=np.float64), np.asarray(lat, dtype=np.float64)
    if wrap:
        lon = np.where(lon < west, lon + 360.0, lon)
    m = float(margin_deg)
    inside = (
        np.isfinite(lon)
        & np.isfinite(lat)
        & (lon >= west - m)
        & (lon <= east + m)
        & (lat >= south - m)
        & (lat <= north + m)
    )
    if not inside.all():
        k = int(np.argmin(inside))
        where = (
            f"a corner maps to longitude {lon[k]:.2f}, latitude {lat[k]:.2f} deg"
            if np.isfinite(lon[k]) and np.isfinite(lat[k])
            else "a corner is outside the projection's domain"
        )
        raise CrsError(
            f"{what} ({box}) lies outside the area of use of '{horizontal.name}' "
            f"({area.name.rstrip('.')}: longitude {area.west:g} to {area.east:g}, latitude "
            f"{area.south:g} "
            f"to {area.north:g} deg; {where}): wrong CRS, or coordinates in another unit or "
            "axis order",
            path=path,
        )


def check_points_in_area(
    crs: CRS, xyz: ArrayLike, *, what: str = "the data", path: str | None = None
) -> None:
    """:func:`check_area_of_use` on the box of the points ``xyz`` ((N, 2) or (N, 3), in
    ``crs``); nothing to check for no points.

    >>> check_points_in_area(CRS.from_epsg(28992), [[84000.0, 446000.0, 0.0]])  # Delft
    """
    p = np.asarray(xyz, dtype=np.float64)
    if p.size:
        check_area_of_use(crs, p.min(axis=0), p.max(axis=0), what=what, path=path)
