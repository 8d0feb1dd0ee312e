# SPDX-License-Identifier: MIT
"""PlantGL's parametric surfaces and volumes (NurbsPatch, BezierPatch, NurbsPatch3D) and swept
surfaces (Revolution, Swung, Extrusion)."""
import math as _math

from .errors import NotInVerdant
from .pgl_curves import NurbsCurve, Polyline2D, _basis, _Curve, _default_knots, _find_span
from .pgl_geometry import _Geometry
from .pgl_math import Point4Matrix, RealArray, Vector2, Vector3, Vector4, _vec, norm, normSquared

class NurbsPatch(_Geometry):
    """A NURBS surface: a matrix of (x, y, z, w) control points, PlantGL's default knots."""

    def __init__(self, ctrlPointMatrix=None, uKnotList=None, vKnotList=None, udegree=3, vdegree=3, ustride=30,
                 vstride=30, ccw=True, **kw):
        if ctrlPointMatrix is None:
            ctrlPointMatrix = kw.pop("ctrlPointList")
        rows = [[p if isinstance(p, Vector4) else Vector4(*(tuple(p) + (1.0,) * (4 - len(p)))) for p in r]
                for r in ctrlPointMatrix]
        self.ctrlPointMatrix = Point4Matrix(rows)
        nu, nv = len(rows), len(rows[0])
        self.udegree, self.vdegree = min(int(udegree), nu - 1), min(int(vdegree), nv - 1)
        self.uKnotList = RealArray(uKnotList) if uKnotList is not None else RealArray(_default_knots(nu, self.udegree))
        self.vKnotList = RealArray(vKnotList) if vKnotList is not None else RealArray(_default_knots(nv, self.vdegree))
        self.ustride, self.vstride, self.ccw = int(ustride), int(vstride), ccw
        self.name = kw.get("name", "")

    ctrlPointList = property(lambda self: self.ctrlPointMatrix)

    def getPointAt(self, u, v):
        nu, nv = len(self.ctrlPointMatrix), len(self.ctrlPointMatrix[0])
        ku, kv, du, dv = self.uKnotList, self.vKnotList, self.udegree, self.vdegree
        u = min(max(u, ku[du]), ku[nu])
        v = min(max(v, kv[dv]), kv[nv])
        su, sv = _find_span(ku, du, nu, u), _find_span(kv, dv, nv, v)
        Nu, Nv = _basis(ku, du, su, u), _basis(kv, dv, sv, v)
        C = [0.0] * 4
        for i in range(du + 1):
            for j in range(dv + 1):
                P = self.ctrlPointMatrix[su - du + i][sv - dv + j]._c
                b = Nu[i] * Nv[j] * P[3]
                C[0] += P[0] * b
                C[1] += P[1] * b
                C[2] += P[2] * b
                C[3] += b
        w = C[3] if abs(C[3]) > 1e-10 else 1.0
        return Vector3(C[0] / w, C[1] / w, C[2] / w)

    def getUTangentAt(self, u, v):
        h = 1e-6
        return (self.getPointAt(min(1, u + h), v) - self.getPointAt(max(0, u - h), v)) / (min(1, u + h) - max(0, u - h))

    def getVTangentAt(self, u, v):
        h = 1e-6
        return (self.getPointAt(u, min(1, v + h)) - self.getPointAt(u, max(0, v - h))) / (min(1, v + h) - max(0, v - h))

    def getNormalAt(self, u, v):
        return (self.getUTangentAt(u, v) ^ self.getVTangentAt(u, v)).normed()

    def getIsoUSectionAt(self, u):
        n = len(self.ctrlPointMatrix[0])
        return NurbsCurve([tuple(self.getPointAt(u, j / (n - 1))) + (1.0,) for j in range(n)])

    def getIsoVSectionAt(self, v):
        n = len(self.ctrlPointMatrix)
        return NurbsCurve([tuple(self.getPointAt(i / (n - 1), v)) + (1.0,) for i in range(n)])

    def _mesh(self):
        nu, nv = max(1, self.ustride), max(1, self.vstride)
        ku, kv = self.uKnotList, self.vKnotList
        u0, u1 = ku[self.udegree], ku[len(self.ctrlPointMatrix)]
        v0, v1 = kv[self.vdegree], kv[len(self.ctrlPointMatrix[0])]
        pts = [tuple(self.getPointAt(u0 + (u1 - u0) * i / nu, v0 + (v1 - v0) * j / nv))
               for i in range(nu + 1) for j in range(nv + 1)]
        t = []
        for i in range(nu):
            for j in range(nv):
                a, b, c, d = i * (nv + 1) + j, (i + 1) * (nv + 1) + j, (i + 1) * (nv + 1) + j + 1, i * (nv + 1) + j + 1
                t += [(a, b, c), (a, c, d)] if self.ccw else [(a, c, b), (a, d, c)]
        return pts, t, False


