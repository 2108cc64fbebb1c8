"""Target correspondence between scans: which targets of two stations are the same (the
rigid motion most of their distances agree with) and one label per physical target over all
stations, from the control's ids where given (the step after :mod:`.targets` detects them)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from .network import kabsch

__all__ = ["label_targets", "match_targets"]

Array = NDArray[np.float64]


def match_targets(
    a: ArrayLike, b: ArrayLike, tolerance: float = 0.02, min_matches: int = 3
) -> tuple[NDArray[np.intp], NDArray[np.intp], Array, Array]:
    """Which targets of scan ``a`` are those of scan ``b`` (any rigid motion between them).

    Every triangle of ``b`` whose three sides match (within ``tolerance``) a triangle of
    ``a`` gives a rigid motion (:func:`~.network.kabsch`); the motion that brings most
    targets of ``a`` within ``tolerance`` of a target of ``b`` wins, refined on its matches.
    Distances are invariant under rigid motion, so the scans need no approximate
    registration; a target layout with repeated distances (a regular grid) can be ambiguous.

    Returns
    -------
    ia, ib : ndarray of int
        Matched indices into ``a`` and ``b``.
    R, t : ndarray
        ``b ~ R a + t``.

    Raises
    ------
    InputError
        Fewer than ``min_matches`` targets in common.
    """
    pa = np.asarray(a, dtype=np.float64)
    pb = np.asarray(b, dtype=np.float64)
    na, nb = len(pa), len(pb)
    if na < 3 or nb < 3:
        raise InputError("at least three targets are needed in each scan to match them")
    da = np.linalg.norm(pa[:, None] - pa[None], axis=-1)
    db = np.linalg.norm(pb[:, None] - pb[None], axis=-1)
    # Triangles of a: each target with its two nearest neighbours farther than 4 tolerances.
    tri_a = []
    fourth: dict[tuple[int, int, int], list[int]] = {}
    for i in range(na):
        order = [int(j) for j in np.argsort(da[i]) if da[i, j] > 4 * tolerance]
        for j in order[:3]:
            for m in order[:4]:
                if m != j and da[j, m] > 4 * tolerance:
                    tri_a.append((i, j, m))
                    fourth[(i, j, m)] = [n for n in order[:7] if n not in (j, m)][:3]

    from scipy.spatial import cKDTree

    tree = cKDTree(pb)

    def search(with_fourth: bool) -> tuple[int, tuple[Array, Array] | None]:
        best: tuple[int, tuple[Array, Array] | None] = (0, None)
        best_map: dict[int, int] = {}
        ia_all = np.arange(na)
        for i, j, m in tri_a:
            cand_k, cand_q = np.nonzero(np.abs(db - da[i, j]) < tolerance)
            for k, kk in zip(cand_k, cand_q):
                if k == kk:
                    continue
                ok = np.flatnonzero(
                    (np.abs(db[k] - da[i, m]) < tolerance) & (np.abs(db[kk] - da[j, m]) < tolerance)
                )
                for q in ok:
                    if q in (k, kk):
                        continue
                    # A triangle whose three pairs the best motion already matches gives that
                    # motion again: skip its verification (most triangles of the overlap do).
                    if best_map.get(i) == k and best_map.get(j) == kk and best_map.get(m) == q:
                        continue
                    # Regular target layouts repeat triangles: ask a fourth target of a to be
                    # at matching distances from some target of b before trying the motion.
                    if with_fourth and not any(
                        np.any(
                            (np.abs(db[k] - da[i, n]) < tolerance)
                            & (np.abs(db[kk] - da[j, n]) < tolerance)
                            & (np.abs(db[q] - da[m, n]) < tolerance)
                        )
                        for n in fourth[(i, j, m)]
                    ):
                        continue
                    try:
                        r, t, _ = kabsch(pa[[i, j, m]], pb[[k, kk, q]])
                    except InputError:
                        continue
                    dist, nearest = tree.query(pa @ r.T + t, distance_upper_bound=tolerance)
                    hit = dist < tolerance
                    count = int(hit.sum())
                    if count > best[0]:
                        best = (count, (r, t))
                        best_map = {int(a): int(b) for a, b in zip(ia_all[hit], nearest[hit])}
                    if count == min(na, nb):
                        return best
        return best

    # With many targets the four-point test prunes most false triangles; with few in common
    # it may reject every true one, so the plain search follows when it finds too little.
    best = search(with_fourth=min(na, nb) >= 8)
    if best[0] < max(min_matches, 4) and min(na, nb) >= 8:
        best = search(with_fourth=False)
    ia_all = np.arange(na)
    if best[1] is None or best[0] < min_matches:
        raise InputError(
            f"fewer than {min_matches} targets in common could be matched (best {best[0]})"
        )
    r, t = best[1]
    for _ in range(2):
        moved = pa @ r.T + t
        d = np.linalg.norm(moved[:, None] - pb[None], axis=-1)
        nearest = np.argmin(d, axis=1)
        hit = d[ia_all, nearest] < tolerance
        # One-to-one: keep the closest when two targets of a pick the same one of b.
        ia = np.flatnonzero(hit)
        ib = nearest[hit]
        keep = np.ones(ia.size, dtype=bool)
        for v in np.unique(ib):
            dup = np.flatnonzero(ib == v)
            if dup.size > 1:
                keep[dup] = False
                keep[dup[np.argmin(d[ia[dup], v])]] = True
        ia, ib = ia[keep], ib[keep]
        r, t, _ = kabsch(pa[ia], pb[ib])
    return ia.astype(np.intp), ib.astype(np.intp), r, t


def label_targets(
    centres: Sequence[Array],
    tolerance: float = 0.02,
    control_ids: Sequence[str] = (),
    control_xyz: ArrayLike | None = None,
    prefix: str = "T",
) -> list[list[str]]:
    """Common target ids for the targets found in several scans.

    The first scan's targets get ids ``T1, T2, ...``; each further scan (the one matching
    most targets already labelled first) is matched (:func:`match_targets`) to all targets
    labelled so far, expressed in the first scan's frame, and its unmatched targets get new
    ids. With control, the labelled set is matched to the control points and the matched ids
    are replaced by the control ids.

    Parameters
    ----------
    centres : sequence of ndarray (n_s, 3)
        Target centres of each scan, in its own scanner frame.
    tolerance : float
        Distances agree within this (m): a few times the centre precision plus the effect of
        the scanner's systematic errors over the network.
    control_ids, control_xyz
        Control point ids and coordinates (object frame).

    Returns
    -------
    list of list of str
        Ids per scan, in the order of ``centres``.

    Raises
    ------
    InputError
        A scan shares fewer than three targets with the others.
    """
    cs = [np.asarray(c, dtype=np.float64).reshape(-1, 3) for c in centres]
    ids: list[list[str | None]] = [[None] * len(c) for c in cs]
    if not cs:
        return []
    counter = 0
    placed_xyz: list[Array] = []
    placed_id: list[str] = []
    for k in range(len(cs[0])):
        counter += 1
        name = f"{prefix}{counter}"
        ids[0][k] = name
        placed_xyz.append(cs[0][k])
        placed_id.append(name)
    done = {0}
    while len(done) < len(cs):
        best = None
        ref = np.array(placed_xyz)
        for s in range(len(cs)):
            if s in done:
                continue
            try:
                ia, ib, r, t = match_targets(cs[s], ref, tolerance)
            except InputError:
                continue
            if best is None or ia.size > best[1].size:
                best = (s, ia, ib, r, t)
        if best is None:
            left = [s for s in range(len(cs)) if s not in done]
            raise InputError(
                f"scan {left[0] + 1} shares fewer than three targets with the "
                "scans labelled so far (distances compared within "
                f"{tolerance:g} m)"
            )
        s, ia, ib, r, t = best
        moved = cs[s] @ r.T + t
        for a_i, b_i in zip(ia, ib):
            ids[s][a_i] = placed_id[b_i]
        for k in range(len(cs[s])):
            if ids[s][k] is None:
                counter += 1
                name = f"{prefix}{counter}"
                ids[s][k] = name
                placed_xyz.append(moved[k])
                placed_id.append(name)
        done.add(s)
    if control_xyz is not None and len(control_ids):
        ctrl = np.asarray(control_xyz, dtype=np.float64)
        # Triangles are built from the first set's near neighbours: start from the (usually
        # few) control points so that their triangles are among them.
        ib, ia, _, _ = match_targets(ctrl, np.array(placed_xyz), tolerance)
        rename = {placed_id[a_i]: str(control_ids[b_i]) for a_i, b_i in zip(ia, ib)}
        taken = set(rename.values())
        for old in placed_id:
            if old not in rename and old in taken:
                rename[old] = f"{old}_new"
        ids = [[rename.get(i, i) for i in row] for row in ids]
    return [[str(i) for i in row] for row in ids]
