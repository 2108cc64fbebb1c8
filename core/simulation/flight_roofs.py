"""Roof geometry of the synthetic town for the flight simulator (:mod:`core.simulation.flight`):
points sampled on the roof faces, the ridges and hips between two faces and the corners where
three meet (map coordinates, metres)."""

from __future__ import annotations

import itertools
import math

import numpy as np
from numpy.typing import NDArray

from .town import Town

Array = NDArray[np.float64]


def _roof_samples(town: Town, density: float, rng) -> tuple[Array, NDArray[np.int64]]:
    """Uniform points on the roofs (map), with their face ids: (M, 3), (M,)."""
    xyz, fid = [], []
    for b in town.buildings:
        n = max(round(density * b.length * b.width), 10)
        uv = rng.uniform(-0.5, 0.5, (n, 2)) * [b.length, b.width]
        c, s = math.cos(b.rotation_rad), math.sin(b.rotation_rad)
        xy = b.centre + np.column_stack([c * uv[:, 0] - s * uv[:, 1], s * uv[:, 0] + c * uv[:, 1]])
        z, f = town.roof_z(b, xy)
        xyz.append(np.column_stack([xy, z]))
        fid.append(f)
    return np.vstack(xyz), np.concatenate(fid).astype(np.int64)


def _face_points(town: Town, faces: list[int], per_face: int, rng, inset: float = 0.15):
    """``per_face`` random points strictly inside each face (map), (F * per_face, 3)."""
    pts, ids = _roof_samples(town, 40.0, rng)
    out = np.empty((len(faces), per_face, 3))
    for k, f in enumerate(faces):
        cand = pts[ids == f]
        centroid = cand.mean(axis=0)
        # pull towards the centroid: keeps measured points away from the roof edges
        pick = cand[rng.choice(len(cand), per_face, replace=len(cand) < per_face)]
        out[k] = centroid + (1.0 - inset) * (pick - centroid)
    return out.reshape(-1, 3)


def _roof_lines(town: Town, faces: set[int]):
    """(segment (2, 3), face a, face b) for every ridge/hip between two kept faces."""
    out = []
    for b in town.buildings:
        fs = [town.faces[f] for f in b.face_ids]
        for seg in b.ridges:
            mid = seg.mean(axis=0)
            on = [f.face_id for f in fs if abs(float(f.normal @ mid + f.d)) < 1e-6]
            if len(on) == 2 and set(on) <= faces:
                out.append((seg, on[0], on[1]))
    return out


def _roof_corners(town: Town, faces: set[int]):
    """(point (3,), (f1, f2, f3)) where three kept faces of a building meet, deduplicated."""
    out = []
    for b in town.buildings:
        ids = [f for f in b.face_ids if f in faces]
        found: list[Array] = []
        for tri in itertools.combinations(ids, 3):
            n = np.array([town.faces[f].normal for f in tri])
            d = np.array([town.faces[f].d for f in tri])
            if abs(np.linalg.det(n)) < 1e-6:
                continue
            p = np.linalg.solve(n, -d)
            z, _ = town.roof_z(b, p[None, :2])
            if not b.inside(p[None, :2])[0] or abs(z[0] - p[2]) > 1e-6:
                continue
            if any(np.linalg.norm(p - q) < 1e-6 for q in found):
                continue
            found.append(p)
            out.append((p, tri))
    return out
