# SPDX-License-Identifier: MIT
"""PlantGL's curves and functions (scenegraph/geometry: nurbscurve, beziercurve, polyline, curve;
function/function.cpp): default knot vectors, homogeneous control points (x, y, w),
[firstKnot, lastKnot] parameter ranges, stride 30, QuantisedFunction's sampling 100, arc
length by the stride's chords."""
import math as _math

from .errors import NotInVerdant
from .pgl_geometry import _EPS, _Geometry
from .pgl_math import Point2Array, Point3Array, Point4Array, RealArray, Vector2, Vector3, _Vec, _vec, norm

class _Curve(_Geometry):
    _dim = 2
    stride = 30
    width = 1

    @property
    def firstKnot(self):
        return self.getFirstKnot()

    @property
    def lastKnot(self):
        return self.getLastKnot()

    def getFirstKnot(self):
        return 0.0

    def getLastKnot(self):
        return 1.0

    def getStride(self):
        return self.stride

    def _P(self, *c):
        return (Vector2 if self._dim == 2 else Vector3)(*c[: self._dim])

    def getTangentAt(self, u):
        """First derivative dC/du (central differences inside, one-sided at the ends)."""
        fk, lk = self.getFirstKnot(), self.getLastKnot()
        h = (lk - fk) * 1e-6
        a, b = max(fk, u - h), min(lk, u + h)
        if b <= a:
            return self._P(0, 0, 0)
        return (self.getPointAt(b) - self.getPointAt(a)) / (b - a)

    def getNormalAt(self, u):
        t = self.getTangentAt(u)
        if self._dim == 2:
            return Vector2(-t.y, t.x).normed()
        n = t ^ Vector3(0, 0, 1) if abs(t.x) > _EPS or abs(t.y) > _EPS else t ^ Vector3(1, 0, 0)
        return n.normed()

    def _samples(self, begin=None, end=None):
        fk, lk = self.getFirstKnot(), self.getLastKnot()
        n = max(1, int(self.getStride()))
        return [fk + (lk - fk) * i / n for i in range(n + 1)]

    def getLength(self, begin=None, end=None):
        """Length along the chords of the stride's samples (Curve2D::getLength)."""
        fk, lk = self.getFirstKnot(), self.getLastKnot()
        begin = fk if begin is None or begin < fk else begin
        end = lk if end is None or end > lk else end
        n = max(1, int(self.getStride()))
        du = (lk - fk) / n
        bi = int((begin - fk) / du) * du + fk
        ei = int((end - fk) / du) * du + fk
        p1 = self.getPointAt(bi)
        length = 0.0
        if begin - bi > _EPS:
            length -= norm(self.getPointAt(begin) - p1)
        k = 1
        while True:
            u = bi + k * du
            if u > ei + 1e-12:
                break
            p2 = self.getPointAt(min(u, lk))
            length += norm(p2 - p1)
            p1 = p2
            k += 1
        if end - ei > _EPS:
            length += norm(self.getPointAt(end) - p1)
        return length

    def getArcLengthToUMapping(self):
        """Normalised arc length (0..1) -> u (Curve2D::getArcLengthToUMapping)."""
        total = self.getLength()
        fk, lk = self.getFirstKnot(), self.getLastKnot()
        n = max(1, int(self.getStride()))
        du = (lk - fk) / n
        p1 = self.getPointAt(fk)
        pts = [Vector2(0, fk)]
        length = 0.0
        for i in range(1, n + 1):
            u = fk + i * du
            p2 = self.getPointAt(min(u, lk))
            d = norm(p2 - p1)
            if d > 0:
                length += d
                p1 = p2
                pts.append(Vector2(length / total if total > 0 else 1.0, u))
        pts[-1] = Vector2(1.0, lk)
        return QuantisedFunction(Point2Array(pts), 5 * n)

    def getUToArcLengthMapping(self):
        total = self.getLength()
        fk, lk = self.getFirstKnot(), self.getLastKnot()
        n = max(1, int(self.getStride()))
        du = (lk - fk) / n
        p1 = self.getPointAt(fk)
        pts = [Vector2(fk, 0)]
        length = 0.0
        for i in range(1, n + 1):
            u = fk + i * du
            p2 = self.getPointAt(min(u, lk))
            length += norm(p2 - p1)
            p1 = p2
            pts.append(Vector2(u, length / total if total > 0 else 1.0))
        return QuantisedFunction(Point2Array(pts), 5 * n)

    def _vd_points(self, n=None):
        """n + 1 points at equal steps of u (the stride by default), as tuples."""
        n = max(1, int(n if n else self.getStride()))
        fk, lk = self.getFirstKnot(), self.getLastKnot()
        return [tuple(self.getPointAt(min(lk, fk + (lk - fk) * i / n))) for i in range(n + 1)]