class BezierPatch(NurbsPatch):
    def __init__(self, ctrlPointMatrix=None, ustride=30, vstride=30, ccw=True, **kw):
        m = ctrlPointMatrix if ctrlPointMatrix is not None else kw.pop("ctrlPointList")
        NurbsPatch.__init__(self, m, None, None, len(m) - 1, len(m[0]) - 1, ustride, vstride, ccw, **kw)


class NurbsPatch3D:
    """A NURBS volume (openalea.plantgl.scenegraph.nurbspatch_nd): a 3D array of (x, y, z, w)
    control points, PlantGL's default knots; getPointAt(u, v, w) maps the unit cube into space."""

    def __init__(self, points, udegree=3, vdegree=3, wdegree=3, uknotList=None, vknotList=None, wknotList=None,
                 ustride=30, vstride=30, wstride=30):
        self.ctrlPointMatrix = [[[p if isinstance(p, Vector4) else Vector4(*(tuple(p) + (1.0,) * (4 - len(p))))
                                  for p in row] for row in plane] for plane in points]
        dims = (len(points), len(points[0]), len(points[0][0]))
        self.udegree, self.vdegree, self.wdegree = (min(int(d), n - 1) for d, n in
                                                    zip((udegree, vdegree, wdegree), dims))
        degs = (self.udegree, self.vdegree, self.wdegree)
        self._knots = [RealArray(k) if k is not None else RealArray(_default_knots(n, d))
                       for k, n, d in zip((uknotList, vknotList, wknotList), dims, degs)]
        self.uknotList, self.vknotList, self.wknotList = self._knots
        self.ustride, self.vstride, self.wstride = int(ustride), int(vstride), int(wstride)
        self.name = ""

    def isValid(self):
        return True

    def getPointAt(self, u, v, w):
        P = self.ctrlPointMatrix
        dims = (len(P), len(P[0]), len(P[0][0]))
        degs = (self.udegree, self.vdegree, self.wdegree)
        spans, bases = [], []
        for x, k, d, n in zip((u, v, w), self._knots, degs, dims):
            x = min(max(x, k[d]), k[n])
            sp = _find_span(k, d, n, x)
            spans.append(sp)
            bases.append(_basis(k, d, sp, x))
        C = [0.0] * 4
        for i in range(degs[0] + 1):
            for j in range(degs[1] + 1):
                for l in range(degs[2] + 1):
                    c = P[spans[0] - degs[0] + i][spans[1] - degs[1] + j][spans[2] - degs[2] + l]._c
                    b = bases[0][i] * bases[1][j] * bases[2][l] * c[3]
                    C[0] += c[0] * b
                    C[1] += c[1] * b
                    C[2] += c[2] * b
                    C[3] += b
        wt = C[3] if abs(C[3]) > 1e-10 else 1.0
        return Vector3(C[0] / wt, C[1] / wt, C[2] / wt)


# ---------------------------------------------------------------------------------------------
# swept surfaces (scenegraph/geometry: revolution, swung, extrusion; algo/base/discretizer.cpp):
# a profile's discretisation (a curve's stride + 1 points at equal steps of u, a polyline's own
# points) turned around the z axis or carried along an axis


def _profile_points(curve, what):
    """The discretisation of a 2D curve, as (x, y) tuples."""
    if not isinstance(curve, _Curve) or curve._dim != 2:
        raise TypeError("%s: the profile must be a 2D curve (NurbsCurve2D, BezierCurve2D, Polyline2D, ...), got %s"
                        % (what, type(curve).__name__))
    return [(float(p[0]), float(p[1])) for p in curve._vd_points(0)]


def _lathe(sections, angles, ccw=True):
    """The mesh of sections (lists of (radius, height)) at angles around z, each ring joined to
    the next and the last to the first (PlantGL's discretizer): (vertices, triangles)."""
    m, n = len(sections[0]), len(sections)
    v = [(r * _math.cos(a), r * _math.sin(a), z) for sec, a in zip(sections, angles) for r, z in sec]
    t = []
    for k in range(n):
        cur, nxt = k * m, ((k + 1) % n) * m
        for j in range(1, m):
            f = [(cur + j, cur + j - 1, nxt + j - 1), (cur + j, nxt + j - 1, nxt + j)]
            t += f if ccw else [(a, c, b) for a, b, c in f]
    return v, t


