# SPDX-License-Identifier: MIT
"""PlantGL's algorithms: point grids (the spatial queries of space-colonisation models), point
set directions, the Discretizer action."""
import itertools as _itertools
import math as _math

from .pgl_curves import Polyline, Polyline2D, _Curve
from .pgl_geometry import TriangleSet, _Geometry, _mesh_of
from .pgl_math import Point2Array, Point3Array, Vector2, Vector3, _Vec, _vec, direction, norm

# ---------------------------------------------------------------------------------------------
# algorithms: point grids (spatial queries of space-colonisation models) and the Discretizer


class _PointGrid:
    """PlantGL's Point2Grid/Point3Grid: the points filed in voxels of a regular grid over their
    bounds. Queries give the indices of the enabled points, voxel by voxel (in the order of the
    voxels' linear ids, then of their filing); a disabled point is no longer found until it is
    enabled again. Built as Point3Grid(voxelsize, points), Point3Grid(voxelsize, minpoint,
    maxpoint, points) or Point3Grid(points, n) (n voxels along each axis of the bounds)."""
    _vec = None

    def __init__(self, *a):
        if len(a) == 2 and self._is_points(a[0]):
            pts, n = a
            self._init_points(pts)
            n = float(n)
            if not n > 0:
                raise ValueError("%s: the number of voxels per axis must be positive" % type(self).__name__)
            size = [(hi - lo) / n for lo, hi in zip(self._lo, self._hi)]
        elif len(a) == 2:
            self._init_points(a[1])
            size = self._size(a[0])
        elif len(a) == 4:
            self._init_points(a[3])
            self._lo, self._hi = list(self._vec(a[1])), list(self._vec(a[2]))
            size = self._size(a[0])
        else:
            raise TypeError("%s(voxelsize, points), (voxelsize, minpoint, maxpoint, points) or (points, n)"
                            % type(self).__name__)
        # an axis without extent (or a zero voxel size) has one voxel
        self._vs = [s if s > 0 else 1.0 for s in size]
        self._dims = [max(1, int(_math.floor((hi - lo) / s)) + 1) for lo, hi, s in zip(self._lo, self._hi, self._vs)]
        self._cells = {}
        for i, p in enumerate(self._pts):
            self._cells.setdefault(self._cell(p), []).append(i)

    def _is_points(self, x):
        if isinstance(x, (int, float, _Vec)):
            return False
        x = list(x)
        return not x or not isinstance(x[0], (int, float))

    def _size(self, v):
        d = len(self._lo)
        if isinstance(v, (int, float)):
            return [float(v)] * d
        return [float(c) for c in self._vec(v)]

    def _init_points(self, pts):
        self._pts = [tuple(float(c) for c in self._vec(p)) for p in pts]
        d = 2 if self._vec is Vector2 else 3
        if self._pts:
            self._lo = [min(p[k] for p in self._pts) for k in range(d)]
            self._hi = [max(p[k] for p in self._pts) for k in range(d)]
        else:
            self._lo, self._hi = [0.0] * d, [0.0] * d

    def _index(self, x, k):
        return min(max(int(_math.floor((x - self._lo[k]) / self._vs[k])), 0), self._dims[k] - 1)

    def _cell(self, p):
        return tuple(self._index(x, k) for k, x in enumerate(p))

    def _around(self, c, r):
        """The enabled point indices of the voxels that the box c +- r touches, in voxel order."""
        ranges = [range(self._index(x - r, k), self._index(x + r, k) + 1) for k, x in enumerate(c)]
        out = []
        for cell in _itertools.product(*ranges):
            out += self._cells.get(cell, ())
        return out

    def query_ball_point(self, point, radius):
        c = tuple(float(x) for x in self._vec(point))
        return [i for i in self._around(c, radius)
                if not _math.dist(self._pts[i], c) > radius]

    def query_points_in_cone(self, origin, direction, radius, angle=_math.pi / 2):
        o = tuple(float(x) for x in self._vec(origin))
        d = self._vec(direction).normed()
        cosa = _math.cos(angle / 2)
        out = []
        for i in self._around(o, radius):
            v = [a - b for a, b in zip(self._pts[i], o)]
            dist = _math.sqrt(sum(x * x for x in v))
            if dist > radius + 1e-5:
                continue
            dt = sum(x * y for x, y in zip(v, d)) / dist if dist > 0 else 0.0
            if dt > cosa - 1e-5:
                out.append(i)
        return out

    def closest_point(self, point, maxdist=float("inf")):
        """The index of the nearest enabled point within maxdist, or None."""
        c = tuple(float(x) for x in self._vec(point))
        best, bi = maxdist, None
        for cell in sorted(self._cells):
            for i in self._cells[cell]:
                dist = _math.dist(self._pts[i], c)
                if dist < best:
                    best, bi = dist, i
        return bi

    def is_point_enabled(self, i):
        return i in self._cells.get(self._cell(self._pts[i]), ())

    def disable_point(self, i):
        lst = self._cells.get(self._cell(self._pts[i]), [])
        if i in lst:
            lst.remove(i)
            return True
        return False

    def enable_point(self, i):
        lst = self._cells.setdefault(self._cell(self._pts[i]), [])
        if i not in lst:
            lst.append(i)
            return True
        return False

    def disable_points(self, ids):
        for i in list(ids):
            self.disable_point(i)

    def enable_points(self, ids):
        for i in list(ids):
            self.enable_point(i)

    def get_enabled_point_indices(self):
        return [i for i in range(len(self._pts)) if self.is_point_enabled(i)]

    def get_disabled_point_indices(self):
        return [i for i in range(len(self._pts)) if not self.is_point_enabled(i)]

    def _array(self, ids):
        return (Point2Array if self._vec is Vector2 else Point3Array)([self._pts[i] for i in ids])

    def get_enabled_points(self):
        return self._array(self.get_enabled_point_indices())

    def get_disabled_points(self):
        return self._array(self.get_disabled_point_indices())

    def nbFilledVoxels(self):
        return sum(1 for v in self._cells.values() if v)

    def size(self):
        n = 1
        for d in self._dims:
            n *= d
        return n

    def getVoxelSize(self):
        return self._vec(*self._vs)

    def dimensions(self):
        return tuple(self._dims)