def _find_span(knots, deg, n, u):
    """Knot span index of u for n control points (The NURBS Book, A2.1)."""
    if u >= knots[n]:
        return n - 1
    if u <= knots[deg]:
        return deg
    lo, hi = deg, n
    mid = (lo + hi) // 2
    while u < knots[mid] or u >= knots[mid + 1]:
        if u < knots[mid]:
            hi = mid
        else:
            lo = mid
        mid = (lo + hi) // 2
    return mid


def _basis(knots, deg, span, u):
    """Non-zero B-spline basis functions at u (The NURBS Book, A2.2)."""
    N = [1.0] + [0.0] * deg
    left = [0.0] * (deg + 1)
    right = [0.0] * (deg + 1)
    for j in range(1, deg + 1):
        left[j] = u - knots[span + 1 - j]
        right[j] = knots[span + j] - u
        saved = 0.0
        for r in range(j):
            den = right[r + 1] + left[j - r]
            temp = N[r] / den if den != 0 else 0.0
            N[r] = saved + right[r + 1] * temp
            saved = left[j - r] * temp
        N[j] = saved
    return N


def _default_knots(n, deg):
    size = n + deg + 1
    k = [0.0] * (deg + 1)
    for j in range(deg + 1, size - deg - 1):
        k.append((j - deg) / (size - 2 * deg - 1))
    return k + [1.0] * (deg + 1)


class _Nurbs(_Curve):
    _hdim = 3  # homogeneous control point size

    def __init__(self, ctrlPointList=None, knotList=None, degree=None, stride=30, width=1, **kw):
        if ctrlPointList is None:
            ctrlPointList = kw.pop("ctrlPoints", [])
        pts = [p if isinstance(p, _Vec) else _vec(p) for p in ctrlPointList]
        if pts and len(pts[0]) == self._hdim - 1:  # points without weights
            pts = [_vec(tuple(p) + (1.0,)) for p in pts]
        self.ctrlPointList = (Point3Array if self._hdim == 3 else Point4Array)(pts)
        n = len(self.ctrlPointList)
        if n < 2:
            raise ValueError("a NURBS curve needs at least 2 control points")
        if degree is None:
            degree = min(3, n - 1) if knotList is None else len(knotList) - n - 1
        self.degree = int(degree)
        self.knotList = RealArray(knotList) if knotList is not None else RealArray(_default_knots(n, self.degree))
        if len(self.knotList) != n + self.degree + 1:
            raise ValueError("a NURBS curve of %d points and degree %d needs %d knots" %
                             (n, self.degree, n + self.degree + 1))
        self.stride = int(stride)
        self.width = width
        self.name = kw.get("name", "")

    def getFirstKnot(self):
        return self.knotList[self.degree]

    def getLastKnot(self):
        return self.knotList[len(self.ctrlPointList)]

    def setKnotListToDefault(self):
        self.knotList = RealArray(_default_knots(len(self.ctrlPointList), self.degree))

    def getPointAt(self, u):
        k, d, n = self.knotList, self.degree, len(self.ctrlPointList)
        u = min(max(u, k[d]), k[n])
        span = _find_span(k, d, n, u)
        N = _basis(k, d, span, u)
        h = self._hdim
        C = [0.0] * h
        for j in range(d + 1):
            P = self.ctrlPointList[span - d + j]._c
            w = P[h - 1]
            for c in range(h - 1):
                C[c] += P[c] * w * N[j]
            C[h - 1] += w * N[j]
        w = C[h - 1]
        if abs(w) < 1e-10:
            return self._P(*C[: h - 1])
        return self._P(*(c / w for c in C[: h - 1]))


