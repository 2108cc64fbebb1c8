"""Positional accuracy of check points: discrepancies, statistics, tests and standards.

Sign convention: a discrepancy is ``d = measured - reference`` (the product minus the
independent, more accurate source), per component dE, dN, dU (up: the height) in metres, in
one projected CRS (the mapping frame of docs/conventions.md).
``dHorizontal = sqrt(dE^2 + dN^2)`` and ``d3D = sqrt(dE^2 + dN^2 + dU^2)``. The names of
the figures (RMSE_E, RMSE_N, RMSE_U, RMSE_HORIZONTAL, RMSE_3D, ...) are one scheme for the
JSON, the HTML, the QGIS outputs and the layers: docs/formats.md, "Accuracy figures".

The check-point and point tables (CSV) are read by :mod:`core.io.checkpoints`.

Statistics (per component and per group, and overall): mean, sample standard deviation
(n - 1), RMSE = sqrt(mean(d^2)), minimum, maximum; Shapiro-Wilk normality test (W, p,
decision at alpha; scipy's implementation of Royston's algorithm); Student's t test of a
zero mean (bias), two-sided; chi-square test of the standard deviation against a declared
precision sigma0, one-sided (``(n-1) s^2 / sigma0^2 <= chi2_{1-alpha, n-1}`` accepts the
declared precision). Outliers are screened by the robust modified z-score of Iglewicz and
Hoaglin (1993) (``|0.6745 (x - median) / MAD| > 3.5``) or by three sigma
(``|x - mean| > 3 s``) before any statistic is computed; flagged points are always reported
and only excluded from the statistics when the caller asks, and the overall statistics are
then also given the other way (without the flagged points, or with them), so that a gross
blunder is seen for what it does to the figures.
"""

from __future__ import annotations

import datetime
import logging
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from numpy.typing import NDArray

from ..errors import CrsError, InputError, stop_if_asked
from .accuracy_options import STANDARD_KEYS, AccuracySettings
from .accuracy_statistics import (
    COMPONENTS,
    HORIZONTAL,
    OUTLIER_RULES,
    THREE_D,
    GroupStatistics,
    OutlierScreen,
    group_statistics,
    screen_outliers,
)
from .html_table import TR_CONTEXT  # noqa: F401 - make i18n collects the _t("...") marks
from .standards import StandardResult, _t
from .standards_asprs import asprs_2023
from .standards_nssda import nssda
from .standards_pec import pec_pcd
from .standards_project import project_threshold

__all__ = [
    "OUTLIER_RULES",
    "STANDARD_KEYS",
    "AccuracyReport",
    "AccuracySettings",
    "CheckPoints",
    "PointSet",
    "assess_accuracy",
    "check_unique_ids",
    "join_points",
    "point_set",
]

log = logging.getLogger(__name__)

#: The coordinates as the point tables name them (columns e, n, h), for error messages.
_COORDINATES = ("E", "N", "H")


# ----------------------------------------------------------------------------- inputs


@dataclass(frozen=True)
class PointSet:
    """Points with ids, read from one table or layer.

    ``xyz`` (N, 3) float64 in metres (E, N, H); ``groups`` ``""`` when not grouped; ``crs``
    an authority id or WKT, None when unknown; ``locations`` the row numbers (tables, header
    is row 1) or feature ids (layers) used in error messages, ``location_kind`` says which.
    """

    ids: tuple[str, ...]
    xyz: NDArray[np.float64]
    groups: tuple[str, ...]
    crs: str | None = None
    source: str = ""
    locations: tuple[int, ...] = ()
    location_kind: str = "row"

    def __len__(self) -> int:
        return len(self.ids)


@dataclass(frozen=True)
class CheckPoints:
    """Measured and reference positions of the same points, (N, 3) each, in one CRS."""

    ids: tuple[str, ...]
    measured: NDArray[np.float64]
    reference: NDArray[np.float64]
    groups: tuple[str, ...]
    crs: str | None = None
    source: str = ""

    def __len__(self) -> int:
        return len(self.ids)

    @property
    def discrepancies(self) -> NDArray[np.float64]:
        """``measured - reference``, (N, 3), metres."""
        return self.measured - self.reference


