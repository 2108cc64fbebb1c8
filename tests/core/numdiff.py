"""Shared helpers of the core tests (importable: tests/core is on pytest's pythonpath)."""

from __future__ import annotations

import numpy as np


def central_difference(fun, x: np.ndarray, steps) -> np.ndarray:
    """d fun / d x by central differences; fun maps (P,) -> (N, 2); returns (N, 2, P)."""
    cols = []
    for j, h in enumerate(steps):
        xp, xm = x.copy(), x.copy()
        xp[j] += h
        xm[j] -= h
        cols.append((fun(xp) - fun(xm)) / (2.0 * h))
    return np.stack(cols, axis=-1)