class Revolution(_Geometry):
    """A surface of revolution: the profile, a 2D curve of (radius, height) points, turned around
    the z axis at `slices` angles 2 pi k / slices. A volume when both ends of the profile lie on
    the axis."""

    def __init__(self, profile=None, slices=8, **kw):
        self.profile = profile if profile is not None else kw.pop("profile")
        self.slices = int(slices)
        if self.slices < 3:
            raise ValueError("Revolution: slices must be at least 3, got %d" % self.slices)
        _profile_points(self.profile, "Revolution")  # checked here, where the model builds it
        self.name = kw.get("name", "")

    def isAVolume(self):
        pts = _profile_points(self.profile, "Revolution")
        return abs(pts[0][0]) < 1e-6 and abs(pts[-1][0]) < 1e-6

    def _mesh(self):
        pts = _profile_points(self.profile, "Revolution")
        n = self.slices
        v, t = _lathe([pts] * n, [2 * _math.pi * k / n for k in range(n)])
        return v, t, self.isAVolume()


def _local_cubic(points, knots):
    """The piecewise cubic Bezier curve through points (tuples) at the parameters knots, with
    the tangents of The NURBS Book's local interpolation (eqs. 9.28-9.31, closed: the end
    tangents averaged) and each arc's inner points at the distance that gives it equal speed at
    both ends (section 9.3.4, eq. 9.47). Returns the arcs' control points [(P0, P1, P2, P3)]."""
    n, d = len(points) - 1, len(points[0])
    sub = lambda a, b: tuple(x - y for x, y in zip(a, b))  # noqa: E731
    mul = lambda a, s: tuple(x * s for x in a)  # noqa: E731
    add = lambda a, b: tuple(x + y for x, y in zip(a, b))  # noqa: E731
    dot = lambda a, b: sum(x * y for x, y in zip(a, b))  # noqa: E731

    def blend(p, q, r, du, dv):
        a = du / (du + dv)
        return add(mul(sub(q, p), (1 - a) / du), mul(sub(r, q), a / dv))

    T = [None] * (n + 1)
    for k in range(1, n):
        T[k] = blend(points[k - 1], points[k], points[k + 1], knots[k] - knots[k - 1], knots[k + 1] - knots[k])
    # closed (as PlantGL's profile interpolation asks): both ends get the tangent across them
    T[0] = T[n] = blend(points[n - 1], points[n], add(points[n], sub(points[1], points[0])),
                        knots[n] - knots[n - 1], knots[1] - knots[0])
    arcs = []
    for k in range(n):
        p0, p3 = points[k], points[k + 1]
        chord = sub(p3, p0)
        if dot(chord, chord) < 1e-12:
            arcs.append((p0, add(p0, mul(chord, 1 / 3)), sub(p3, mul(chord, 1 / 3)), p3))
            continue
        n0, n3 = _math.sqrt(dot(T[k], T[k])), _math.sqrt(dot(T[k + 1], T[k + 1]))
        if max(n0, n3) < 1e-6:
            arcs.append((p0, p0, p3, p3))
            continue
        u = mul(T[k], 1 / n0) if n0 >= 1e-6 else (0.0,) * d
        w = mul(T[k + 1], 1 / n3) if n3 >= 1e-6 else (0.0,) * d
        s = add(u, w)
        a, b, c = 16 - dot(s, s), 12 * dot(chord, s), -36 * dot(chord, chord)
        alpha = (-b + _math.sqrt(b * b - 4 * a * c)) / (2 * a) / 3  # the positive root (a > 0 > c)
        arcs.append((p0, add(p0, mul(u, alpha)), sub(p3, mul(w, alpha)), p3))
    return arcs


def _bezier3(arc, t):
    s = 1 - t
    return tuple(s * s * s * a + 3 * s * s * t * b + 3 * s * t * t * c + t * t * t * e for a, b, c, e in zip(*arc))


