# SPDX-License-Identifier: MIT
"""PlantGL's geometry for custom shapes: solids, explicit meshes, transformations, groups,
shapes and scenes. Each gives the turtle a triangle mesh: _mesh() -> (vertices, triangles,
closed)."""
import math as _math

from .pgl_math import Matrix3, Point3Array, Vector3, _vec, norm

# ---------------------------------------------------------------------------------------------
# curves (scenegraph/geometry: nurbscurve, beziercurve, polyline, curve)

_EPS = 1e-6


class _Geometry:
    """Any PlantGL geometry: a name, and a triangle mesh for the turtle (_vd_mesh)."""
    name = ""

    def isValid(self):
        return True

    def deepcopy(self):
        import copy
        return copy.deepcopy(self)

    def getName(self):
        return self.name




# ---------------------------------------------------------------------------------------------
# geometry for custom shapes (@g, PglShape): each gives verdant a triangle mesh (_mesh)


def _ring(r, n, z):
    return [(r * _math.cos(2 * _math.pi * i / n), r * _math.sin(2 * _math.pi * i / n), z) for i in range(n)]


class Sphere(_Geometry):
    def __init__(self, radius=0.5, slices=8, stacks=8, **kw):
        self.radius, self.slices, self.stacks = radius, max(3, int(slices)), max(2, int(stacks))

    def _mesh(self):
        v, t, n, m = [(0, 0, -self.radius)], [], self.slices, self.stacks
        for k in range(1, m):
            phi = -_math.pi / 2 + _math.pi * k / m
            v += _ring(self.radius * _math.cos(phi), n, self.radius * _math.sin(phi))
        v.append((0, 0, self.radius))
        top = len(v) - 1
        for i in range(n):
            j = (i + 1) % n
            t.append((0, 1 + j, 1 + i))
            for k in range(m - 2):
                a, b = 1 + k * n, 1 + (k + 1) * n
                t += [(a + i, a + j, b + j), (a + i, b + j, b + i)]
            c = 1 + (m - 2) * n
            t.append((c + i, c + j, top))
        return v, t, True


class Frustum(_Geometry):
    def __init__(self, radius=0.5, height=1.0, taper=0.5, solid=True, slices=8, **kw):
        self.radius, self.height, self.taper, self.solid, self.slices = radius, height, taper, solid, max(3, int(slices))

    def _mesh(self):
        n = self.slices
        v = _ring(self.radius, n, 0) + _ring(self.radius * self.taper, n, self.height)
        t = []
        for i in range(n):
            j = (i + 1) % n
            t += [(i, j, n + j), (i, n + j, n + i)]
        if self.solid:
            v += [(0, 0, 0), (0, 0, self.height)]
            for i in range(n):
                j = (i + 1) % n
                t += [(2 * n, j, i), (2 * n + 1, n + i, n + j)]
        return v, t, bool(self.solid)


class Cylinder(Frustum):
    def __init__(self, radius=0.5, height=1.0, solid=True, slices=8, **kw):
        Frustum.__init__(self, radius, height, 1.0, solid, slices)


class Cone(Frustum):
    def __init__(self, radius=0.5, height=1.0, solid=True, slices=8, **kw):
        Frustum.__init__(self, radius, height, 0.0, solid, slices)


class Disc(_Geometry):
    def __init__(self, radius=0.5, slices=8, **kw):
        self.radius, self.slices = radius, max(3, int(slices))

    def _mesh(self):
        n = self.slices
        v = [(0, 0, 0)] + _ring(self.radius, n, 0)
        return v, [(0, 1 + i, 1 + (i + 1) % n) for i in range(n)], False


class Box(_Geometry):
    def __init__(self, size=Vector3(0.5, 0.5, 0.5), *more, **kw):
        self.size = Vector3(size, *more) if more else (_vec(size) if not isinstance(size, (int, float))
                                                        else Vector3(size, size, size))

    def _mesh(self):
        x, y, z = self.size
        v = [(sx * x, sy * y, sz * z) for sz in (-1, 1) for sy in (-1, 1) for sx in (-1, 1)]
        t = [(0, 2, 1), (1, 2, 3), (4, 5, 6), (5, 7, 6), (0, 1, 4), (1, 5, 4),
             (2, 6, 3), (3, 6, 7), (0, 4, 2), (2, 4, 6), (1, 3, 5), (3, 7, 5)]
        return v, t, True


class Mesh(_Geometry):
    """The base of PlantGL's explicit meshes (TriangleSet, QuadSet, FaceSet)."""


class TriangleSet(Mesh):
    def __init__(self, pointList=(), indexList=(), *a, **kw):
        self.pointList = Point3Array(pointList)
        self.indexList = [tuple(int(i) for i in f) for f in indexList]

    def _mesh(self):
        return [tuple(p) for p in self.pointList], list(self.indexList), False


class FaceSet(TriangleSet):
    def _mesh(self):
        t = []
        for f in self.indexList:
            t += [(f[0], f[k], f[k + 1]) for k in range(1, len(f) - 1)]
        return [tuple(p) for p in self.pointList], t, False


QuadSet = FaceSet