class NurbsCurve2D(_Nurbs):
    _dim, _hdim = 2, 3


class NurbsCurve(_Nurbs):
    _dim, _hdim = 3, 4


class _Bezier(_Curve):
    _hdim = 3

    def __init__(self, ctrlPointList=None, stride=30, width=1, **kw):
        if ctrlPointList is None:
            ctrlPointList = kw.pop("ctrlPoints", [])
        pts = [p if isinstance(p, _Vec) else _vec(p) for p in ctrlPointList]
        if pts and len(pts[0]) == self._hdim - 1:
            pts = [_vec(tuple(p) + (1.0,)) for p in pts]
        self.ctrlPointList = (Point3Array if self._hdim == 3 else Point4Array)(pts)
        self.stride = int(stride)
        self.width = width
        self.degree = len(self.ctrlPointList) - 1
        self.name = kw.get("name", "")

    def getPointAt(self, u):
        """de Casteljau on the homogeneous points (BezierCurve2D::getPointAt)."""
        Q = [list(p._c) for p in self.ctrlPointList]
        u = min(max(u, 0.0), 1.0)
        for k in range(1, len(Q)):
            for i in range(len(Q) - k):
                Q[i] = [a * (1 - u) + b * u for a, b in zip(Q[i], Q[i + 1])]
        h = self._hdim
        w = Q[0][h - 1]
        if abs(w) < 1e-10:
            return self._P(*Q[0][: h - 1])
        return self._P(*(c / w for c in Q[0][: h - 1]))


class BezierCurve2D(_Bezier):
    _dim, _hdim = 2, 3


class BezierCurve(_Bezier):
    _dim, _hdim = 3, 4


class _Polyline(_Curve):
    def __init__(self, pointList=None, width=1, **kw):
        if pointList is None:
            pointList = kw.pop("points", [])
        self.pointList = (Point2Array if self._dim == 2 else Point3Array)(pointList)
        self.width = width
        self.name = kw.get("name", "")

    def getFirstKnot(self):
        return 0.0

    def getLastKnot(self):
        return float(len(self.pointList) - 1)

    def getStride(self):
        return len(self.pointList) - 1

    def getPointAt(self, u):
        n = len(self.pointList)
        u = min(max(u, 0.0), n - 1.0)
        i = int(u)
        if i == u or i >= n - 1:
            return self._P(*self.pointList[min(i, n - 1)])
        return self.pointList[i] * (i + 1 - u) + self.pointList[i + 1] * (u - i)

    def getTangentAt(self, u):
        p, n = self.pointList, len(self.pointList)
        i = int(u)
        if u <= 0:
            return p[1] - p[0]
        if u >= n - 1:
            return p[n - 1] - p[n - 2]
        if i == u:
            return ((p[i] - p[i - 1]).normed() + (p[i + 1] - p[i]).normed()) / 2
        return p[i + 1] - p[i]

    def __len__(self):
        return len(self.pointList)

    def __getitem__(self, i):
        return self.pointList[i]


class Polyline2D(_Polyline):
    _dim = 2

    @staticmethod
    def Circle(radius=0.5, slices=8):
        return Polyline2D([Vector2(radius * _math.cos(2 * _math.pi * i / slices),
                                   radius * _math.sin(2 * _math.pi * i / slices)) for i in range(slices + 1)])

    @staticmethod
    def ArcOfCircle(radius=0.5, starting_angle=0, angle_range=_math.pi, slices=8):
        return Polyline2D([Vector2(radius * _math.cos(starting_angle + angle_range * i / slices),
                                   radius * _math.sin(starting_angle + angle_range * i / slices))
                           for i in range(slices + 1)])

    @staticmethod
    def SuperEllipsis(a=0.5, b=0.5, n=2.5, m=None, slices=16):
        m = n if m is None else m
        pts = []
        for i in range(slices + 1):
            t = 2 * _math.pi * i / slices
            c, s = _math.cos(t), _math.sin(t)
            pts.append(Vector2(a * _math.copysign(abs(c) ** (2 / n), c), b * _math.copysign(abs(s) ** (2 / m), s)))
        return Polyline2D(pts)