def point_set(
    ids: Sequence[object],
    xyz: NDArray[np.float64],
    groups: Sequence[object] | None = None,
    *,
    crs: str | None = None,
    source: str = "",
    locations: Sequence[int] | None = None,
    location_kind: str = "feature",
) -> PointSet:
    """Build a validated :class:`PointSet` (used by the QGIS adapter for layers).

    Raises :class:`InputError` naming the source, the feature/row and the coordinate for
    empty ids, duplicate ids and NaN or infinite coordinates.

    Examples
    --------
    >>> ps = point_set(["a", "b"], np.array([[0.0, 0, 0], [1, 1, 1]]))
    >>> len(ps), ps.groups
    (2, ('', ''))
    """
    ids_ = tuple("" if i is None else str(i).strip() for i in ids)
    arr = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
    if len(arr) != len(ids_):
        raise InputError(f"{len(ids_)} ids but {len(arr)} positions", path=source or None)
    locs = (
        tuple(int(v) for v in locations)
        if locations is not None
        else tuple(range(1, len(ids_) + 1))
    )
    grp = tuple("" if g is None else str(g) for g in groups) if groups is not None else None
    if grp is None:
        grp = ("",) * len(ids_)
    kind = location_kind

    def where(k: int) -> str:
        return f"{kind} {locs[k]}"

    for k, value in enumerate(ids_):
        if not value or value.upper() == "NULL":
            raise InputError(f"{where(k)}: empty id", path=source or None)
    bad = np.argwhere(~np.isfinite(arr))
    if len(bad):
        k, c = (int(v) for v in bad[0])
        raise InputError(
            f"{where(k)} (id '{ids_[k]}'): {_COORDINATES[c]} is not a finite number "
            f"({len(np.unique(bad[:, 0]))} point(s) affected)",
            path=source or None,
            column=_COORDINATES[c],
        )
    check_unique_ids(ids_, [where(k) for k in range(len(ids_))], source)
    return PointSet(ids_, arr, grp, crs or None, source, locs, kind)


def check_unique_ids(ids: Sequence[str], where: Sequence[str], source: str) -> None:
    first: dict[str, int] = {}
    dups = []
    for k, value in enumerate(ids):
        if value in first:
            dups.append(f"'{value}' ({where[first[value]]} and {where[k]})")
        else:
            first[value] = k
    if dups:
        raise InputError(
            f"duplicate id{'s' if len(dups) > 1 else ''}: {', '.join(dups[:10])}"
            + (f" and {len(dups) - 10} more" if len(dups) > 10 else ""),
            path=source or None,
        )


def _same_crs(a: str | None, b: str | None) -> bool:
    if not a or not b or a == b:
        return True
    from pyproj import CRS
    from pyproj.exceptions import CRSError

    try:
        return CRS.from_user_input(a) == CRS.from_user_input(b)
    except CRSError as exc:
        raise CrsError(f"cannot read the CRS ({exc})") from exc


def _crs_name(crs: str) -> str:
    try:
        from pyproj import CRS

        c = CRS.from_user_input(crs)
        auth = c.to_authority()
        return f"{c.name} ({':'.join(auth)})" if auth else c.name
    except Exception:
        return crs[:60]


