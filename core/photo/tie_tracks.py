"""Tracks of tie points: the pairwise matches joined by union-find into one measurement per
image and ground point (a track with two points in one image dropped)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .tie_data import ImageFeatures, PairMatch

__all__ = ["Tracks", "build_tracks"]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class Tracks:
    """Tie points: one row per measurement (image, track), sorted by track then image.

    ``track`` numbers the tracks 0..T-1; ``feature`` is the keypoint index in its image.
    ``rejected_inconsistent`` counts the tracks dropped for holding two keypoints of one
    image, ``rejected_short`` those below the minimum length.
    """

    track: NDArray[np.intp]
    image: NDArray[np.intp]
    feature: NDArray[np.intp]
    pixels: Array
    rejected_inconsistent: int
    rejected_short: int

    @property
    def n_tracks(self) -> int:
        return int(self.track.max()) + 1 if self.track.size else 0

    def lengths(self) -> NDArray[np.intp]:
        """Images per track."""
        return np.bincount(self.track, minlength=self.n_tracks)


def _same_point(features: Sequence[ImageFeatures], offset: NDArray[np.intp]) -> NDArray[np.intp]:
    """For every keypoint (global index), the first keypoint of its image at the same pixel
    position: SIFT describes an extremum once per dominant orientation (about 1.2 keypoints
    per position), and one orientation may match in one pair, another in the next; taken as
    one node, their matches join into one track instead of two shorter ones."""
    out = np.arange(offset[-1], dtype=np.intp)
    for k, f in enumerate(features):
        if len(f) < 2:
            continue
        _, first, inv = np.unique(f.pixels, axis=0, return_index=True, return_inverse=True)
        out[offset[k] : offset[k + 1]] = offset[k] + first[inv.ravel()]
    return out


def build_tracks(
    features: Sequence[ImageFeatures], matches: Sequence[PairMatch], min_track_length: int = 2
) -> Tracks:
    """Merge the kept pairwise matches into tracks (connected components, union-find);
    keypoints of one image at the same position (SIFT's orientations of one extremum) are
    one node.

    Examples
    --------
    >>> z = np.array([[1.0, 1], [5, 5], [1, 1]])  # keypoints 0 and 2: one extremum twice
    >>> d = np.zeros((3, 128), np.uint8); s = np.ones(3, np.float32)
    >>> fs = [ImageFeatures(n, (10, 10), 1, z, s, d) for n in "abc"]
    >>> e = np.array([0, 1]); r = np.zeros(2)
    >>> m = [PairMatch(0, 1, e, e, 2, 2, 2, r, "ok"), PairMatch(1, 2, e, e[::-1], 2, 2, 2, r, "ok")]
    >>> t = build_tracks(fs, m)  # a0-b0-c1 and a1-b1-c0
    >>> t.n_tracks, t.lengths().tolist(), t.feature.tolist()
    (2, [3, 3], [0, 0, 1, 1, 1, 0])
    >>> m.append(PairMatch(0, 2, e[:1], e[:1], 1, 1, 1, r[:1], "ok"))  # a0-c0: joins both
    >>> t = build_tracks(fs, m); t.n_tracks, t.rejected_inconsistent
    (0, 1)
    >>> e2 = np.array([2]); r1 = r[:1]  # a2 (= a0's position) with b0: joins a0's track
    >>> m = [PairMatch(0, 1, e[:1], e[:1], 1, 1, 1, r1, "ok"),
    ...      PairMatch(0, 2, e2, e[1:], 1, 1, 1, r1, "ok")]
    >>> t = build_tracks(fs, m); t.lengths().tolist(), t.feature.tolist()
    ([3], [0, 0, 1])
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    counts = np.array([len(f) for f in features], dtype=np.intp)
    offset = np.concatenate([[0], np.cumsum(counts)])
    kept = [m for m in matches if m.kept and m.idx_i.size]
    empty = np.zeros(0, np.intp)
    if not kept:
        return Tracks(empty, empty, empty, np.zeros((0, 2)), 0, 0)
    same = _same_point(features, offset)
    a = same[np.concatenate([offset[m.i] + m.idx_i for m in kept])]
    b = same[np.concatenate([offset[m.j] + m.idx_j for m in kept])]
    nodes, inv = np.unique(np.concatenate([a, b]), return_inverse=True)
    n = nodes.size
    ea, eb = inv[: a.size], inv[a.size :]
    graph = coo_matrix((np.ones(ea.size, np.int8), (ea, eb)), shape=(n, n))
    _, comp = connected_components(graph, directed=False)
    img = np.searchsorted(offset, nodes, side="right") - 1
    feat = nodes - offset[img]
    order = np.lexsort((img, comp))
    comp, img, feat, nodes = comp[order], img[order], feat[order], nodes[order]
    # two keypoints of one image in a track: sorted by (track, image), they are neighbours
    dup = (comp[1:] == comp[:-1]) & (img[1:] == img[:-1])
    bad = np.zeros(comp.max() + 1, bool)
    bad[comp[1:][dup]] = True
    length = np.bincount(comp)
    short = (length < min_track_length) & ~bad
    keep_comp = ~bad & ~short
    keep = keep_comp[comp]
    new_id = np.cumsum(keep_comp) - 1
    track = new_id[comp[keep]]
    pix = np.vstack([f.pixels for f in features])[nodes[keep]]
    return Tracks(
        track.astype(np.intp),
        img[keep].astype(np.intp),
        feat[keep].astype(np.intp),
        pix,
        int(bad.sum()),
        int(short.sum()),
    )
