# SPDX-License-Identifier: MIT
"""openalea.plantgl.math of the shim: vectors and matrices against hand-computed values."""
import math

import pytest

from lpyshim.pgl_math import Matrix3, Point3Array, Vector2, Vector3, Vector4, angle, cross, direction, dot, norm


def test_vector_arithmetic():
    a, b = Vector3(1, 2, 3), Vector3(-2, 0.5, 4)
    assert a + b == Vector3(-1, 2.5, 7)
    assert a - b == Vector3(3, 1.5, -1)
    assert a * b == pytest.approx(-2 + 1 + 12)  # v * w is the dot product, as in PlantGL
    assert dot(a, b) == pytest.approx(11)
    assert a ^ b == Vector3(2 * 4 - 3 * 0.5, 3 * -2 - 1 * 4, 1 * 0.5 - 2 * -2)
    assert cross(a, b) == a ^ b
    assert (a * 2) / 4 == Vector3(0.5, 1, 1.5)
    assert Vector2(1, 0) ^ Vector2(0, 1) == 1  # the 2D cross product is a number


def test_normalize_returns_the_old_norm():
    v = Vector3(3, 4, 12)
    assert v.normalize() == pytest.approx(13)
    assert norm(v) == pytest.approx(1)
    assert direction(Vector3(0, 0, 5)) == Vector3(0, 0, 1)


def test_signed_angle_around_an_axis():
    x, y, z = Vector3(1, 0, 0), Vector3(0, 1, 0), Vector3(0, 0, 1)
    assert angle(x, y) == pytest.approx(math.pi / 2)
    assert angle(x, y, z) == pytest.approx(math.pi / 2)
    assert angle(y, x, z) == pytest.approx(-math.pi / 2)


def test_axis_rotation():
    r = Matrix3.axisRotation(Vector3(0, 0, 1), math.pi / 2)
    assert r * Vector3(1, 0, 0) == Vector3(0, 1, 0)
    # a rotation keeps lengths and its transpose undoes it
    v = Vector3(0.3, -1.2, 2.0)
    w = Matrix3.axisRotation(Vector3(1, 1, 0), 0.7) * v
    assert norm(w) == pytest.approx(norm(v))
    assert Matrix3.axisRotation(Vector3(1, 1, 0), 0.7).transpose() * w == v


def test_vector4_projects_by_its_weight():
    assert Vector4(2, 4, 6, 2).project() == Vector3(1, 2, 3)


def test_arrays_convert_their_items():
    a = Point3Array([(1, 2, 3), [4, 5, 6]])
    assert isinstance(a[1], Vector3) and a[1] == Vector3(4, 5, 6)
    a.append((0, 0, 1))
    assert isinstance(a[2], Vector3)
    assert isinstance(a[0:2], Point3Array)


def test_wrong_sizes_are_errors():
    with pytest.raises(TypeError):
        Vector3(1, 2)
    with pytest.raises(TypeError):
        Vector3(1, 2, 3) + (1, 2)
