# SPDX-License-Identifier: MIT
"""The shim's solids and transformations: the meshes the turtle draws, checked for closure,
orientation (outward normals give a positive volume) and their size against the closed forms
of the polyhedra they are (an n-gon prism for a cylinder of n slices, ...)."""
import math

import pytest

from meshcheck import area, in_range, is_closed, signed_volume
from lpyshim.pgl_geometry import AxisRotated, Box, Cone, Cylinder, Disc, FaceSet, Frustum, Group, Oriented, \
    Paraboloid, Scaled, Shape, Sphere, Translated, TriangleSet, _mesh_of
from lpyshim.pgl_math import Vector3


def ngon_area(r, n):
    return 0.5 * n * r * r * math.sin(2 * math.pi / n)


def test_cylinder_is_a_closed_prism():
    v, t, closed = Cylinder(0.5, 2.0, True, 12)._mesh()
    assert closed and is_closed(t) and in_range(v, t)
    assert signed_volume(v, t) == pytest.approx(ngon_area(0.5, 12) * 2.0)


def test_frustum_volume():
    r, h, k, n = 1.0, 3.0, 0.5, 16
    v, t, _ = Frustum(r, h, k, True, n)._mesh()
    a0, a1 = ngon_area(r, n), ngon_area(r * k, n)
    assert is_closed(t)
    assert signed_volume(v, t) == pytest.approx(h / 3 * (a0 + a1 + math.sqrt(a0 * a1)))


def test_cone_open_side_only():
    v, t, closed = Cone(1.0, 2.0, False, 8)._mesh()
    assert not closed
    assert all(0 <= p[2] <= 2 for p in v)


def test_sphere_points_on_the_sphere():
    v, t, closed = Sphere(2.0, 10, 6)._mesh()
    assert closed and is_closed(t)
    assert all(math.sqrt(sum(c * c for c in p)) == pytest.approx(2.0) for p in v)
    vol = signed_volume(v, t)
    assert 0 < vol < 4 / 3 * math.pi * 8


def test_box_has_half_sizes():
    v, t, closed = Box(Vector3(1, 2, 3))._mesh()
    assert closed and is_closed(t)
    assert signed_volume(v, t) == pytest.approx(8 * 1 * 2 * 3)
    assert area(v, t) == pytest.approx(2 * (2 * 4 + 2 * 6 + 4 * 6))


def test_disc_area():
    v, t, closed = Disc(1.0, 20)._mesh()
    assert not closed
    assert area(v, t) == pytest.approx(ngon_area(1.0, 20))


def test_paraboloid_apex_and_base():
    v, t, closed = Paraboloid(1.0, 2.0, 2.0, True, 12, 6)._mesh()
    assert closed and is_closed(t) and in_range(v, t)
    assert max(p[2] for p in v) == pytest.approx(2.0)
    assert signed_volume(v, t) > 0


def test_faceset_fans_its_polygons():
    fs = FaceSet([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], [(0, 1, 2, 3)])
    v, t, _ = fs._mesh()
    assert len(t) == 2 and area(v, t) == pytest.approx(1)
    ts = TriangleSet([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1, 2)])
    assert _mesh_of(ts)[1] == [(0, 1, 2)]


def test_transformations_map_points():
    box = Box(Vector3(1, 1, 1))
    v = _mesh_of(Translated(Vector3(1, 2, 3), box))[0]
    assert min(p[0] for p in v) == pytest.approx(0) and max(p[2] for p in v) == pytest.approx(4)
    v = _mesh_of(Scaled(Vector3(2, 1, 1), box))[0]
    assert max(p[0] for p in v) == pytest.approx(2)
    cyl = Cylinder(0.1, 1.0, True, 8)
    v = _mesh_of(AxisRotated(Vector3(0, 1, 0), math.pi / 2, cyl))[0]
    assert max(p[0] for p in v) == pytest.approx(1.0)  # the axis turned from z to x
    v = _mesh_of(Oriented(Vector3(0, 1, 0), Vector3(0, 0, 1), cyl))[0]
    assert max(p[0] for p in v) == pytest.approx(1.0)  # local z = primary x secondary = x
    # rotations keep the volume and the orientation
    vv, tt, _ = _mesh_of(AxisRotated(Vector3(1, 1, 1), 0.4, Cylinder(0.5, 2.0, True, 12)))
    assert signed_volume(vv, tt) == pytest.approx(ngon_area(0.5, 12) * 2.0)


def test_group_and_shape_merge_meshes():
    a, b = Box(Vector3(1, 1, 1)), Translated(Vector3(5, 0, 0), Box(Vector3(1, 1, 1)))
    v, t, closed = _mesh_of(Group([Shape(a), Shape(b)]))
    assert len(v) == 16 and len(t) == 24 and closed and in_range(v, t)
    assert signed_volume(v, t) == pytest.approx(16)
