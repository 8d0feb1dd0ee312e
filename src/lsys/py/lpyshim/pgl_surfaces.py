# SPDX-License-Identifier: MIT
"""PlantGL's parametric surfaces and volumes: NurbsPatch, BezierPatch, NurbsPatch3D."""
from .pgl_curves import NurbsCurve, _basis, _default_knots, _find_span
from .pgl_geometry import _Geometry
from .pgl_math import Point4Matrix, RealArray, Vector3, Vector4

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


