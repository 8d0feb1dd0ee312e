# SPDX-License-Identifier: MIT
"""The shim's curves against closed forms: a rational quadratic NURBS is an exact circular arc,
Bezier curves are Bernstein sums, polylines are linear, QuantisedFunction samples a graph."""
import math

import pytest

from lpyshim.pgl_curves import BezierCurve, BezierCurve2D, NurbsCurve, NurbsCurve2D, Polyline, Polyline2D, \
    QuantisedFunction
from lpyshim.pgl_math import Vector2, Vector3

W = math.sqrt(0.5)  # the weight of the middle point of a quarter circle


def test_rational_nurbs_is_an_exact_arc():
    # PlantGL's control points are (x, y, w) with the weight applied to x and y
    c = NurbsCurve2D([(1, 0, 1), (1, 1, W), (0, 1, 1)])
    assert c.degree == 2
    assert (c.firstKnot, c.lastKnot) == (0.0, 1.0)
    for i in range(11):
        p = c.getPointAt(i / 10)
        assert math.hypot(p.x, p.y) == pytest.approx(1, abs=1e-12)
    assert c.getPointAt(0) == Vector2(1, 0) and c.getPointAt(1) == Vector2(0, 1)
    # length by the chords of the stride's 30 samples: under the arc, within the chord error
    length = c.getLength()
    assert length < math.pi / 2
    assert length == pytest.approx(math.pi / 2, rel=2e-3)


def test_default_knots_are_clamped_uniform():
    c = NurbsCurve2D([(0, 0, 1), (1, 1, 1), (2, 0, 1), (3, 1, 1), (4, 0, 1)])
    assert c.degree == 3
    assert list(c.knotList) == [0, 0, 0, 0, 0.5, 1, 1, 1, 1]
    assert c.getPointAt(0) == Vector2(0, 0) and c.getPointAt(1) == Vector2(4, 0)


def test_nurbs_3d_with_unit_weights_is_a_bspline():
    pts = [(0, 0, 0), (1, 2, 0), (3, 2, 1), (4, 0, 2)]
    c = NurbsCurve([p + (1,) for p in pts])
    b = BezierCurve([p + (1,) for p in pts])  # 4 points, degree 3, clamped: the same curve
    for i in range(6):
        assert c.getPointAt(i / 5) == b.getPointAt(i / 5)


def test_bezier_is_the_bernstein_sum():
    pts = [Vector2(0, 0), Vector2(1, 3), Vector2(3, 3), Vector2(4, 0)]
    c = BezierCurve2D(pts)
    for u in (0, 0.2, 0.5, 0.9, 1):
        bern = [math.comb(3, k) * u ** k * (1 - u) ** (3 - k) for k in range(4)]
        want = Vector2(sum(b * p.x for b, p in zip(bern, pts)), sum(b * p.y for b, p in zip(bern, pts)))
        assert c.getPointAt(u) == want
    # the derivative at the ends is 3 (P1 - P0) and 3 (P3 - P2)
    assert c.getTangentAt(0) == pytest.approx(Vector2(3, 9), abs=1e-4)
    assert c.getTangentAt(1) == pytest.approx(Vector2(3, -9), abs=1e-4)


def test_polyline_is_linear_between_points():
    p = Polyline([(0, 0, 0), (3, 0, 0), (3, 4, 0)])
    assert p.getLastKnot() == 2
    assert p.getPointAt(0.5) == Vector3(1.5, 0, 0)
    assert p.getPointAt(1.25) == Vector3(3, 1, 0)
    assert p.getLength() == pytest.approx(7)
    assert Polyline2D.Circle(1, 64).getLength() == pytest.approx(2 * 64 * math.sin(math.pi / 64))


def test_arc_length_mapping_walks_equal_lengths():
    c = BezierCurve2D([(0, 0), (0, 2), (3, 2), (3, 0)])
    f = c.getArcLengthToUMapping()
    total = c.getLength()
    for s in (0.25, 0.5, 0.75):
        assert c.getLength(0, f(s)) == pytest.approx(s * total, rel=2e-2)


def test_quantised_function_samples_a_graph():
    f = QuantisedFunction(Polyline2D([(0, 1), (1, 3), (2, 3)]))
    assert f(0.5) == pytest.approx(2)
    assert f(1.5) == pytest.approx(3)
    assert f(-1) == pytest.approx(1) and f(5) == pytest.approx(3)  # clamped to the curve's range
    g = QuantisedFunction(Polyline2D([(0, 0), (2, 4)]))
    assert g.isIncreasing(True)
    inv = g.inverse()
    assert inv(2) == pytest.approx(1, abs=1e-9)


def test_bad_curves_are_errors():
    with pytest.raises(ValueError):
        NurbsCurve2D([(0, 0, 1)])
    with pytest.raises(ValueError):
        NurbsCurve2D([(0, 0, 1), (1, 0, 1), (2, 0, 1)], knotList=[0, 0, 1, 1], degree=2)


def test_cspline_interpolates_with_half_chord_tangents():
    from lpyshim.pgl_curves import cspline
    pts = [(0, 0), (1, 2), (3, 3), (4, 0)]
    c = cspline(pts)
    assert c.degree == 3 and c.stride == 30
    d = [math.dist(pts[i], pts[i + 1]) for i in range(3)]
    knots = [0, d[0], d[0] + d[1], sum(d)]
    assert list(c.knotList) == pytest.approx([0] * 4 + [knots[1]] * 3 + [knots[2]] * 3 + [knots[3]] * 4)
    for k, p in zip(knots, pts):
        assert c.getPointAt(k) == Vector2(*p)
    # at an inner point the derivative is (P[i+1] - P[i-1]) / 2 over the arc's knot span
    h = 1e-7
    dc = (c.getPointAt(knots[1] + h) - c.getPointAt(knots[1])) / h
    want = (Vector2(3, 3) - Vector2(0, 0)) / 2 / d[1]
    assert dc == pytest.approx(want, rel=1e-4)


def test_cspline_3d_and_closed():
    from lpyshim.pgl_curves import CSpline
    c = CSpline([(0, 0, 0), (1, 0, 0), (1, 1, 0)], is_closed=True)
    assert len(c) == 4  # the first point again at the end
    n = c.curve()
    assert isinstance(n, NurbsCurve)
    assert n.getPointAt(n.getFirstKnot()) == n.getPointAt(n.getLastKnot())
