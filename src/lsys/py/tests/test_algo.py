# SPDX-License-Identifier: MIT
"""The shim's point algorithms against brute force, and the Discretizer."""
import math
import random

import pytest

from lpyshim.pgl_algo import Discretizer, Point3Grid, findClosestFromSubset, pointset_mean_direction
from lpyshim.pgl_curves import BezierCurve2D, Polyline2D
from lpyshim.pgl_geometry import Box, TriangleSet
from lpyshim.pgl_math import Vector3, angle, norm


def cloud(n, seed=3):
    r = random.Random(seed)
    return [Vector3(r.uniform(-1, 1), r.uniform(-1, 1), r.uniform(0, 2)) for _ in range(n)]


def test_ball_query_matches_brute_force():
    pts = cloud(400)
    g = Point3Grid(0.3, pts)
    for c, rad in ((Vector3(0, 0, 1), 0.5), (Vector3(0.9, -0.9, 0.1), 0.7), (Vector3(5, 5, 5), 1.0)):
        want = {i for i, p in enumerate(pts) if norm(p - c) <= rad}
        assert set(g.query_ball_point(c, rad)) == want


def test_cone_query_matches_brute_force():
    pts = cloud(300, 5)
    g = Point3Grid(0.25, pts)
    o, d, rad, ang = Vector3(0, 0, 0.2), Vector3(0, 0, 1), 1.5, math.radians(60)
    want = {i for i, p in enumerate(pts) if 0 < norm(p - o) <= rad and angle(p - o, d) <= ang / 2 + 1e-9}
    assert set(g.query_points_in_cone(o, d, rad, ang)) == want


def test_disabled_points_are_not_found():
    pts = cloud(50)
    g = Point3Grid(0.5, pts)
    near = g.closest_point(pts[7])
    assert near == 7
    g.disable_points([7])
    assert 7 not in g.query_ball_point(pts[7], 10)
    assert g.closest_point(pts[7]) != 7
    assert len(g.get_enabled_points()) == 49
    g.enable_points([7])
    assert g.closest_point(pts[7]) == 7


def test_mean_direction_and_closest():
    pts = [Vector3(1, 0, 0), Vector3(0, 1, 0), Vector3(0, 0, 5)]
    m = pointset_mean_direction(Vector3(0, 0, 0), pts)
    assert m == Vector3(1, 1, 1) / math.sqrt(3)
    assert pointset_mean_direction(Vector3(0, 0, 0), pts, [0, 1]) == Vector3(1, 1, 0) / math.sqrt(2)
    i, dist = findClosestFromSubset(Vector3(0, 0, 4), pts)
    assert (i, dist) == (2, pytest.approx(1))


def test_discretizer():
    d = Discretizer()
    BezierCurve2D([(0, 0), (1, 1), (2, 0)], stride=10).apply(d)
    assert isinstance(d.result, Polyline2D) and len(d.result) == 11
    Box(Vector3(1, 1, 1)).apply(d)
    assert isinstance(d.result, TriangleSet) and len(d.result.indexList) == 12