def join_points(measured: PointSet, reference: PointSet) -> CheckPoints:
    """Pair measured and reference points by id.

    Raises
    ------
    CrsError
        The two sets are in different CRSs (reproject one first).
    InputError
        Ids present in one set only (all of them named).

    The order and the groups are those of ``measured`` (the groups of ``reference`` are used
    when ``measured`` has none).
    """
    if not _same_crs(measured.crs, reference.crs):
        raise CrsError(
            f"the measured points ({measured.source or 'measured'}) are in "
            f"{_crs_name(measured.crs or '')} but the reference points "
            f"({reference.source or 'reference'}) in {_crs_name(reference.crs or '')}; "
            "give both in one CRS (in QGIS, REPROJECT reprojects the reference layer)"
        )
    ref_index = {value: k for k, value in enumerate(reference.ids)}
    missing = [i for i in measured.ids if i not in ref_index]
    meas_set = set(measured.ids)
    extra = [i for i in reference.ids if i not in meas_set]
    if missing or extra:
        parts = []
        if missing:
            parts.append(
                f"{len(missing)} measured id(s) without a reference point: "
                + ", ".join(f"'{m}'" for m in missing[:20])
                + (" ..." if len(missing) > 20 else "")
            )
        if extra:
            parts.append(
                f"{len(extra)} reference id(s) without a measured point: "
                + ", ".join(f"'{m}'" for m in extra[:20])
                + (" ..." if len(extra) > 20 else "")
            )
        raise InputError(
            "unmatched ids between "
            f"{measured.source or 'measured'} and {reference.source or 'reference'}: "
            + "; ".join(parts)
        )
    order = np.array([ref_index[i] for i in measured.ids], dtype=np.int64)
    groups = measured.groups
    if not any(groups):
        groups = tuple(reference.groups[k] for k in order)
    return CheckPoints(
        measured.ids,
        measured.xyz,
        reference.xyz[order],
        groups,
        measured.crs or reference.crs,
        f"{measured.source} / {reference.source}",
    )


# ----------------------------------------------------------------------------- the report


@dataclass(frozen=True)
class AccuracyReport:
    """Result of :func:`assess_accuracy`.

    ``discrepancies`` (N, 3); ``used`` (N,) the points in the statistics (all unless
    outliers are excluded); ``overall`` and ``groups`` the statistics; ``standards`` the
    verdicts on the used points of all groups; ``group_thresholds`` the project threshold per
    group (as Pedrosa & dos Santos (2020) judge each flight direction); ``contrast`` the
    overall statistics of the other choice when points were flagged: without them when they
    are kept, with them when they are excluded (None when nothing was flagged).
    """

    points: CheckPoints
    settings: AccuracySettings
    discrepancies: NDArray[np.float64]
    outliers: OutlierScreen
    used: NDArray[np.bool_]
    overall: GroupStatistics
    groups: dict[str, GroupStatistics]
    standards: tuple[StandardResult, ...]
    group_thresholds: dict[str, StandardResult] = field(default_factory=dict)
    created: str = ""
    contrast: GroupStatistics | None = None

    @property
    def horizontal(self) -> NDArray[np.float64]:
        return np.hypot(self.discrepancies[:, 0], self.discrepancies[:, 1])

    @property
    def d3(self) -> NDArray[np.float64]:
        return np.linalg.norm(self.discrepancies, axis=1)

    @property
    def rmse(self) -> dict[str, float]:
        """RMSE_E, RMSE_N, RMSE_U (height), RMSE_HORIZONTAL, RMSE_3D of the used points (m)."""
        return _rmse_of(self.overall)

    @property
    def rmse_contrast(self) -> dict[str, float]:
        """The same RMSEs for :attr:`contrast` (empty when nothing was flagged)."""
        return _rmse_of(self.contrast) if self.contrast is not None else {}


def _rmse_of(stats: GroupStatistics) -> dict[str, float]:
    c = stats.components
    return {
        "RMSE_E": c["E"].rmse,
        "RMSE_N": c["N"].rmse,
        "RMSE_U": c["U"].rmse,
        "RMSE_HORIZONTAL": c[HORIZONTAL].rmse,
        "RMSE_3D": c[THREE_D].rmse,
    }


def _tick(progress, should_stop, fraction: float) -> None:
    stop_if_asked(should_stop, "making the accuracy report")
    if progress is not None:
        progress(fraction)


