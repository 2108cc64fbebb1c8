"""The synthetic terrains for ground filters: every class holds what it promises, the truth is
consistent and the same seed gives the same points."""

from __future__ import annotations

import numpy as np
import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.simulation.terrain import TERRAIN_CLASSES, make_terrain

TERRAIN, BUILDING, VEGETATION, DECK, SMALL, LOW, HIGH = range(7)


@pytest.fixture(scope="module")
def scenes():
    return {n: make_terrain(n, size=120, density=1.0, noise_sigma=0.0, seed=5)
            for n in TERRAIN_CLASSES}  # fmt: skip


def test_every_class_has_ground_objects_and_its_own_difficulty(scenes):
    for name, s in scenes.items():
        assert s.xyz.shape == (len(s.ground), 3) and s.kind.shape == s.ground.shape
        np.testing.assert_array_equal(s.ground, s.kind == TERRAIN)
        assert 0.3 < s.ground.mean() < 1.0, name
        assert s.xyz[:, :2].min() >= 0 and s.xyz[:, :2].max() <= 120.0, name
    assert (scenes["bridges"].kind == DECK).sum() > 100
    assert (scenes["low_outliers"].kind == LOW).sum() >= 120 * 120 / 150
    assert (scenes["high_outliers"].kind == HIGH).sum() > 0
    assert (scenes["dense_buildings"].kind == BUILDING).mean() > 0.4
    assert (scenes["slopes"].kind == VEGETATION).mean() > 0.2


def test_outliers_lie_below_and_above_the_ground(scenes):
    for name, kind, sign in (("low_outliers", LOW, -1), ("high_outliers", HIGH, 1)):
        s = scenes[name]
        g = s.xyz[s.ground]
        for p in s.xyz[s.kind == kind][:50]:
            near = g[np.hypot(*(g[:, :2] - p[:2]).T) < 4.0]
            if len(near):
                assert sign * (p[2] - near[:, 2].mean()) > 1.0, (name, p)


def test_density_gaps_and_steep_faces():
    s = make_terrain("gaps", size=120, density=2.0, seed=1)
    ground = s.xyz[s.ground]
    # the lakes return nothing: the 12 m x 9 m ellipse centre of the first lake is empty
    lake = np.hypot((ground[:, 0] - 36) / 0.2, (ground[:, 1] - 42) / 0.15) < 60
    assert not lake.any()
    # top-surface sampling at the asked density (plus ground beneath crowns, minus gaps)
    s = make_terrain("high_outliers", size=100, density=3.0, seed=2)
    assert 2.5 < len(s.xyz) / 100**2 < 4.0
    # cliffs: points on the faces (steeper than 60 degrees) are ground too
    s = make_terrain("cliffs", size=120, density=2.0, noise_sigma=0.0, seed=3)
    assert s.ground.sum() > 0.5 * len(s.xyz)


def test_same_seed_same_points_and_bad_input():
    a = make_terrain("bridges", size=100, density=1.0, seed=9)
    b = make_terrain("bridges", size=100, density=1.0, seed=9)
    np.testing.assert_array_equal(a.xyz, b.xyz)
    np.testing.assert_array_equal(a.kind, b.kind)
    c = make_terrain("bridges", size=100, density=1.0, seed=10)
    assert len(c.xyz) != len(a.xyz) or not np.array_equal(c.xyz, a.xyz)
    with pytest.raises(InputError, match="terrain class"):
        make_terrain("volcano")
    with pytest.raises(InputError, match="size"):
        make_terrain("gaps", size=50)