class Swung(_Geometry):
    """A surface swept around the z axis through profiles given at angles (PlantGL's Swung): each
    of the stride + 1 samples of the profiles (a Polyline2D: its points; the stride is the
    largest of the profiles' when not given) is interpolated across the angles, linearly for
    degree 1 or by local cubic interpolation for degree 3; `slices` sections cover the angles'
    range (2 pi for one profile), the last joined to the first."""

    def __init__(self, profileList=None, angleList=None, slices=8, ccw=True, degree=3, stride=0, **kw):
        self.profileList = list(profileList if profileList is not None else kw.pop("profileList"))
        self.angleList = [float(a) for a in (angleList if angleList is not None else kw.pop("angleList"))]
        if not self.profileList or len(self.profileList) != len(self.angleList):
            raise ValueError("Swung: one angle per profile (%d profiles, %d angles)"
                             % (len(self.profileList), len(self.angleList)))
        if any(b <= a for a, b in zip(self.angleList, self.angleList[1:])):
            raise ValueError("Swung: the angles must increase")
        if int(degree) not in (1, 3):
            raise NotInVerdant("Swung(degree=%d): verdant interpolates the profiles linearly (1) or cubically (3)"
                               % int(degree))
        for p in self.profileList:
            _profile_points(p, "Swung")
        self.slices, self.ccw, self.degree, self.stride = int(slices), bool(ccw), int(degree), int(stride)
        self.name = kw.get("name", "")

    def _samples(self):
        stride = self.stride
        if stride <= 2:
            stride = max(2, max(int(p.getStride()) for p in self.profileList))
        out = []
        for p in self.profileList:
            if isinstance(p, Polyline2D) and int(p.getStride()) == stride:
                out.append([(float(q[0]), float(q[1])) for q in p.pointList])
            else:
                fk, lk = p.getFirstKnot(), p.getLastKnot()
                out.append([tuple(float(c) for c in p.getPointAt(fk + (lk - fk) * i / stride)) for i in range(stride + 1)])
        return out

    def _section(self, samples, arcs, a):
        """The profile at angle a: each sample interpolated across the angles."""
        ang = self.angleList
        if len(ang) == 1:
            return samples[0]
        a = min(max(a, ang[0]), ang[-1])
        k = max(0, min(len(ang) - 2, next((i for i in range(len(ang) - 1) if a < ang[i + 1]), len(ang) - 2)))
        t = (a - ang[k]) / (ang[k + 1] - ang[k])
        if self.degree == 1:
            return [tuple(x * (1 - t) + y * t for x, y in zip(samples[k][j], samples[k + 1][j]))
                    for j in range(len(samples[0]))]
        return [_bezier3(arcs[j][k], t) for j in range(len(samples[0]))]

    def _mesh(self):
        samples = self._samples()
        ang = self.angleList
        arcs = None
        if self.degree == 3 and len(ang) > 1:
            arcs = [_local_cubic([s[j] for s in samples], ang) for j in range(len(samples[0]))]
        lo, rng = (ang[0], ang[-1] - ang[0]) if len(ang) > 1 else (ang[0], 2 * _math.pi)
        angles = [lo + rng * i / self.slices for i in range(self.slices)]
        secs = [self._section(samples, arcs, a) for a in angles]
        v, t = _lathe(secs, angles, self.ccw)
        # a volume when every section starts and ends at the same points (on the axis)
        m = len(secs[0])
        closed = all(_math.dist(v[i * m], v[0]) <= 0.01 and _math.dist(v[i * m + m - 1], v[m - 1]) <= 0.01
                     for i in range(len(secs)))
        return v, t, closed


def _initial_normal(axis, given):
    """Extrusion's first normal: the one given, else the axis's normal at its start, else one
    across its tangent (PlantGL's getInitialNormalValue)."""
    n = _vec(given) if given is not None else Vector3(0, 0, 0)
    if normSquared(n) > 1e-6:
        return n
    fk = axis.getFirstKnot()
    n = axis.getNormalAt(fk)
    if normSquared(n) >= 1e-6:
        return n
    tg = axis.getTangentAt(fk)
    if tg.x < tg.y:
        u = Vector3(0, 0, 1) if tg.z < tg.x else Vector3(1, 0, 0)
    else:
        u = Vector3(0, 0, 1) if tg.z < tg.y else Vector3(0, 1, 0)
    return tg ^ u


def _lerp_list(values, knots, u):
    """Piecewise-linear value of a list given at knots (PlantGL's ProfileTransformation)."""
    if len(values) == 1 or u <= knots[0]:
        return values[0]
    if u >= knots[-1]:
        return values[len(knots) - 1]
    i = next(i for i in range(1, len(knots)) if knots[i] >= u)
    t = (knots[i] - u) / (knots[i] - knots[i - 1])
    a, b = values[i - 1], values[i]
    return a * t + b * (1 - t)


