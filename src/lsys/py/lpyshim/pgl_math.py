# SPDX-License-Identifier: MIT
"""openalea.plantgl.math: vectors (Vector2/3/4), Matrix3 and the point arrays."""
import math as _math

# ---------------------------------------------------------------------------------------------
# openalea.plantgl.math: vectors


class _Vec:
    __slots__ = ("_c",)
    _n = 0
    _names = ("x", "y", "z", "w")

    def __init__(self, *a):
        if len(a) == 1 and not isinstance(a[0], (int, float)):
            a = tuple(a[0])
        elif len(a) >= 1 and isinstance(a[0], _Vec) and len(a[0]) < self._n:
            a = tuple(a[0]) + tuple(a[1:])
        if not a:
            a = (0.0,) * self._n
        if len(a) != self._n:
            raise TypeError("%s takes %d coordinates, got %d" % (type(self).__name__, self._n, len(a)))
        self._c = [float(v) for v in a]

    def __getitem__(self, i):
        return self._c[i]

    def __setitem__(self, i, v):
        self._c[i] = float(v)

    def __len__(self):
        return self._n

    def __iter__(self):
        return iter(self._c)

    def _new(self, c):
        v = object.__new__(type(self))
        v._c = list(c)
        return v

    def __add__(self, o):
        return self._new(a + b for a, b in zip(self._c, _coords(o, self._n)))

    __radd__ = __add__

    def __sub__(self, o):
        return self._new(a - b for a, b in zip(self._c, _coords(o, self._n)))

    def __rsub__(self, o):
        return self._new(b - a for a, b in zip(self._c, _coords(o, self._n)))

    def __neg__(self):
        return self._new(-a for a in self._c)

    def __pos__(self):
        return self._new(self._c)

    def __mul__(self, o):
        if isinstance(o, (_Vec, tuple, list)):
            return sum(a * b for a, b in zip(self._c, _coords(o, self._n)))  # dot product
        return self._new(a * o for a in self._c)

    def __rmul__(self, o):
        return self.__mul__(o)

    def __truediv__(self, o):
        return self._new(a / o for a in self._c)

    def __iadd__(self, o):
        self._c = [a + b for a, b in zip(self._c, _coords(o, self._n))]
        return self

    def __isub__(self, o):
        self._c = [a - b for a, b in zip(self._c, _coords(o, self._n))]
        return self

    def __imul__(self, o):
        self._c = [a * o for a in self._c]
        return self

    def __itruediv__(self, o):
        self._c = [a / o for a in self._c]
        return self

    def __eq__(self, o):
        try:
            return all(abs(a - b) < 1e-10 for a, b in zip(self._c, _coords(o, self._n)))
        except TypeError:
            return NotImplemented

    def __ne__(self, o):
        r = self.__eq__(o)
        return r if r is NotImplemented else not r

    __hash__ = None

    def __abs__(self):
        return self._new(abs(a) for a in self._c)

    def __repr__(self):
        return "%s(%s)" % (type(self).__name__, ",".join("%g" % a for a in self._c))

    __str__ = __repr__

    def __norm__(self):
        return _math.sqrt(sum(a * a for a in self._c))

    def __normSquared__(self):
        return sum(a * a for a in self._c)

    def __normL1__(self):
        return sum(abs(a) for a in self._c)

    def __normLinf__(self):
        return max(abs(a) for a in self._c)

    def __direction__(self):
        return self.normed()

    def normalize(self):
        n = self.__norm__()
        if n > 0:
            self._c = [a / n for a in self._c]
        return n

    def normed(self):
        n = self.__norm__()
        return self._new(a / n for a in self._c) if n > 0 else self._new(self._c)

    def isNormalized(self):
        return abs(self.__norm__() - 1) < 1e-10

    def isOrthogonalTo(self, o):
        return abs(self * o) < 1e-10

    def isValid(self):
        return all(_math.isfinite(a) for a in self._c)

    def cwiseProduct(self, o):
        return self._new(a * b for a, b in zip(self._c, _coords(o, self._n)))

    def getMaxAbsCoord(self):
        return max(range(self._n), key=lambda i: abs(self._c[i]))

    def getMinAbsCoord(self):
        return min(range(self._n), key=lambda i: abs(self._c[i]))

    def __getattr__(self, k):
        if k in self._names[: self._n]:
            return self._c[self._names.index(k)]
        raise AttributeError(k)

    def __setattr__(self, k, v):
        if k in ("x", "y", "z", "w")[: self._n]:
            self._c[self._names.index(k)] = float(v)
        else:
            object.__setattr__(self, k, v)


def _coords(o, n):
    if isinstance(o, _Vec):
        return o._c
    if isinstance(o, (tuple, list)) and len(o) == n:
        return o
    raise TypeError("expected a vector of %d coordinates" % n)


class Vector2(_Vec):
    __slots__ = ()
    _n = 2

    def __xor__(self, o):
        o = _coords(o, 2)
        return self._c[0] * o[1] - self._c[1] * o[0]

    def __mod__(self, o):
        return self.__xor__(o)


