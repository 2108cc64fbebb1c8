"""A network of scanner stations observing targets: the observations, station and control
data, the checks a network must pass, and approximate values by rigid-body registration.

Object frame: a local right-handed Cartesian frame in metres, z up (the frame of the control,
or of the reference station when there is none). A station's pose is its position ``X0`` and
the rotation ``M = R3(kappa) R2(phi) R1(omega)`` from the object frame into its scanner frame
(Carvalho, Correa & dos Santos, Eq. 1)::

    d = M (X - X0)

so a levelled scanner has omega = phi = 0 and kappa is the angle from the object x axis to the
scanner's x axis, counter-clockwise seen from above (the scanner's zero direction: its x axis
is the object direction (cos kappa, sin kappa, 0), the first row of M). The scanner frame
and the polar observations are defined in :mod:`.polar`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ..geometry.rotations import matrix_to_opk, opk_to_matrix
from .polar import face_of, polar_to_cartesian

__all__ = [
    "ControlTarget",
    "StationInfo",
    "TlsObservations",
    "check_network",
    "distance_consistency",
    "kabsch",
    "register_stations",
]

Array = NDArray[np.float64]
#: A vertical angle this close to the zenith or nadir (radians) leaves the horizontal
#: direction undefined: such observations are refused.
ZENITH_GUARD_RAD = math.radians(0.5)


@dataclass(frozen=True)
class TlsObservations:
    """Polar observations of targets from stations (one row per station, target and face).

    Attributes
    ----------
    station, target : tuple of str, shape (N,)
    polar : ndarray, shape (N, 3)
        Recorded range (m), horizontal direction and vertical angle (radians, elevation);
        a vertical angle beyond +-90 degrees is a face-II reading (:mod:`.polar`).
    cov : ndarray, shape (N, 3, 3)
        Covariance of (range, horizontal, vertical) in m^2, m rad, rad^2.
    rows : ndarray of int, shape (N,)
        Row numbers in the source table (header = 1), for messages; 0 when unknown.
    path : str or None
        The source file, for messages.
    """

    station: tuple[str, ...]
    target: tuple[str, ...]
    polar: Array
    cov: Array
    rows: NDArray[np.int64] = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    path: str | None = None

    def __post_init__(self) -> None:
        n = len(self.station)
        polar = np.asarray(self.polar, dtype=np.float64).reshape(n, 3)
        cov = np.asarray(self.cov, dtype=np.float64).reshape(n, 3, 3)
        rows = np.asarray(self.rows, dtype=np.int64)
        if rows.size != n:
            rows = np.zeros(n, dtype=np.int64)
        object.__setattr__(self, "polar", polar)
        object.__setattr__(self, "cov", cov)
        object.__setattr__(self, "rows", rows)
        object.__setattr__(self, "station", tuple(str(s) for s in self.station))
        object.__setattr__(self, "target", tuple(str(s) for s in self.target))
        if len(self.target) != n:
            raise InputError("station and target lists differ in length")

    def __len__(self) -> int:
        return len(self.station)

    @property
    def face_two(self) -> NDArray[np.bool_]:
        """True for face-II readings."""
        return face_of(self.polar[:, 2])

    def scanner_xyz(self) -> Array:
        """(N, 3) points in each station's scanner frame (no AP corrections)."""
        return polar_to_cartesian(self.polar)

    def stations(self) -> list[str]:
        """Station ids in order of first appearance."""
        return list(dict.fromkeys(self.station))

    def targets(self) -> list[str]:
        """Target ids in order of first appearance."""
        return list(dict.fromkeys(self.target))

    def subset(self, keep: ArrayLike) -> TlsObservations:
        """The rows where ``keep`` is True (or the given indices)."""
        idx = np.arange(len(self))[np.asarray(keep)]
        return TlsObservations(
            tuple(self.station[i] for i in idx),
            tuple(self.target[i] for i in idx),
            self.polar[idx],
            self.cov[idx],
            self.rows[idx],
            self.path,
        )

    def where(self, k: int) -> dict:
        """Keyword arguments of :class:`InputError` locating observation ``k``."""
        row = int(self.rows[k]) if self.rows[k] > 0 else None
        return {"path": self.path, "row": row}