class Point3Grid(_PointGrid):
    _vec = Vector3


class Point2Grid(_PointGrid):
    _vec = Vector2


def _group_points(points, group):
    pts = [_vec(points[i]) for i in group] if group else [_vec(p) for p in points]
    return pts


def pointset_directions(origin, points, group=()):
    """The unit directions from origin to the points (those of group when given)."""
    o = _vec(origin)
    return Point3Array([direction(p - o) for p in _group_points(points, group)])


def pointset_mean_direction(origin, points, group=()):
    """PlantGL's pointset_mean_direction: the normed mean of the unit directions from origin to
    the points (those of group when given)."""
    d = pointset_directions(origin, points, group)
    if not d:
        return Vector3(0, 0, 0)
    s = Vector3(0, 0, 0)
    for v in d:
        s += v
    return (s / len(d)).normed()


def findClosestFromSubset(origin, points, group=()):
    """(index, distance) of the point nearest origin (among group when given; the first of equals)."""
    o = _vec(origin)
    ids = list(group) if group else range(len(points))
    best = None
    for i in ids:
        dist = norm(_vec(points[i]) - o)
        if best is None or dist < best[1]:
            best = (i, dist)
    return best


class PointSet(_Geometry):
    """Points (PlantGL's PointSet): no surface, so @g of it draws nothing (with a warning)."""

    def __init__(self, pointList=(), colorList=None, width=1, **kw):
        self.pointList, self.colorList, self.width = Point3Array(pointList), colorList, width


class Discretizer:
    """PlantGL's Discretizer action: geometry.apply(d) puts the geometry's discrete form in
    d.result: a Polyline2D/Polyline of a curve's stride + 1 points, a TriangleSet of a surface
    or a solid (the mesh the turtle draws)."""

    def __init__(self):
        self.result = None

    def clear(self):
        self.result = None

    def getDiscretization(self):
        return self.result

    def process(self, g):
        if isinstance(g, _Curve):
            pts = g._vd_points(0)
            self.result = Polyline2D(pts) if len(pts[0]) == 2 else Polyline(pts)
            return True
        m = _mesh_of(g)
        if m is None:
            self.result = None
            return False
        self.result = TriangleSet(m[0], m[1])
        return True


def _geometry_apply(self, action):
    """PlantGL's geometry.apply(action): the action processes the geometry."""
    return action.process(self)


_Geometry.apply = _geometry_apply