class Extrusion(_Geometry):
    """A cross-section (a 2D curve) carried along an axis (a 3D curve), PlantGL's Extrusion: at the
    axis's stride + 1 steps of u the section's points (x, y) go to x N + y B around the axis
    point, the frame (N, B, tangent) carried from the initial normal by PlantGL's rule (N = B x T
    of the previous B); `scale` ((sx, sy) per knot) and `orientation` (radians per knot) change
    the section along the way, linearly between their knots (uniform over [0, 1] by default). A
    closed section (first point = last) gives a tube; `solid` caps its ends."""

    def __init__(self, axis=None, crossSection=None, scale=None, orientation=None, knotList=None, solid=False,
                 ccw=True, initialNormal=None, **kw):
        self.axis = axis if axis is not None else kw.pop("axis")
        self.crossSection = crossSection if crossSection is not None else kw.pop("crossSection")
        if not isinstance(self.axis, _Curve):
            raise TypeError("Extrusion: the axis must be a curve, got %s" % type(self.axis).__name__)
        _profile_points(self.crossSection, "Extrusion")
        self.scale = [Vector2(*s) if not isinstance(s, (int, float)) else Vector2(s, s) for s in (scale or [])]
        self.orientation = [float(a) for a in (orientation or [])]
        self.knotList = [float(k) for k in knotList] if knotList is not None else None
        self.solid, self.ccw, self.initialNormal = bool(solid), bool(ccw), initialNormal
        self.name = kw.get("name", "")

    def _knots(self):
        if self.knotList is not None:
            return self.knotList
        n = max(len(self.scale), len(self.orientation), 2)
        return [i / (n - 1) for i in range(n)]

    def _transform(self, p, u):
        x, y = p
        if self.scale:
            s = _lerp_list(self.scale, self._knots(), u)
            x, y = x * s.x, y * s.y
        if self.orientation:
            a = _lerp_list(self.orientation, self._knots(), u)
            x, y = x * _math.cos(a) - y * _math.sin(a), x * _math.sin(a) + y * _math.cos(a)
        return x, y

    def _dim3(self, p):
        return Vector3(*p) if len(p) == 3 else Vector3(p[0], p[1], 0)

    def _mesh(self):
        sec = _profile_points(self.crossSection, "Extrusion")
        closed = len(sec) > 2 and _math.dist(sec[0], sec[-1]) <= 1e-10
        if closed:
            sec = sec[:-1]
        ax = self.axis
        fk, lk, size = ax.getFirstKnot(), ax.getLastKnot(), max(1, int(ax.getStride()))
        step = (lk - fk) / size
        knots = self._knots()
        t0, tstep = knots[0], (knots[-1] - knots[0]) / size

        def tangent(u):
            return self._dim3(ax.getTangentAt(u)).normed()

        def next_frame(frame, u):
            vel = tangent(u)
            nrm = frame[1] ^ vel
            if norm(nrm) == 0:
                nrm = vel.anOrthogonalVector()
            nrm = nrm.normed()
            return nrm, (vel ^ nrm).normed(), vel

        vel = tangent(fk)
        nrm = self._dim3(_initial_normal(ax, self.initialNormal)).normed()
        frame = (nrm, (vel ^ nrm).normed(), vel)
        v = []
        for i in range(size + 1):
            u = fk + i * step if i < size else lk
            if i == size:
                frame = next_frame(frame, lk)
            c = self._dim3(ax.getPointAt(u))
            for p in sec:
                x, y = self._transform(p, t0 + i * tstep)
                v.append(tuple(c + frame[0] * x + frame[1] * y))
            if i < size - 1:
                frame = next_frame(frame, u + step)
        m, t = len(sec), []
        for i in range(size):
            for j in range(m if closed else m - 1):
                a, b = i * m + j, i * m + (j + 1) % m
                t += [(a, b, b + m), (a, b + m, a + m)]
        if self.solid and closed:
            last = size * m
            t += [(0, j + 1, j) for j in range(1, m - 1)] + [(last, last + j, last + j + 1) for j in range(1, m - 1)]
        # the sides face outward for a section that turns counter-clockwise; the caps agree
        if _vol_sign(v, t) < 0:
            t = [(a, c, b) for a, b, c in t]
        if not self.ccw:
            t = [(a, c, b) for a, b, c in t]
        return v, t, bool(self.solid and closed)


def _vol_sign(v, t):
    s = 0.0
    for a, b, c in t:
        (ax, ay, az), (bx, by, bz), (cx, cy, cz) = v[a], v[b], v[c]
        s += ax * (by * cz - bz * cy) - ay * (bx * cz - bz * cx) + az * (bx * cy - by * cx)
    return s