@dataclass(frozen=True)
class StationInfo:
    """What is known of a station before the adjustment (a row of the stations table).

    Attributes
    ----------
    id : str
    xyz : ndarray (3,) or None
        Approximate (or, for the reference station, datum) position, object frame, metres.
    opk : ndarray (3,) or None
        Approximate omega, phi, kappa (radians). For a levelled station omega and phi are the
        compensator's readings (observations with ``tilt_sigma``).
    levelled : bool or None
        The compensator levelled the scanner (omega, phi observed); None: the option's default.
    row : int
        Row in the source table (0 unknown), for messages.
    """

    id: str
    xyz: Array | None = None
    opk: Array | None = None
    levelled: bool | None = None
    row: int = 0


@dataclass(frozen=True)
class ControlTarget:
    """A target with known object coordinates.

    Attributes
    ----------
    id : str
    xyz : ndarray (3,)
        Object frame, metres.
    sigma : ndarray (3,)
        Standard deviations (m); all zero: held fixed (error-free reference, as in the paper).
    row : int
        Row in the source table, for messages.
    """

    id: str
    xyz: Array
    sigma: Array
    row: int = 0

    @property
    def fixed(self) -> bool:
        return bool(np.all(np.asarray(self.sigma) == 0.0))


def check_network(
    obs: TlsObservations, control: Sequence[ControlTarget] = (), min_targets: int = 3
) -> None:
    """Refuse a network the adjustment cannot use, naming the file and row.

    - a row repeated (the same station, target and face twice);
    - a target seen by one station only that is not a control target (it adds as many
      unknowns as observations: nothing to check it with);
    - a station with fewer than ``min_targets`` targets (its six pose parameters need three
      points);
    - a vertical angle within 0.5 degrees of the zenith or nadir (horizontal direction
      undefined);
    - ranges that are not positive, covariances that are not positive definite.

    >>> cov = np.tile(np.eye(3) * 1e-6, (2, 1, 1))
    >>> o = TlsObservations(("s1", "s2"), ("t1", "t1"), [[5, 0, 0], [5, 1, 0]], cov)
    >>> try:
    ...     check_network(o)
    ... except InputError as exc:
    ...     print(exc)
    station 's1' observes 1 target(s); at least 3 are needed to orient it
    """
    n = len(obs)
    if n == 0:
        raise InputError("no observations", path=obs.path)
    bad = np.flatnonzero(~(obs.polar[:, 0] > 0))
    if bad.size:
        k = int(bad[0])
        raise InputError(f"range {obs.polar[k, 0]:g} m is not positive", **obs.where(k))
    alpha = (obs.polar[:, 2] + math.pi / 2) % (2 * math.pi) - math.pi / 2
    near = np.flatnonzero(np.abs(np.cos(alpha)) < math.sin(ZENITH_GUARD_RAD))
    if near.size:
        k = int(near[0])
        raise InputError(
            f"vertical angle {math.degrees(obs.polar[k, 2]):.4f} deg is within 0.5 deg of the "
            "zenith or nadir: the horizontal direction is undefined there (leave the target out)",
            **obs.where(k),
        )
    try:
        np.linalg.cholesky(obs.cov)
    except np.linalg.LinAlgError:
        ev = np.linalg.eigvalsh(obs.cov)[:, 0]
        k = int(np.flatnonzero(ev <= 0)[0]) if (ev <= 0).any() else 0
        raise InputError(
            "the covariance of the observation is not positive definite (a sigma of zero?)",
            **obs.where(k),
        ) from None
    face = obs.face_two
    seen: dict[tuple[str, str, bool], int] = {}
    for k, key in enumerate(zip(obs.station, obs.target, face)):
        if key in seen:
            first = seen[key]
            where = f"row {int(obs.rows[first])}" if obs.rows[first] > 0 else "before"
            raise InputError(
                f"station '{key[0]}' observes target '{key[1]}' twice in face "
                f"{'II' if key[2] else 'I'} (first in {where}): keep one (or average them)",
                **obs.where(k),
            )
        seen[key] = k
    controlled = {c.id for c in control}
    stations_of: dict[str, set[str]] = {}
    first_row: dict[str, int] = {}
    for k, (s, t) in enumerate(zip(obs.station, obs.target)):
        stations_of.setdefault(t, set()).add(s)
        first_row.setdefault(t, k)
    for t, ss in stations_of.items():
        if len(ss) < 2 and t not in controlled:
            k = first_row[t]
            raise InputError(
                f"target '{t}' is seen by station '{next(iter(ss))}' only and is not a control "
                "target: it cannot be checked or contribute (observe it from a second station, "
                "give its coordinates as control, or remove it)",
                **obs.where(k),
            )
    targets_of: dict[str, set[str]] = {}
    first_station_row: dict[str, int] = {}
    for k, (s, t) in enumerate(zip(obs.station, obs.target)):
        targets_of.setdefault(s, set()).add(t)
        first_station_row.setdefault(s, k)
    for s, ts in targets_of.items():
        if len(ts) < min_targets:
            raise InputError(
                f"station '{s}' observes {len(ts)} target(s); at least {min_targets} are needed "
                "to orient it",
                **obs.where(first_station_row[s]),
            )