class Polyline(_Polyline):
    _dim = 3


Curve2D = _Curve


# ---------------------------------------------------------------------------------------------
# functions (scenegraph/function/function.cpp)


class QuantisedFunction:
    """y(x) of a curve that is a graph (x increasing), sampled at `sampling` points."""

    def __init__(self, curve=None, sampling=100, clamped=True, firstx=None, lastx=None):
        self.sampling = int(sampling)
        self.clamped = clamped
        if isinstance(curve, (list, tuple)) and not isinstance(curve, _Curve) and curve and \
                isinstance(curve[0], (int, float)):
            self.values = [float(v) for v in curve]
            self.sampling = len(self.values)
            self.firstx, self.lastx = (0.0 if firstx is None else firstx), (1.0 if lastx is None else lastx)
            return
        if isinstance(curve, (list, tuple)):
            curve = Polyline2D(curve)
        if curve is None:
            self.values, self.firstx, self.lastx = [0.0, 0.0], 0.0, 1.0
            return
        if self.sampling < 3:
            self.sampling = 3
        fk, lk = curve.getFirstKnot(), curve.getLastKnot()
        self.firstx = curve.getPointAt(fk).x
        self.lastx = curve.getPointAt(lk).x
        ext = self.lastx - self.firstx
        self.values = [self._value(curve, ext * i / (self.sampling - 1) + self.firstx) for i in range(self.sampling)]

    @staticmethod
    def _value(curve, x, maxerror=1e-5):
        fk, lk = curve.getFirstKnot(), curve.getLastKnot()
        p0, p1 = curve.getPointAt(fk), curve.getPointAt(lk)
        if x == p0.x:
            return p0.y
        if x == p1.x:
            return p1.y
        lo, hi = fk, lk
        for _ in range(200):
            mid = (lo + hi) / 2
            t = curve.getPointAt(mid)
            if t.x > x:
                hi = mid
            else:
                lo = mid
            if abs(t.x - x) <= maxerror:
                break
        return t.y

    def getValue(self, x):
        if not self.clamped or True:
            x = min(max(x, self.firstx), self.lastx)
        span = self.lastx - self.firstx
        idx = (self.sampling - 1) * (x - self.firstx) / span if span else 0.0
        i = int(_math.floor(idx))
        d = idx - i
        if i >= self.sampling - 1 or abs(d) < 1e-12:
            return self.values[min(i, self.sampling - 1)]
        return (1 - d) * self.values[i] + d * self.values[i + 1]

    __call__ = getValue

    def getX(self, i):
        return self.firstx + i * (self.lastx - self.firstx) / (self.sampling - 1)

    def findX(self, y, startingX=None):
        x0 = self.firstx if startingX is None else startingX
        i0 = int((self.sampling - 1) * (x0 - self.firstx) / (self.lastx - self.firstx)) + 1
        for i in range(max(1, i0), self.sampling):
            a, b = self.values[i - 1], self.values[i]
            if a <= y < b or a >= y > b:
                return self.getX(i - 1 + (y - a) / (b - a))
        return None

    def isMonotonous(self, strictly=False):
        return self.isIncreasing(strictly) or self.isDecreasing(strictly)

    def isIncreasing(self, strictly=False):
        v = self.values
        return all(v[i - 1] < v[i] if strictly else v[i - 1] <= v[i] for i in range(1, len(v)))

    def isDecreasing(self, strictly=False):
        v = self.values
        return all(v[i - 1] > v[i] if strictly else v[i - 1] >= v[i] for i in range(1, len(v)))

    def inverse(self):
        if not self.isMonotonous(True):
            return None
        y0, y1 = self.values[0], self.values[-1]
        if y0 > y1:
            y0, y1 = y1, y0
        xs, x, dy = [], self.firstx, (y1 - y0) / (self.sampling - 1)
        for i in range(self.sampling):
            fx = self.findX(y0 + i * dy, x) if i else self.firstx
            x = fx if fx is not None else x
            xs.append(x)
        return QuantisedFunction(xs, firstx=y0, lastx=y1)