def assess_accuracy(
    points: CheckPoints,
    settings: AccuracySettings | None = None,
    *,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> AccuracyReport:
    """Discrepancies, outlier screening, statistics per group and overall, and standards.

    Parameters
    ----------
    points : CheckPoints
        N >= 1 pairs in one projected CRS (metres).
    settings : AccuracySettings, optional
        Defaults: alpha 0.05, robust outlier screening without exclusion, every standard.

    Returns
    -------
    AccuracyReport

    Examples
    --------
    >>> ref = np.zeros((4, 3)); meas = ref + [[0.1, 0, 0], [-0.1, 0, 0], [0, 0.1, 0], [0, -0.1, 0]]
    >>> r = assess_accuracy(CheckPoints(("a", "b", "c", "d"), meas, ref, ("",) * 4))
    >>> round(r.rmse["RMSE_HORIZONTAL"], 3)
    0.1
    """
    s = (settings or AccuracySettings()).validated()
    if len(points) == 0:
        raise InputError("no check points")
    d = points.discrepancies
    if not np.all(np.isfinite(d)):
        k = int(np.argwhere(~np.isfinite(d))[0, 0])
        raise InputError(f"point '{points.ids[k]}' has a coordinate that is not a number")
    _tick(progress, should_stop, 0.05)
    outliers = screen_outliers(d, s.outlier_rule)
    used = ~outliers.any if s.exclude_outliers else np.ones(len(d), dtype=bool)
    if not used.any():
        raise InputError("every point was flagged as an outlier; nothing left to assess")
    sig = (s.declared_sigma_h, s.declared_sigma_h, s.declared_sigma_v)
    du = d[used]
    flagged = outliers.any
    n_flag = int(flagged.sum())
    without = _t("without the {n} flagged point(s)", n=n_flag)
    label = without if s.exclude_outliers and n_flag else _t("all points")
    overall = group_statistics(du, label, alpha=s.alpha, declared_sigma=sig)
    contrast = None
    if n_flag:  # the user sees what the flagged points do to the figures, both ways
        other = np.ones(len(d), dtype=bool) if s.exclude_outliers else ~flagged
        if other.any():
            other_label = _t("all points (flagged included)") if s.exclude_outliers else without
            contrast = group_statistics(d[other], other_label, alpha=s.alpha, declared_sigma=sig)
    _tick(progress, should_stop, 0.3)
    groups: dict[str, GroupStatistics] = {}
    thresholds: dict[str, StandardResult] = {}
    names = list(dict.fromkeys(points.groups))
    garr = np.asarray(points.groups, dtype=object)
    if len(names) > 1 or (names and names[0]):
        for g in names:
            mask = (garr == g) & used
            group_label = g or "(no group)"
            groups[group_label] = group_statistics(
                d[mask], group_label, alpha=s.alpha, declared_sigma=sig
            )
            if "project" in s.standards and mask.any():
                thresholds[group_label] = project_threshold(
                    d[mask],
                    h_threshold=s.project_h_threshold,
                    v_threshold=s.project_v_threshold or None,
                    flight_geometry=s.flight_geometry,
                )
            _tick(progress, should_stop, 0.3 + 0.4 * len(groups) / len(names))
    results = []
    comps = overall.components
    for key in s.standards:
        if key == "asprs":
            results.append(
                asprs_2023(
                    du,
                    survey_sigma_h=s.survey_sigma_h,
                    survey_sigma_v=s.survey_sigma_v,
                    h_class_cm=s.asprs_h_class_cm,
                    v_class_cm=s.asprs_v_class_cm,
                )
            )
        elif key == "nssda":
            normality = [comps[c].normality for c in COMPONENTS]
            bias = [comps[c].bias for c in COMPONENTS]
            # E, N and H of a non-empty set are always tested
            assert all(x is not None for x in normality) and all(x is not None for x in bias)
            results.append(
                nssda(
                    du,
                    normal=[x.normal for x in normality if x is not None],
                    biased=[x.biased for x in bias if x is not None],
                )
            )
        elif key == "pec":
            results.append(
                pec_pcd(
                    du,
                    scale=s.pec_scale,
                    equidistance=s.pec_equidistance or None,
                    target_class=s.pec_class,
                )
            )
        elif key == "project":
            results.append(
                project_threshold(
                    du,
                    h_threshold=s.project_h_threshold,
                    v_threshold=s.project_v_threshold or None,
                    flight_geometry=s.flight_geometry,
                )
            )
    _tick(progress, should_stop, 0.8)
    if n_flag:
        log.warning(
            "%d point(s) flagged as outliers (%s)%s",
            n_flag,
            outliers.description,
            "; excluded from the statistics" if s.exclude_outliers else "; kept in the statistics",
        )
    return AccuracyReport(
        points,
        s,
        d,
        outliers,
        used,
        overall,
        groups,
        tuple(results),
        thresholds,
        datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        contrast,
    )