def distance_consistency(obs: TlsObservations) -> tuple[float, str]:
    """Median relative disagreement of target-to-target distances between stations.

    A rigid body keeps its distances: the distance between two targets computed from one
    station's observations must equal that from any other station, to within the noise and
    the scanner's systematic errors (a few 1e-4 at most). Angles in the wrong unit (gon read
    as degrees) or a wrong angle convention break this by percent.

    Returns
    -------
    median : float
        Median of ``|d_a - d_b| / mean(d_a, d_b)`` over every pair of targets seen by two
        stations (NaN when no two stations share two targets).
    worst : str
        The station pair with the largest median, for messages.
    """
    xyz = obs.scanner_xyz()
    face = obs.face_two
    by_station: dict[str, dict[str, Array]] = {}
    for k, (s, t) in enumerate(zip(obs.station, obs.target)):
        if not face[k]:
            by_station.setdefault(s, {})[t] = xyz[k]
    ids = list(by_station)
    meds, names = [], []
    for i in range(len(ids)):
        for j in range(i + 1, len(ids)):
            a, b = by_station[ids[i]], by_station[ids[j]]
            common = [t for t in a if t in b]
            if len(common) < 2:
                continue
            pa = np.array([a[t] for t in common])
            pb = np.array([b[t] for t in common])
            iu = np.triu_indices(len(common), 1)
            da = np.linalg.norm(pa[:, None] - pa[None], axis=-1)[iu]
            db = np.linalg.norm(pb[:, None] - pb[None], axis=-1)[iu]
            ok = (da + db) > 1e-6
            rel = np.abs(da - db)[ok] / (0.5 * (da + db)[ok])
            if rel.size:
                meds.append(float(np.median(rel)))
                names.append(f"'{ids[i]}' and '{ids[j]}'")
    if not meds:
        return math.nan, ""
    worst = int(np.argmax(meds))
    return float(np.median(meds)), names[worst]


#: A median disagreement of target-to-target distances between stations beyond this
#: (relative) is not a scanner error but a wrong angle unit or convention.
MAX_DISTANCE_DISAGREEMENT = 0.005


def check_distance_consistency(obs: TlsObservations, *, path: str | None = None) -> float:
    """:func:`distance_consistency`'s median (NaN without two stations sharing two targets),
    refused when it exceeds :data:`MAX_DISTANCE_DISAGREEMENT`: the angles are then in another
    unit or convention (``path``, the observations' file, names the error)."""
    median, pair = distance_consistency(obs)
    if math.isfinite(median) and median > MAX_DISTANCE_DISAGREEMENT:
        raise InputError(
            f"the distances between targets disagree by {100 * median:.2g} % (median) between "
            f"stations (worst: {pair}); a scanner error is a few 0.01 %: the angles are in "
            "another unit (gon read as degrees?) or another convention (zenith angle instead "
            "of elevation?)",
            path=path,
        )
    return median


def kabsch(src: ArrayLike, dst: ArrayLike) -> tuple[Array, Array, float]:
    """Rigid motion ``dst ~ R src + t`` by least squares (Kabsch's SVD solution).

    Returns ``(R, t, rms)``; raises :class:`InputError` when the points are (nearly)
    collinear, since the rotation about their line is then undetermined.

    >>> r = opk_to_matrix(0.1, -0.2, 0.3).T
    >>> p = np.array([[0, 0, 0], [1, 0, 0], [0, 2, 0], [0, 0, 3.0]])
    >>> R, t, rms = kabsch(p, p @ r.T + [1, 2, 3])
    >>> bool(np.allclose(R, r)), np.round(t, 9).tolist(), rms < 1e-12
    (True, [1.0, 2.0, 3.0], True)
    """
    a = np.asarray(src, dtype=np.float64)
    b = np.asarray(dst, dtype=np.float64)
    ca, cb = a.mean(axis=0), b.mean(axis=0)
    h = (a - ca).T @ (b - cb)
    u, s, vt = np.linalg.svd(h)
    if s[1] <= 1e-9 * max(s[0], 1e-300):
        raise InputError("the common targets are collinear: the rotation is undetermined")
    sign = np.sign(np.linalg.det(vt.T @ u.T)) or 1.0
    r = vt.T @ np.diag([1.0, 1.0, sign]) @ u.T
    t = cb - r @ ca
    rms = float(np.sqrt(np.mean(np.sum((a @ r.T + t - b) ** 2, axis=1))))
    return r, t, rms


