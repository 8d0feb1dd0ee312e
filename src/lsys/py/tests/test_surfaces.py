# SPDX-License-Identifier: MIT
"""The shim's swept surfaces against closed forms: a revolved semicircle is a sphere, a revolved
line a cone, a circle extruded along a straight axis a prism, one along a quarter circle keeps
its radius; Swung through equal profiles is their revolution, through scaled ones scales."""
import math

import pytest

from meshcheck import area, in_range, signed_volume
from lpyshim.errors import NotInVerdant
from lpyshim.pgl_curves import BezierCurve2D, NurbsCurve, NurbsCurve2D, Polyline, Polyline2D
from lpyshim.pgl_math import Vector3
from lpyshim.pgl_surfaces import Extrusion, Revolution, Swung

W = math.sqrt(0.5)


def semicircle(r=1.0, stride=40):
    """From the south pole to the north pole through (r, 0): (radius, height) points."""
    return NurbsCurve2D([(0, -r, 1), (r, -r, W), (r, 0, 1), (r, r, W), (0, r, 1)],
                        knotList=[0, 0, 0, 0.5, 0.5, 1, 1, 1], degree=2, stride=stride)


def ngon_area(r, n):
    return 0.5 * n * r * r * math.sin(2 * math.pi / n)


def test_revolved_semicircle_is_a_sphere():
    v, t, closed = Revolution(semicircle(2.0), 24)._mesh()
    assert closed and in_range(v, t)
    assert all(math.sqrt(sum(c * c for c in p)) == pytest.approx(2.0) for p in v)
    vol = signed_volume(v, t)
    assert 0 < vol < 4 / 3 * math.pi * 8
    assert vol == pytest.approx(4 / 3 * math.pi * 8, rel=0.05)  # inscribed polyhedron, 24 x 40


def test_revolved_segment_is_a_cone_side():
    # profile from the apex (0, h) down to (r, 0): the side of a cone of slant sqrt(r^2 + h^2)
    r, h, n = 1.0, 2.0, 64
    v, t, closed = Revolution(Polyline2D([(0, h), (r, 0)]), n)._mesh()
    assert not closed and len(v) == 2 * n
    assert area(v, t) == pytest.approx(n * math.sin(math.pi / n) * r * math.sqrt(h * h + r * r * math.cos(math.pi / n) ** 2))


def test_revolution_orientation_follows_the_profile():
    # a closed revolved solid (profile from the axis to the axis, upward) faces outward
    v, t, _ = Revolution(Polyline2D([(0, 0), (1, 0), (1, 1), (0, 1)]), 16)._mesh()
    assert signed_volume(v, t) == pytest.approx(ngon_area(1, 16))


def test_revolution_needs_a_2d_profile():
    with pytest.raises(TypeError):
        Revolution(Polyline([(0, 0, 0), (1, 0, 1)]))
    with pytest.raises(ValueError):
        Revolution(Polyline2D([(0, 0), (1, 1)]), 2)


def test_extruded_circle_along_a_line_is_a_prism():
    n = 12
    section = Polyline2D.Circle(0.5, n)  # closed: the last point is the first
    ext = Extrusion(Polyline([(0, 0, 0), (0, 0, 3)]), section, solid=True)
    v, t, closed = ext._mesh()
    assert closed and in_range(v, t)
    assert signed_volume(v, t) == pytest.approx(ngon_area(0.5, n) * 3)
    assert min(p[2] for p in v) == pytest.approx(0) and max(p[2] for p in v) == pytest.approx(3)


def test_extrusion_along_a_curve_keeps_the_section_across_the_axis():
    # the axis, a quarter circle of radius 5 in the xz plane; every ring is a circle of radius
    # 0.2 around its axis point, in the plane across the tangent
    axis = NurbsCurve([(5, 0, 0, 1), (5, 0, 5, W), (0, 0, 5, 1)], knotList=[0, 0, 0, 1, 1, 1], degree=2, stride=20)
    m = 10
    ext = Extrusion(axis, Polyline2D.Circle(0.2, m))
    v, t, closed = ext._mesh()
    assert not closed
    for i in range(21):
        ring = v[i * m:(i + 1) * m]
        c = Vector3(*[sum(p[k] for p in ring) / m for k in range(3)])
        assert math.hypot(c.x, c.z) == pytest.approx(5, abs=1e-3)
        for p in ring:
            d = Vector3(*p) - c
            assert math.sqrt(d * d) == pytest.approx(0.2, rel=1e-6)
            # across the tangent of the circle at c: d . tangent = 0
            tangent = Vector3(-c.z, 0, c.x)
            assert abs(d * tangent) < 1e-6 * 5


def test_extrusion_scale_and_orientation():
    section = Polyline2D([(-1, 0), (1, 0)])
    ext = Extrusion(Polyline([(0, 0, 0), (0, 0, 1)]), section, scale=[(1, 1), (3, 3)], orientation=[0, math.pi / 2],
                    initialNormal=Vector3(1, 0, 0))
    v, _, _ = ext._mesh()
    assert v[0] == pytest.approx((-1, 0, 0)) and v[1] == pytest.approx((1, 0, 0))
    # at the end: three times longer and turned a quarter turn (x -> y)
    assert v[-2] == pytest.approx((0, -3, 1), abs=1e-9) and v[-1] == pytest.approx((0, 3, 1), abs=1e-9)


def test_swung_of_equal_profiles_is_their_revolution():
    prof = BezierCurve2D([(0, 0), (1, 0.5), (0.5, 1.5), (0, 2)], stride=12)
    sw = Swung([prof, prof, prof], [0, math.pi, 2 * math.pi], slices=16)
    rv = Revolution(prof, 16)
    v1, t1, c1 = sw._mesh()
    v2, t2, c2 = rv._mesh()
    assert t1 == t2 and c1 and c2
    assert all(a == pytest.approx(b, abs=1e-12) for p, q in zip(v1, v2) for a, b in zip(p, q))


def test_swung_interpolates_across_angles():
    # a profile of radius 1 at angle 0 and radius 2 at pi: linear (degree 1) halfway is 1.5; the
    # cubic passes through both and stays between them on this monotone data
    p1, p2 = Polyline2D([(1, 0), (1, 1)]), Polyline2D([(2, 0), (2, 1)])
    lin = Swung([p1, p2], [0, math.pi], slices=4, degree=1)
    v, _, closed = lin._mesh()
    assert not closed
    radius = [math.hypot(p[0], p[1]) for p in v]
    assert radius[0:3] == pytest.approx([1, 1, 1])  # angle 0 (3 samples: stride 2)
    assert radius[6] == pytest.approx(1.5)  # angle pi/2
    cub = Swung([p1, p2], [0, math.pi], slices=4)
    r = [math.hypot(p[0], p[1]) for p in cub._mesh()[0]]
    assert r[0] == pytest.approx(1) and 1 < r[3] < r[6] < r[9] < 2


def test_swung_refuses_what_it_lacks():
    p = Polyline2D([(1, 0), (1, 1)])
    with pytest.raises(NotInVerdant, match="degree=2"):
        Swung([p, p], [0, 1], degree=2)
    with pytest.raises(ValueError):
        Swung([p, p], [0])