class Vector3(_Vec):
    __slots__ = ()
    _n = 3

    def __xor__(self, o):
        a, b = self._c, _coords(o, 3)
        return Vector3(a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])

    def __mod__(self, o):
        return self.__xor__(o)

    def anOrthogonalVector(self):
        x, y, z = self._c
        v = Vector3(-y, x, 0) if abs(x) > 1e-10 or abs(y) > 1e-10 else Vector3(0, -z, y)
        return v.normed()

    @staticmethod
    def Spherical(r, theta, phi):
        return Vector3(r * _math.cos(theta) * _math.sin(phi), r * _math.sin(theta) * _math.sin(phi), r * _math.cos(phi))

    @staticmethod
    def Cylindrical(r, theta, z):
        return Vector3(r * _math.cos(theta), r * _math.sin(theta), z)


class Vector4(_Vec):
    __slots__ = ()
    _n = 4

    def project(self):
        w = self._c[3]
        return Vector3(*(a / w for a in self._c[:3])) if w else Vector3(*self._c[:3])


Vector2.ORIGIN = Vector2(0, 0)
Vector2.OX = Vector2(1, 0)
Vector2.OY = Vector2(0, 1)
Vector3.ORIGIN = Vector3(0, 0, 0)
Vector3.OX = Vector3(1, 0, 0)
Vector3.OY = Vector3(0, 1, 0)
Vector3.OZ = Vector3(0, 0, 1)
Vector4.ORIGIN = Vector4(0, 0, 0, 0)
Vector4.OX = Vector4(1, 0, 0, 0)
Vector4.OY = Vector4(0, 1, 0, 0)
Vector4.OZ = Vector4(0, 0, 1, 0)
Vector4.OW = Vector4(0, 0, 0, 1)


def _vec(v):
    if isinstance(v, _Vec):
        return v
    v = tuple(v)
    return (Vector2, Vector3, Vector4)[len(v) - 2](*v)


def norm(v):
    return _vec(v).__norm__()


def normSquared(v):
    return _vec(v).__normSquared__()


def normL1(v):
    return _vec(v).__normL1__()


def normLinf(v):
    return _vec(v).__normLinf__()


def direction(v):
    return _vec(v).normed()


def dot(a, b):
    return _vec(a) * _vec(b)


def cross(a, b):
    return _vec(a) ^ _vec(b)


def angle(a, b, axis=None):
    """Angle between a and b (radians); signed around axis when given (PlantGL's angle)."""
    a, b = _vec(a), _vec(b)
    if isinstance(a, Vector2):
        return _math.atan2(a ^ b, a * b)
    c = a ^ b
    ang = _math.atan2(norm(c), a * b)
    if axis is not None and c * _vec(axis) < 0:
        ang = -ang
    return ang


class Matrix3:
    """3x3 matrix (rows), with PlantGL's axis rotation."""

    def __init__(self, *rows):
        if len(rows) == 3 and all(isinstance(r, (_Vec, tuple, list)) for r in rows):
            self.m = [list(map(float, r)) for r in rows]
        elif len(rows) == 9:
            self.m = [list(map(float, rows[i:i + 3])) for i in (0, 3, 6)]
        else:
            self.m = [[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]]

    @staticmethod
    def axisRotation(axis, ang):
        x, y, z = _vec(axis).normed()
        c, s, t = _math.cos(ang), _math.sin(ang), 1 - _math.cos(ang)
        return Matrix3(t * x * x + c, t * x * y - s * z, t * x * z + s * y,
                       t * x * y + s * z, t * y * y + c, t * y * z - s * x,
                       t * x * z - s * y, t * y * z + s * x, t * z * z + c)

    def __mul__(self, o):
        if isinstance(o, Matrix3):
            return Matrix3(*[sum(self.m[i][k] * o.m[k][j] for k in range(3)) for i in range(3) for j in range(3)])
        if isinstance(o, (int, float)):
            return Matrix3(*[v * o for r in self.m for v in r])
        v = _coords(o, 3)
        return Vector3(*(sum(r[k] * v[k] for k in range(3)) for r in self.m))

    def transpose(self):
        return Matrix3(*[self.m[j][i] for i in range(3) for j in range(3)])

    def getColumn(self, j):
        return Vector3(*(r[j] for r in self.m))

    def getRow(self, i):
        return Vector3(*self.m[i])

    def __getitem__(self, ij):
        return self.m[ij[0]][ij[1]]

    def __repr__(self):
        return "Matrix3(%s)" % self.m


# ---------------------------------------------------------------------------------------------
# arrays


class _Array(list):
    _kind = None

    def __init__(self, items=()):
        if isinstance(items, int):
            items = [self._kind() for _ in range(items)] if self._kind else [0.0] * items
        super().__init__(self._conv(v) for v in items)

    def _conv(self, v):
        return self._kind(v) if self._kind is not None and not isinstance(v, self._kind) else v

    def append(self, v):
        list.append(self, self._conv(v))

    def __setitem__(self, i, v):
        list.__setitem__(self, i, self._conv(v) if not isinstance(i, slice) else [self._conv(x) for x in v])

    def getLength(self):
        return len(self)

    def __getitem__(self, i):
        r = list.__getitem__(self, i)
        return type(self)(r) if isinstance(i, slice) else r


class Point2Array(_Array):
    _kind = Vector2


class Point3Array(_Array):
    _kind = Vector3


class Point4Array(_Array):
    _kind = Vector4


class RealArray(_Array):
    _kind = float


class Index3Array(list):
    pass


class Index4Array(list):
    pass


class IndexArray(list):
    pass


class Point2Matrix(list):
    pass


class Point3Matrix(list):
    pass


class Point4Matrix(list):
    def __init__(self, rows=()):
        super().__init__([Vector4(*p) if not isinstance(p, Vector4) else p for p in r] for r in rows)