class Paraboloid(_Geometry):
    """z = height (r / radius)^shape around the axis (PlantGL's Paraboloid), r from 0 to radius."""

    def __init__(self, radius=0.5, height=1.0, shape=2.0, solid=True, slices=8, stacks=8, **kw):
        self.radius, self.height, self.shape, self.solid = radius, height, shape, solid
        self.slices, self.stacks = max(3, int(slices)), max(1, int(stacks))

    def _mesh(self):
        n, m = self.slices, self.stacks
        v, t = [(0.0, 0.0, self.height)], []
        for k in range(1, m + 1):
            # PlantGL's profile: the height falls from the apex as the radius opens
            r = self.radius * k / m
            v += _ring(r, n, self.height * (1 - (k / m) ** self.shape))
        for i in range(n):
            j = (i + 1) % n
            t.append((0, 1 + i, 1 + j))
            for k in range(m - 1):
                a, b = 1 + k * n, 1 + (k + 1) * n
                t += [(a + i, b + i, b + j), (a + i, b + j, a + j)]
        closed = bool(self.solid)
        if closed:
            c = len(v)
            v.append((0.0, 0.0, 0.0))
            base = 1 + (m - 1) * n
            t += [(c, base + (i + 1) % n, base + i) for i in range(n)]
        return v, t, closed


class _Transformed(_Geometry):
    def __init__(self, *a, **kw):
        self.geometry = a[-1] if a else kw.get("geometry")

    def _map(self, p):
        return p

    def _mesh(self):
        m = _mesh_of(self.geometry)
        if m is None:
            return None
        v, t, closed = m
        return [self._map(p) for p in v], t, closed


class Translated(_Transformed):
    def __init__(self, translation=Vector3(0, 0, 0), geometry=None, **kw):
        self.translation, self.geometry = _vec(translation), geometry

    def _map(self, p):
        return tuple(a + b for a, b in zip(p, self.translation))


class Scaled(_Transformed):
    def __init__(self, scale=Vector3(1, 1, 1), geometry=None, **kw):
        self.scale = Vector3(scale, scale, scale) if isinstance(scale, (int, float)) else _vec(scale)
        self.geometry = geometry

    def _map(self, p):
        return tuple(a * b for a, b in zip(p, self.scale))


class AxisRotated(_Transformed):
    def __init__(self, axis=Vector3(0, 0, 1), angle=0.0, geometry=None, **kw):
        self.axis, self.angle, self.geometry = _vec(axis), angle, geometry
        self._m = Matrix3.axisRotation(self.axis, angle)

    def _map(self, p):
        return tuple(self._m * Vector3(*p))


class EulerRotated(_Transformed):
    def __init__(self, azimuth=0.0, elevation=0.0, roll=0.0, geometry=None, **kw):
        self.azimuth, self.elevation, self.roll, self.geometry = azimuth, elevation, roll, geometry
        self._m = (Matrix3.axisRotation((0, 0, 1), azimuth) * Matrix3.axisRotation((0, 1, 0), -elevation) *
                   Matrix3.axisRotation((1, 0, 0), roll))

    def _map(self, p):
        return tuple(self._m * Vector3(*p))


class Oriented(_Transformed):
    def __init__(self, primary=Vector3(1, 0, 0), secondary=Vector3(0, 1, 0), geometry=None, **kw):
        self.primary, self.secondary, self.geometry = _vec(primary).normed(), _vec(secondary).normed(), geometry
        self._t = self.primary ^ self.secondary

    def _map(self, p):
        return tuple(self.primary * p[0] + self.secondary * p[1] + self._t * p[2])


class Group(_Geometry):
    def __init__(self, geometryList=(), *a, **kw):
        self.geometryList = list(geometryList) if not isinstance(geometryList, _Geometry) else [geometryList, *a]

    def _mesh(self):
        v, t, closed = [], [], True
        for g in self.geometryList:
            m = _mesh_of(g)
            if m is None:
                continue
            o = len(v)
            v += m[0]
            t += [(a + o, b + o, c + o) for a, b, c in m[1]]
            closed = closed and m[2]
        return v, t, closed and bool(t)


class Shape(_Geometry):
    def __init__(self, geometry=None, appearance=None, id=0, parentId=0, **kw):
        self.geometry, self.appearance, self.id, self.parentId = geometry, appearance, id, parentId

    def _mesh(self):
        return _mesh_of(self.geometry)


class Scene(list):
    """A list of Shapes. The one a hook receives (EndEach(lstring, lscene)) is filled on first use
    with what the turtle draws from the string: one Shape per primitive, id = the module's index
    in the string, geometry as PglTurtleDrawer builds it (Cylinder/Frustum/Cone placed by
    Oriented and Translated, Polyline for zero radii, Sphere, TriangleSet)."""
    _vd_source = None  # a function giving the shapes still to add (the engine's turtle)

    def _vd_fill(self):
        if self._vd_source is not None:
            source, self._vd_source = self._vd_source, None
            list.extend(self, source())

    def __len__(self):
        self._vd_fill()
        return list.__len__(self)

    def __getitem__(self, i):
        self._vd_fill()
        return list.__getitem__(self, i)

    def __iter__(self):
        self._vd_fill()
        return list.__iter__(self)

    def __bool__(self):
        return self.__len__() > 0

    def add(self, s):
        self._vd_fill()
        self.append(s)

    def todict(self):
        d = {}
        for sh in self:
            d.setdefault(sh.id, []).append(sh)
        return d

    def _mesh(self):
        return Group(list(self))._mesh()


def _mesh_of(g):
    """(vertices, triangles, closed) of a geometry; None for one without a surface (a curve)."""
    if g is None:
        return None
    f = getattr(g, "_mesh", None)
    return f() if f is not None else None