# ---------------------------------------------------------------------------------------------
# cardinal splines (openalea.plantgl.scenegraph.cspline)


class CSpline:
    """A cardinal spline through points (PlantGL's scenegraph.cspline.CSpline): a C1 curve of
    cubic Bezier arcs, one per pair of neighbours; at each inner point the derivative is half the
    chord of its neighbours ((P[i+1] - P[i-1]) / 2), at the ends half the end chord (closed: the
    chord across the joint); the arcs' inner control points lie a third of the derivatives away.
    curve() gives it as a NurbsCurve2D / NurbsCurve of degree 3 whose knots are the cumulated
    chord lengths (is_linear: 0, 1, 2, ...), stride_factor samples per arc."""

    def __init__(self, points, is_closed=False):
        pts = [_vec(p) for p in points]
        if len(pts) < 2:
            raise ValueError("CSpline: at least 2 points, got %d" % len(pts))
        self.dim = len(pts[0])
        if self.dim not in (2, 3):
            raise ValueError("CSpline: points of 2 or 3 coordinates, got %d" % self.dim)
        self.is_closed = bool(is_closed)
        if self.is_closed and norm(pts[-1] - pts[0]) > 0.001:
            pts.append(pts[0])
        self.points = (Point2Array if self.dim == 2 else Point3Array)(pts)
        self.nurbs = None

    def __len__(self):
        return len(self.points)

    def distances(self):
        self.dist = [norm(self.points[i + 1] - self.points[i]) for i in range(len(self.points) - 1)]
        return self.dist

    def derivatives(self):
        p = self.points
        if self.is_closed:
            # as PlantGL's: the last point is the first again here, so this is (P[1] - P[0]) / 2
            d0 = dn = (p[1] - p[-1]) / 2
        else:
            d0, dn = (p[1] - p[0]) / 2, (p[-1] - p[-2]) / 2
        self.der = [d0] + [(p[i + 1] - p[i - 1]) / 2 for i in range(1, len(p) - 1)] + [dn]
        return self.der

    def bezier_cp(self):
        p, d = self.points, self.der
        cp = []
        for i in range(len(p) - 1):
            cp += [p[i], p[i] + d[i] / 3, p[i + 1] - d[i + 1] / 3]
        cp.append(p[-1])
        if self.is_closed:
            # PlantGL's closing: the control points beside the joint are moved onto its tangent line
            cp[1], cp[-2] = cp[2], cp[-3]
        self.ctrl_pts = cp
        return cp

    def bezier_kv(self, is_linear=False):
        if is_linear:
            params = [float(i) for i in range(len(self.points))]
        else:
            params = [0.0]
            for dd in self.dist:
                params.append(params[-1] + dd)
        self.kv = [params[0]] + [u for u in params for _ in range(3)] + [params[-1]]
        return self.kv

    def curve(self, is_linear=False, degree=3, stride_factor=10, distances=None):
        if int(degree) != 3:
            raise NotInVerdant("CSpline.curve(degree=%d): PlantGL's cardinal splines are cubic" % int(degree))
        if self.nurbs is None:
            self.dist = list(distances) if distances is not None else self.distances()
            self.derivatives()
            self.bezier_cp()
            self.bezier_kv(is_linear)
            stride = (len(self.points) - 1) * int(stride_factor)
            hom = [tuple(p) + (1.0,) for p in self.ctrl_pts]
            cls = NurbsCurve2D if self.dim == 2 else NurbsCurve
            self.nurbs = cls(hom, RealArray(self.kv), 3, stride)
        return self.nurbs


def cspline(pts, is_closed=False, is_linear=False, distances=None, degree=3):
    """The NurbsCurve of the cardinal spline through pts (PlantGL's cspline)."""
    return CSpline(pts, is_closed).curve(is_linear, degree=degree, distances=distances)


NurbsCurve.CSpline = staticmethod(cspline)