def register_stations(
    obs: TlsObservations,
    control: Sequence[ControlTarget] = (),
    stations: Sequence[StationInfo] = (),
    reference: str | None = None,
) -> tuple[dict[str, Array], dict[str, Array], str | None]:
    """Approximate station poses and target coordinates by chained rigid-body registration.

    With control, each station that sees three control targets is registered to them; without,
    the reference station (the first of ``stations`` with a position, else the first station
    of the observations) is put at its given pose (or the origin, unrotated). Then, repeatedly,
    the station sharing most targets with those already placed is registered to them (at
    least three, not collinear) and its targets join the placed set (averaged).

    Returns
    -------
    poses : dict of str to ndarray (6,)
        X0 (3) and omega, phi, kappa (radians) per station.
    targets : dict of str to ndarray (3,)
        Approximate object coordinates of every target.
    reference : str or None
        The station that defined the frame (None with control).

    Raises
    ------
    InputError
        A station cannot be connected (fewer than three targets in common with the rest).
    """
    xyz = obs.scanner_xyz()
    local: dict[str, dict[str, list[Array]]] = {}
    for k, (s, t) in enumerate(zip(obs.station, obs.target)):
        local.setdefault(s, {}).setdefault(t, []).append(xyz[k])
    points = {s: {t: np.mean(v, axis=0) for t, v in d.items()} for s, d in local.items()}
    known: dict[str, list[Array]] = {}
    poses: dict[str, Array] = {}
    info = {st.id: st for st in stations}
    ref_id = None
    ctrl = {c.id: np.asarray(c.xyz, dtype=np.float64) for c in control}

    def place(s: str, r_ss_to_obj: Array, t: Array) -> None:
        m = r_ss_to_obj.T  # object -> scanner
        om, ph, ka = matrix_to_opk(m)
        poses[s] = np.array([*t, float(om), float(ph), float(ka)])
        for tid, p in points[s].items():
            known.setdefault(tid, []).append(r_ss_to_obj @ p + t)

    order = obs.stations()
    if ctrl:
        for s in order:
            common = [t for t in points[s] if t in ctrl]
            if len(common) >= 3:
                try:
                    r, shift, _ = kabsch([points[s][c] for c in common], [ctrl[c] for c in common])
                except InputError:
                    continue
                place(s, r, shift)
        for tid, p in ctrl.items():
            known.setdefault(tid, []).insert(0, p)
    if not poses:
        if reference is not None and reference not in points:
            raise InputError(f"the reference station '{reference}' has no observations")
        with_pose = [s.id for s in stations if s.xyz is not None and s.id in points]
        ref_id = reference or (with_pose[0] if with_pose else order[0])
        st = info.get(ref_id)
        x0 = st.xyz if st is not None and st.xyz is not None else np.zeros(3)
        opk = st.opk if st is not None and st.opk is not None else np.zeros(3)
        place(ref_id, opk_to_matrix(*opk).T, np.asarray(x0, dtype=np.float64))
    while len(poses) < len(points):
        best: str | None = None
        best_common: list[str] = []
        for s in order:
            if s in poses:
                continue
            common = [t for t in points[s] if t in known]
            if len(common) > len(best_common):
                best, best_common = s, common
        if best is None or len(best_common) < 3:
            missing = [s for s in order if s not in poses]
            k = obs.station.index(missing[0])
            raise InputError(
                f"station '{missing[0]}' shares fewer than 3 targets with the stations already "
                f"registered ({', '.join(sorted(poses)) or 'none'}): it cannot be connected to "
                "the network",
                **obs.where(k),
            )
        src = [points[best][c] for c in best_common]
        dst = [np.mean(known[c], axis=0) for c in best_common]
        try:
            r, shift, _ = kabsch(src, dst)
        except InputError:
            k = obs.station.index(best)
            raise InputError(
                f"station '{best}': its targets in common with the network are collinear",
                **obs.where(k),
            ) from None
        place(best, r, shift)
    targets = {tid: np.mean(v, axis=0) for tid, v in known.items()}
    for tid, p in ctrl.items():
        targets[tid] = p
    return poses, targets, ref_id
