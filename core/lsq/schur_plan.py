"""The fixed structure of a reduced system (:mod:`.schur`): which parameters are eliminated
in blocks (object points), the signatures and occurrences of the groups that see them, the
pairs of occurrences that fill the reduced matrix, and the chunked reductions over them.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError

Array = NDArray[np.float64]
Index = NDArray[np.intp]

__all__ = ["EliminationPlan"]

# Items (groups or pairs of occurrences) per chunk of a reduction: bounds the temporaries.
_CHUNK = 1 << 16


class _Reducer:
    """Sums of per-item values by key, in chunks aligned to whole keys.

    The items are sorted by key once; :meth:`sum` asks ``values(items)`` for a chunk of item
    numbers at a time and reduces the chunk with ``np.add.reduceat``.
    """

    def __init__(self, keys: Index, n_keys: int, chunk: int = _CHUNK) -> None:
        keys = np.asarray(keys, dtype=np.intp)
        self.item_keys = keys  # the key of every item (for the compiled sums)
        # already sorted (pairs are stored in key order): the items are taken as slices
        self.identity = bool(keys.size < 2 or (keys[1:] >= keys[:-1]).all())
        self.order = (
            np.arange(keys.size, dtype=np.intp)
            if self.identity
            else np.argsort(keys, kind="stable")
        )
        sk = keys[self.order]
        self.n_keys = int(n_keys)
        self.n_items = int(keys.size)
        if sk.size:
            starts = np.flatnonzero(np.r_[True, sk[1:] != sk[:-1]])
        else:
            starts = np.zeros(0, dtype=np.intp)
        self.keys = sk[starts]
        self.starts = starts
        # Chunk boundaries on key boundaries: a new chunk starts at the first key start past
        # the running limit, so that no key is split between chunks.
        bounds = [0]
        if starts.size:
            while bounds[-1] < starts.size:
                lo = starts[bounds[-1]]
                nxt = int(np.searchsorted(starts, lo + chunk, side="right"))
                bounds.append(max(nxt, bounds[-1] + 1))
        self.bounds = bounds

    def sum_outer(
        self, X: Callable[[Index], Array], Y: Callable[[Index], Array] | None, k1: int, k2: int
    ) -> Array:
        """Per key ``sum_items X' Y`` with ``X(items)`` (n, m, k1) and ``Y(items)`` (n, m, k2)
        (``Y = X`` when None). Keys holding enough work are one matrix product each (BLAS on
        views of the chunk, whose rows are the items' m rows); otherwise batched products are
        reduced."""
        out = np.zeros((self.n_keys, k1, k2))
        if not self.starts.size:
            return out
        per_key = self.n_items * k1 * k2 >= 2000 * self.starts.size
        ends = np.r_[self.starts[1:], self.n_items]
        for a, b in zip(self.bounds[:-1], self.bounds[1:]):
            lo, hi = int(self.starts[a]), int(ends[b - 1])
            items = slice(lo, hi) if self.identity else self.order[lo:hi]
            A = X(items)
            B = A if Y is None else Y(items)
            if per_key:
                m = A.shape[1]
                A2 = np.ascontiguousarray(A).reshape(-1, k1)
                B2 = A2 if Y is None else np.ascontiguousarray(B).reshape(-1, k2)
                for key, s0, s1 in zip(self.keys[a:b], self.starts[a:b] - lo, ends[a:b] - lo):
                    out[key] = A2[s0 * m : s1 * m].T @ B2[s0 * m : s1 * m]
            else:
                vals = np.swapaxes(A, 1, 2) @ B
                out[self.keys[a:b]] = np.add.reduceat(vals, self.starts[a:b] - lo, axis=0)
        return out

    def sum(self, values: Callable[[Index], Array], shape: tuple[int, ...]) -> Array:
        out = np.zeros((self.n_keys, *shape))
        ends = np.r_[self.starts[1:], self.n_items] if self.starts.size else self.starts
        for a, b in zip(self.bounds[:-1], self.bounds[1:]):
            lo, hi = int(self.starts[a]), int(ends[b - 1])
            vals = values(self.order[lo:hi])
            out[self.keys[a:b]] = np.add.reduceat(vals, self.starts[a:b] - lo, axis=0)
        return out


@dataclass
class _BlockPlan:
    """How the columns of one observation block split into reduced and eliminated ones."""

    rc: Index  # (kr,) column positions that are reduced parameters
    ec: Index  # (ke,) column positions that are eliminated parameters
    rrows: Index  # (G, kr) reduced row numbers of the rc columns
    eslot: Index  # (G, ke) slot of the ec columns in their eliminated block
    point: Index  # (G,) eliminated block of each group, -1 for none
    vc: Index  # positions within rc of the columns that vary between groups
    cc: Index  # positions within rc of the columns every group shares
    sig: Index  # (G,) signature (distinct rows of rrows)
    sig_rows: Index  # (n_sig, kr)
    u_reducer: _Reducer | None = None
    v_reducer: _Reducer | None = None  # groups with a point, keyed by point
    with_point: Index = field(default_factory=lambda: np.zeros(0, dtype=np.intp))
    vset: int = -1  # occurrence set of the varying columns (occurrence = group)
    cset: int = -1  # occurrence set of the shared columns (occurrence = point of the block)
    c_occ: Index = field(default_factory=lambda: np.zeros(0, dtype=np.intp))  # (G,)
    c_reducer: _Reducer | None = None  # groups with a point, keyed by c_occ
    eslot_identity: bool = False  # every group's ec columns are the slots 0..b-1 in order


@dataclass
class _OccSet:
    """Occurrences of eliminated blocks in reduced rows (see the module docstring)."""

    point: Index  # (O,)
    sig: Index  # (O,)
    rows: Index  # (n_sig, kk) rows of the reduced (bordered) system
    source: tuple[str, int]  # ("v" | "c" | "k", block number)
    _by_point: tuple[Index, Index] | None = None

    def by_point(self, n_points: int) -> tuple[Index, Index]:
        """(order, start): the occurrences sorted by their block, and where each block's
        run starts (n_points + 1,); made on first use."""
        if self._by_point is None:
            order = np.argsort(self.point, kind="stable").astype(np.intp)
            counts = np.bincount(self.point, minlength=n_points)
            start = np.concatenate([[0], np.cumsum(counts)]).astype(np.intp)
            self._by_point = (order, start)
        return self._by_point


@dataclass
class _PairList:
    """Pairs (o1, o2) of occurrences of sets s1 <= s2 at the same eliminated block, in the
    order of their key (sig1, sig2).

    ``mirror``: each pair stands for itself and its reverse (o2, o1), whose contribution is
    the transposed block (all pairs between two sets; the pairs o1 < o2 within a set); the
    pairs o1 == o2 within a set are a list of their own without mirror.
    """

    s1: int
    s2: int
    o1: Index
    o2: Index
    key_reducer: _Reducer  # by (sig1, sig2)
    key_sig1: Index  # (n_keys,)
    key_sig2: Index
    n1: int  # occurrences in s1 and s2
    n2: int
    mirror: bool = True


def _pairs(pa: Index, pb: Index) -> tuple[Index, Index]:
    """Every (i, j) with ``pa[i] == pb[j]`` (item numbers into pa and pb)."""
    order_b = np.argsort(pb, kind="stable")
    sb = pb[order_b]
    lo = np.searchsorted(sb, pa, side="left")
    hi = np.searchsorted(sb, pa, side="right")
    cnt = hi - lo
    i = np.repeat(np.arange(pa.size, dtype=np.intp), cnt)
    # offset of each pair within its run: arange minus the run start
    run_start = np.repeat(np.cumsum(cnt) - cnt, cnt)
    within = np.arange(i.size, dtype=np.intp) - run_start
    j = order_b[np.repeat(lo, cnt) + within]
    return i, j


def _unique_rows(a: Index) -> tuple[Index, Index]:
    """(first row of each distinct row, inverse) of an integer matrix (G, k)."""
    if a.shape[1] == 0:
        return np.zeros(min(1, a.shape[0]), dtype=np.intp), np.zeros(a.shape[0], dtype=np.intp)
    # usually the first column determines the row (e.g. an image's six orientation
    # parameters): a 1-D unique, verified, is much faster than the row-wise one
    _, first, inv = np.unique(a[:, 0], return_index=True, return_inverse=True)
    inv = np.asarray(inv, dtype=np.intp).ravel()
    if (a[first][inv] == a).all():
        return first.astype(np.intp), inv
    _, first, inv = np.unique(a, axis=0, return_index=True, return_inverse=True)
    return first.astype(np.intp), np.asarray(inv, dtype=np.intp).ravel()


class EliminationPlan:
    """The fixed structure of a reduced system: block splits, signatures, occurrences, pairs.

    Parameters
    ----------
    n : int
        Number of parameters.
    eliminate : array_like of int, shape (P, b)
        Parameter indices of the eliminated blocks.
    blocks : sequence
        The validated observation blocks of the adjustment (with ``param_index``, ``name``).
    constraint_index : sequence of ndarray (G_c, k_c)
        Parameter indices of each hard-constraint set.
    """

    def __init__(
        self,
        n: int,
        eliminate: ArrayLike,
        blocks: Sequence,
        constraint_index: Sequence[Index],
    ) -> None:
        e = np.asarray(eliminate)
        if e.ndim != 2 or e.size == 0:
            raise InputError(f"eliminate must have shape (P, b) with P, b >= 1, got {e.shape}")
        if not np.issubdtype(e.dtype, np.integer):
            raise InputError(f"eliminate must be integers, got {e.dtype}")
        e = e.astype(np.intp)
        if e.min() < 0 or e.max() >= n:
            raise InputError(f"eliminate: indices outside 0..{n - 1}")
        if np.unique(e).size != e.size:
            raise InputError("eliminate: a parameter appears twice")
        self.n = n
        self.elim = e
        self.P, self.b = e.shape
        point_of = np.full(n, -1, dtype=np.intp)
        slot_of = np.full(n, -1, dtype=np.intp)
        point_of[e.ravel()] = np.repeat(np.arange(self.P), self.b)
        slot_of[e.ravel()] = np.tile(np.arange(self.b), self.P)
        self.point_of = point_of
        self.reduced = np.flatnonzero(point_of < 0)
        self.n_r = int(self.reduced.size)
        rmap = np.full(n, -1, dtype=np.intp)
        rmap[self.reduced] = np.arange(self.n_r)
        self.rmap = rmap
        self.sets: list[_OccSet] = []
        self.plans: list[_BlockPlan] = []
        for bi, bk in enumerate(blocks):
            self.plans.append(self._block_plan(bi, bk, point_of, slot_of, rmap))
        seen = np.zeros(self.P, dtype=bool)
        for bp in self.plans:
            seen[bp.point[bp.point >= 0]] = True
        self.constraint_points = np.unique(
            np.concatenate(
                [point_of[ci.ravel()] for ci in constraint_index] or [np.zeros(0, np.intp)]
            )
        )
        self.constraint_points = self.constraint_points[self.constraint_points >= 0]
        self.unobserved = np.flatnonzero(~seen)
        self.mc: int | None = None
        self.pairs: list[_PairList] = []

    # -- structure -------------------------------------------------------------------------

    def _block_plan(self, bi: int, bk, point_of: Index, slot_of: Index, rmap: Index) -> _BlockPlan:
        where = f"block '{bk.name}'"
        idx = bk.param_index
        g, k = idx.shape
        pt = point_of[idx]
        el = pt >= 0
        col_any = el.any(axis=0) if g else np.zeros(k, dtype=bool)
        col_all = el.all(axis=0) if g else np.zeros(k, dtype=bool)
        if (col_any != col_all).any():
            raise InputError(
                f"{where}: a column holds eliminated parameters in some groups and other "
                "parameters in others; order the columns the same way in every group"
            )
        ec = np.flatnonzero(col_any)
        rc = np.flatnonzero(~col_any)
        if g and k > 1:
            srt = np.sort(idx, axis=1)
            if (srt[:, 1:] == srt[:, :-1]).any():
                raise InputError(
                    f"{where}: a group uses the same parameter twice, which the elimination "
                    "of blocks does not support"
                )
        if ec.size:
            gp = pt[:, ec]
            point = gp[:, 0].copy()
            if (gp != point[:, None]).any():
                bad = int(np.flatnonzero((gp != point[:, None]).any(axis=1))[0])
                raise InputError(
                    f"{where}: group {bk.labels[bad]} depends on two eliminated blocks; each "
                    "group may depend on at most one"
                )
        else:
            point = np.full(g, -1, dtype=np.intp)
        eslot = slot_of[idx[:, ec]]
        rrows = rmap[idx[:, rc]]
        if g:
            const = (rrows == rrows[:1]).all(axis=0)
        else:
            const = np.ones(rc.size, dtype=bool)
        vc = np.flatnonzero(~const)
        cc = np.flatnonzero(const)
        first, sig = _unique_rows(rrows[:, vc])
        sig_rows = rrows[first] if g else np.zeros((0, rc.size), dtype=np.intp)
        bp = _BlockPlan(rc, ec, rrows, eslot, point, vc, cc, sig, sig_rows)
        bp.eslot_identity = bool(ec.size == self.b and (eslot == np.arange(self.b)[None, :]).all())
        if rc.size and g:
            bp.u_reducer = _Reducer(sig, sig_rows.shape[0])
        wp = np.flatnonzero(point >= 0)
        bp.with_point = wp
        if ec.size and wp.size:
            bp.v_reducer = _Reducer(point[wp], self.P)
            if vc.size:
                bp.vset = len(self.sets)
                used, inv = np.unique(sig[wp], return_inverse=True)
                self.sets.append(
                    _OccSet(
                        point=point[wp],
                        sig=np.asarray(inv, dtype=np.intp).ravel(),
                        rows=sig_rows[used][:, vc],
                        source=("v", bi),
                    )
                )
            if cc.size:
                bp.cset = len(self.sets)
                upts, inv = np.unique(point[wp], return_inverse=True)
                inv = np.asarray(inv, dtype=np.intp).ravel()
                c_occ = np.full(g, -1, dtype=np.intp)
                c_occ[wp] = inv
                bp.c_occ = c_occ
                bp.c_reducer = _Reducer(inv, upts.size)
                self.sets.append(
                    _OccSet(
                        point=upts.astype(np.intp),
                        sig=np.zeros(upts.size, dtype=np.intp),
                        rows=rrows[:1, cc],
                        source=("c", bi),
                    )
                )
        return bp

    def rows_per_block(self, rows_per_group, active) -> Index:
        """Observation rows touching each eliminated block (of the active groups, or of all
        groups when ``active`` is None)."""
        out = np.zeros(self.P, dtype=np.intp)
        for k, bp in enumerate(self.plans):
            c = rows_per_group[k] or 0
            sel = bp.point >= 0
            if active is not None:
                sel = sel & active[k]
            if bp.ec.size and sel.any():
                out += c * np.bincount(bp.point[sel], minlength=self.P)
        return out

    def finish(self, mc: int) -> None:
        """Add the constraint occurrences (``mc`` rows) and enumerate the pairs (once)."""
        if self.mc is not None:
            return
        self.mc = int(mc)
        if mc and self.constraint_points.size:
            self.kset = len(self.sets)
            self.sets.append(
                _OccSet(
                    point=self.constraint_points.astype(np.intp),
                    sig=np.zeros(self.constraint_points.size, dtype=np.intp),
                    rows=(self.n_r + np.arange(mc, dtype=np.intp))[None, :],
                    source=("k", -1),
                )
            )
        else:
            self.kset = -1
        for s1 in range(len(self.sets)):
            for s2 in range(s1, len(self.sets)):
                a, b = self.sets[s1], self.sets[s2]
                o1, o2 = _pairs(a.point, b.point)
                if s1 == s2:
                    # o1 < o2 mirrored, o1 == o2 on their own: half the products
                    parts = [(o1[o1 < o2], o2[o1 < o2], True), (o1[o1 == o2], o2[o1 == o2], False)]
                else:
                    parts = [(o1, o2, True)]
                nsig2 = b.rows.shape[0]
                for p1, p2, mirror in parts:
                    if p1.size == 0:
                        continue
                    key = a.sig[p1] * nsig2 + b.sig[p2]
                    order = np.argsort(key, kind="stable")
                    p1, p2, key = p1[order], p2[order], key[order]
                    ukey, kinv = np.unique(key, return_inverse=True)
                    kinv = np.asarray(kinv, dtype=np.intp).ravel()
                    self.pairs.append(
                        _PairList(
                            s1,
                            s2,
                            p1,
                            p2,
                            _Reducer(kinv, ukey.size),
                            (ukey // nsig2).astype(np.intp),
                            (ukey % nsig2).astype(np.intp),
                            a.point.size,
                            b.point.size,
                            mirror,
                        )
                    )
