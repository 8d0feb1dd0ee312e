# SPDX-License-Identifier: MIT
# verdant's Python engine: the names an .lpy file sees (L-Py's openalea.lpy and a small
# openalea.plantgl), written for verdant. The C side (lsys_py.c) runs this module last of the
# package and calls the functions here; `_vd` is its C module (produce, groups, iteration, the
# log). No openalea name is placed in sys.modules: a file's `import openalea...` is answered from
# OPENALEA through the namespace's own __import__, so a host process with a real openalea keeps it.
import builtins as _builtins
import os as _os
import random as _random
import sys as _sys
import types as _types

from . import _vd
from .errors import NotInVerdant, NotProvided, _NoWindow, _display_only, missing_attr, unsupported
from .lpy import *  # noqa: F401,F403 - the L-Py names
from .lpy import _future_module, _tableparam_module, _vd_items, _vd_lstring, _vd_make_vec3, _vd_mk
from .lpy import _predefined_class, _vd_init_context, _vd_turtle_settings
from .pgl_algo import *  # noqa: F401,F403
from .pgl_appearance import *  # noqa: F401,F403
from .pgl_curves import *  # noqa: F401,F403
from .pgl_curves import QuantisedFunction, _Curve
from .pgl_geometry import *  # noqa: F401,F403
from .pgl_geometry import Cone, Cylinder, Frustum, Oriented, Scene, Shape, Sphere, Translated, TriangleSet, _mesh_of
from .pgl_math import *  # noqa: F401,F403
from .pgl_math import Vector2, Vector3, Vector4, norm
from .pgl_surfaces import *  # noqa: F401,F403

# ---------------------------------------------------------------------------------------------
# run support called from C

_run = {"seed": 0, "np_seeded": False}


def _np_random():
    np = _sys.modules.get("numpy")
    return getattr(np, "random", None) if np is not None else None


def _vd_seed(seed):
    """random.seed(seed) for a new derivation; numpy's generator too once numpy is loaded."""
    _run["seed"] = seed
    _run["np_seeded"] = False
    _random.seed(seed)
    npr = _np_random()
    if npr is not None:
        npr.seed(seed % (1 << 32))
        _run["np_seeded"] = True


def _vd_swap(state):
    """Put state (or nothing) into random (and numpy.random); return what was there."""
    npr = _np_random()
    old = (_random.getstate(), npr.get_state() if npr is not None else None)
    if state is not None:
        _random.setstate(state[0])
        if npr is not None and state[1] is not None:
            npr.set_state(state[1])
    return old


# ---------------------------------------------------------------------------------------------
# print goes to verdant's log (stderr in the CLI), not stdout: --stats writes JSON there


class _Log:
    def __init__(self):
        self.buf = ""

    def write(self, s):
        self.buf += s
        while "\n" in self.buf:
            line, self.buf = self.buf.split("\n", 1)
            _vd.log(line)
        return len(s)

    def flush(self):
        if self.buf:
            _vd.log(self.buf)
            self.buf = ""


_log = _Log()
_real_print = _builtins.print


def _vd_print(*args, **kw):
    if kw.get("file") is None:
        kw["file"] = _log
        _real_print(*args, **kw)
        _log.flush()
    else:
        _real_print(*args, **kw)


# ---------------------------------------------------------------------------------------------
# import: openalea.* from this shim, other modules as usual (and from the .lpy's folder)

_real_import = _builtins.__import__
_local_modules = {}


# modules made for each file, as they hold its state: the import's name -> the key that keeps
# the file's copy in its globals, the attribute of openalea.lpy, the factory (defined below)
_PER_FILE_MODULES = {
    "openalea.lpy.__lpyfuture__": ("__vd_future", "__lpyfuture__", lambda: _future_module()),
    "openalea.lpy.tableparameterset": ("__vd_tableps", "tableparameterset", lambda: _tableparam_module()),
}


def _vd_import(name, globals=None, locals=None, fromlist=(), level=0):
    per_file = _PER_FILE_MODULES.get(name) if level == 0 and globals is not None else None
    if per_file:
        key, attr, make = per_file
        mod = globals.get(key)
        if mod is None:
            mod = globals[key] = make()
        setattr(_lpy, attr, mod)
        return mod if fromlist else OPENALEA["openalea"]
    if level == 0 and (name == "openalea" or name.startswith("openalea.")):
        mod = OPENALEA.get(name)
        if mod is None:
            raise ModuleNotFoundError(
                "No module named '%s' (verdant provides openalea.plantgl and openalea.lpy only)" % name)
        return mod if fromlist else OPENALEA["openalea"]
    # the model's folder first, as on L-Py's sys.path; then the installed modules
    mod = _import_beside(name, globals, fromlist, level)
    if mod is None:
        try:
            mod = _real_import(name, globals, locals, fromlist, level)
        except ModuleNotFoundError:
            if level == 0 and name in ("pylab", "matplotlib", "matplotlib.pyplot"):
                mod = _plot_module(name, fromlist)
            if mod is None:
                raise
    if getattr(mod, "__name__", None) in ("importlib", "imp"):
        mod = _reload_proxy(mod)
    if not _run["np_seeded"] and name.split(".")[0] == "numpy":
        npr = _np_random()
        if npr is not None:
            npr.seed(_run["seed"] % (1 << 32))
            _run["np_seeded"] = True
    return mod


def _reload_proxy(mod):
    """importlib (or imp) whose reload() gives verdant's openalea modules back as they are (each
    run has fresh ones) and runs a module beside the .lpy file again: neither is in
    sys.modules, where the real reload looks."""
    p = _types.ModuleType(mod.__name__)
    p.__dict__.update(mod.__dict__)
    real = mod.reload

    def reload(m):
        if getattr(m, "__vd_local__", False):
            # a module beside the .lpy file: run again
            m.__spec__.loader.exec_module(m)
            return m
        return m if getattr(m, "__vd_shim__", False) else real(m)
    p.reload = reload
    return p


_PLOT_CALLS = ["plot", "show", "draw", "close", "figure", "clf", "cla", "subplot", "xlabel", "ylabel", "title",
               "legend", "grid", "axis", "xlim", "ylim", "ion", "ioff", "pause", "scatter", "bar", "hist", "text",
               "imshow", "colorbar", "gca", "gcf", "hold", "semilogx", "semilogy", "loglog", "fill", "fill_between",
               "axhline", "axvline", "tight_layout", "xticks", "yticks", "annotate", "errorbar", "contour",
               "contourf", "pcolor", "pcolormesh", "quiver", "boxplot", "pie", "step", "stem", "suptitle"]


class _NoPlot:
    """A figure or axes of the stand-in pyplot: drawing methods do nothing; queries (get_*) and
    files (savefig) raise, naming them."""

    def __init__(self, what):
        self._what = what

    def __getattr__(self, name):
        if name.startswith("__"):
            raise AttributeError(name)
        path = "matplotlib %s.%s" % (self._what, name)
        if name.startswith("get") or name == "savefig":
            raise NotInVerdant("%s (matplotlib is not installed: plots are not drawn)" % path)
        return _display_only(path)


def _plot_module(name, fromlist):
    """pylab / matplotlib.pyplot where matplotlib is not installed: plotting draws nothing (as
    PlantGL's Viewer here: a command-line run has no window), pylab's numpy names are numpy's;
    savefig, whose file a user would expect, is refused."""
    m = _types.ModuleType("matplotlib.pyplot" if name != "pylab" else "pylab")
    if name == "pylab":
        try:
            import numpy
            m.__dict__.update({k: v for k, v in numpy.__dict__.items() if not k.startswith("_")})
        except ImportError:
            pass
    for n in _PLOT_CALLS:
        setattr(m, n, _display_only("%s.%s" % (m.__name__, n)))
    m.subplots = lambda *a, **k: (_NoPlot("figure"), _NoPlot("axes"))
    m.savefig = unsupported("savefig (matplotlib is not installed)")
    m.__vd_shim__ = True
    if name == "pylab":
        return m
    pkg = _types.ModuleType("matplotlib")
    pkg.pyplot = m
    pkg.use = _display_only("matplotlib.use")
    pkg.__vd_shim__ = True
    return m if fromlist and name == "matplotlib.pyplot" else pkg


def _import_beside(name, globals, fromlist, level):
    """A module or package in the .lpy file's folder (L-Py puts that folder on sys.path): `mod.py`
    or `pkg/__init__.py` there, a package's submodules, relative imports inside a package. None
    when the name is not there. The modules are kept here, not in sys.modules (a host process's
    modules stay its own), and import openalea from this shim."""
    if not globals:
        return None
    root = globals.get("__vd_root__")
    if root is None:
        if not globals.get("__file__"):
            return None
        root = _os.path.dirname(_os.path.abspath(globals["__file__"]))
    if level:
        pkg = globals.get("__package__") or ""
        parts = pkg.split(".") if pkg else []
        if not parts or level - 1 > len(parts) - 1:
            return None
        base = ".".join(parts[: len(parts) - (level - 1)])
        name = base + "." + name if name else base
    parts = name.split(".")
    mod, top = None, None
    for k in range(len(parts)):
        mod = _load_beside(root, ".".join(parts[: k + 1]), mod)
        if mod is None:
            return None
        top = top or mod
    for f in fromlist or ():
        # `from pkg import sub`: a submodule the package has not imported itself
        if f != "*" and not hasattr(mod, f) and getattr(mod, "__path__", None):
            _load_beside(root, name + "." + f, mod)
    return mod if fromlist else top


def _load_beside(root, qualname, parent):
    """The module qualname (its parent package already loaded) from root, run once."""
    leaf = qualname.rsplit(".", 1)[-1]
    folder = parent.__path__[0] if parent is not None else root
    if parent is not None and not getattr(parent, "__path__", None):
        return None
    path, pkgdir = _os.path.join(folder, leaf + ".py"), None
    if _os.path.isfile(_os.path.join(folder, leaf, "__init__.py")):
        pkgdir = _os.path.join(folder, leaf)
        path = _os.path.join(pkgdir, "__init__.py")
    elif not _os.path.isfile(path):
        return None
    mod = _local_modules.get(path)
    if mod is None:
        import importlib.util as iu
        spec = iu.spec_from_file_location(qualname, path, submodule_search_locations=[pkgdir] if pkgdir else None)
        mod = iu.module_from_spec(spec)
        # its own imports are answered as the file's are (openalea from this shim, the model's
        # folder first)
        mod.__builtins__ = _BUILTINS
        mod.__vd_local__ = True
        mod.__vd_root__ = root
        _local_modules[path] = mod
        try:
            spec.loader.exec_module(mod)
        except BaseException:
            del _local_modules[path]
            raise
    if parent is not None:
        setattr(parent, leaf, mod)
    return mod


# ---------------------------------------------------------------------------------------------
# display and extensions: verdant has no viewer (every Viewer call does nothing, as in L-Py's
# batch runs); tools it does not provide fail when called, not when imported


Viewer = _NoWindow("Viewer")
eStatic, eAnimatedPrimitives, eAnimatedScene = 0, 1, 2


def pgl_support_extension(name):
    """PlantGL's optional extensions (CGAL, ...): none here."""
    return False


def _vd_lazy_scene(_=None):
    """The scene a hook receives: filled on first use with what the turtle draws."""
    sc = Scene()
    sc._vd_source = lambda: _vd_build_scene(_vd.scene())
    return sc


def _placed(g, pos, u, l):
    """PglTurtleDrawer::transform: local x along U, y along -L, z along H, then the position."""
    if abs(u.x - 1) > 1e-9 or abs(u.y) > 1e-9 or abs(u.z) > 1e-9 or abs(l.x) > 1e-9 or abs(l.y + 1) > 1e-9 or abs(l.z) > 1e-9:
        g = Oriented(u, -l, g)
    if norm(pos) > 1e-12:
        g = Translated(pos, g)
    return g


def _vd_build_scene(prims):
    """Shapes from the turtle's primitives (kind, module, parent, ...), in module order."""
    out = []
    order = sorted(range(len(prims)), key=lambda k: (prims[k][1], k))
    for k in order:
        p = prims[k]
        kind, mid, parent = p[0], int(p[1]), int(p[2])
        if kind == "seg":
            p0, p1, r0, r1, up = Vector3(*p[3]), Vector3(*p[4]), p[5], p[6], Vector3(*p[7])
            d = p1 - p0
            length = norm(d)
            h = d / length if length > 0 else Vector3(0, 0, 1)
            l = (up ^ h).normed()
            if r0 > 1e-6:
                taper = r1 / r0
                if abs(taper) < 1e-6:
                    g = Cone(r0, length, False)
                elif abs(taper - 1) < 1e-6:
                    g = Cylinder(r0, length, False)
                else:
                    g = Frustum(r0, length, taper, False)
                g = _placed(g, p0, up, l)
            elif r1 < 1e-6:
                g = Polyline([p0, p1])
            else:
                g = Cone(r1, length, False)
                if abs(l.x - 1) > 1e-9 or abs(l.y) > 1e-9 or abs(l.z) > 1e-9 or abs(up.y + 1) > 1e-9:
                    g = Oriented(l, -up, g)
                g = Translated(p1, g)
        elif kind == "sph":
            g = Sphere(p[4])
            if norm(Vector3(*p[3])) > 1e-12:
                g = Translated(Vector3(*p[3]), g)
        else:
            g = TriangleSet(p[3], p[4])
        out.append(Shape(g, None, mid, parent))
    return out




# ---------------------------------------------------------------------------------------------
# what the turtle asks for


def _vd_mesh(g):
    """(flat vertex coordinates, flat triangle indices, closed) of a geometry, or None."""
    m = _mesh_of(g)
    if m is None or not m[1]:
        return None
    v, t, closed = m
    return [float(c) for p in v for c in p], [int(i) for f in t for i in f], bool(closed)


def _vd_curve(c, n=0):
    """(flat points, dimension) of a curve sampled at n + 1 equal steps of u (its stride when
    n is 0), or None when c is not a curve."""
    if not isinstance(c, _Curve):
        if hasattr(c, "getPointAt") and hasattr(c, "getStride"):
            pass
        else:
            return None
    pts = c._vd_points(n) if hasattr(c, "_vd_points") else _Curve._vd_points(c, n)
    dim = len(pts[0])
    return [float(x) for p in pts for x in p], dim


def _vd_guide(c, m):
    """A guide for the turtle (PlantGL's TurtlePath): the curve's length (PlantGL's chords of its
    stride), m + 1 points, unit tangents and unit normals at equal steps of normalised arc length
    (through getArcLengthToUMapping, as PlantGL), and the dimension; None if c is not a curve."""
    if not (isinstance(c, _Curve) or (hasattr(c, "getPointAt") and hasattr(c, "getArcLengthToUMapping"))):
        return None
    length = c.getLength()
    f = c.getArcLengthToUMapping()
    pts, tan, nrm = [], [], []
    for i in range(m + 1):
        u = f(i / m)
        pts += list(c.getPointAt(u))
        t = c.getTangentAt(u)
        n = norm(t)
        tan += [x / n for x in t] if n > 0 else list(t)
        nn = c.getNormalAt(u) if hasattr(c, "getNormalAt") else t
        k = norm(nn)
        nrm += [x / k for x in nn] if k > 0 else list(nn)
    return float(length), [float(x) for x in pts], [float(x) for x in tan], [float(x) for x in nrm], len(pts) // (m + 1)


def _vd_function(f):
    """(firstx, lastx, values) of a function for the turtle: a QuantisedFunction's own samples
    (a curve used as a function is quantised first, as L-Py does); None otherwise."""
    if isinstance(f, _Curve):
        f = QuantisedFunction(f)
    if isinstance(f, QuantisedFunction):
        return float(f.firstx), float(f.lastx), [float(v) for v in f.values]
    if callable(f):
        return 0.0, 1.0, [float(f(i / 100)) for i in range(101)]
    return None


def _vd_vec3(x):
    """The three coordinates of a 3D vector (Vector3, a sequence of three numbers), or None."""
    if isinstance(x, (Vector2, Vector4, str)):
        return None
    try:
        c = [float(a) for a in x]
    except (TypeError, ValueError):
        return None
    return c if len(c) == 3 else None


def _vd_number(x):
    """float(x) for number-like objects; None otherwise."""
    try:
        return float(x)
    except (TypeError, ValueError):
        return None


# ---------------------------------------------------------------------------------------------
# the module tree answered to `import openalea...` and the base namespace of every run


def _module(name, names):
    m = _types.ModuleType(name)
    g = globals()
    for n in names:
        setattr(m, n, g[n])
    return m


_MATH = ["Vector2", "Vector3", "Vector4", "Matrix3", "norm", "normSquared", "normL1", "normLinf", "dot", "cross",
         "angle", "direction"]
_SCENEGRAPH = ["Point2Array", "Point3Array", "Point4Array", "RealArray", "Index3Array", "Index4Array", "IndexArray",
               "Point2Matrix", "Point3Matrix", "Point4Matrix", "Color3", "Color4", "Material", "ImageTexture",
               "Texture2D", "Texture2DTransformation", "NurbsCurve2D", "NurbsCurve", "BezierCurve2D", "BezierCurve",
               "Polyline2D", "Polyline", "Curve2D", "QuantisedFunction", "Sphere", "Cylinder", "Cone", "Frustum",
               "Disc", "Box", "Mesh", "TriangleSet", "FaceSet", "QuadSet", "Translated", "Scaled", "AxisRotated", "NurbsPatch",
               "BezierPatch", "Paraboloid", "NurbsPatch3D", "Point2Grid", "Point3Grid", "Discretizer",
               "PointSet", "pointset_directions", "pointset_mean_direction", "findClosestFromSubset",
               "EulerRotated", "Oriented", "Group", "Shape", "Scene", "Revolution", "Swung", "Extrusion"]
_LPY = ["Lstring", "AxialTree", "PatternString", "Module", "ParamModule", "useGroup", "getGroup",
        "getIterationNb", "isFirstIteration", "Stop", "forward", "backward", "isForward", "frameDisplay",
        "nsproduce", "extern", "context", "execContext", "isAnimationEnabled", "ParameterSet", "isFrameDisplayed",
        "PatternModule", "inLeftContext", "inRightContext", "InLeftContext", "InRightContext", "ModuleClass",
        "Lsystem", "newmodule"]

_DISPLAY = ["Viewer", "eStatic", "eAnimatedPrimitives", "eAnimatedScene", "pgl_support_extension"]
_pgl_math = _module("openalea.plantgl.math", _MATH)
_pgl_sg = _module("openalea.plantgl.scenegraph", _SCENEGRAPH)
_pgl_all = _module("openalea.plantgl.all", _MATH + _SCENEGRAPH + _DISPLAY)
_pgl_nd = _module("openalea.plantgl.scenegraph.nurbspatch_nd", ["NurbsPatch3D"])
_pgl_sg.nurbspatch_nd = _pgl_nd
_pgl_cspline = _module("openalea.plantgl.scenegraph.cspline", ["CSpline", "cspline"])
_pgl_sg.cspline = _pgl_cspline
_pgl_light = _types.ModuleType("openalea.plantgl.light.light")
_pgl_light.diffuseInterception = unsupported("diffuseInterception")
_pgl_light.directionalInterception = unsupported("directionalInterception")
_pgl_light_pkg = _types.ModuleType("openalea.plantgl.light")
_pgl_light_pkg.light = _pgl_light
_pgl = _module("openalea.plantgl", [])
_pgl.all, _pgl.math, _pgl.scenegraph, _pgl.light = _pgl_all, _pgl_math, _pgl_sg, _pgl_light_pkg
_lpy = _module("openalea.lpy", _LPY)
_lpy_ps = _module("openalea.lpy.parameterset", ["ParameterSet"])
_lpy.parameterset = _lpy_ps
_openalea = _module("openalea", [])
_openalea.plantgl, _openalea.lpy = _pgl, _lpy
OPENALEA = {"openalea": _openalea, "openalea.plantgl": _pgl, "openalea.plantgl.all": _pgl_all,
            "openalea.plantgl.math": _pgl_math, "openalea.plantgl.scenegraph": _pgl_sg, "openalea.lpy": _lpy,
            "openalea.plantgl.light": _pgl_light_pkg, "openalea.plantgl.light.light": _pgl_light,
            "openalea.lpy.parameterset": _lpy_ps, "openalea.plantgl.scenegraph.nurbspatch_nd": _pgl_nd,
            "openalea.plantgl.scenegraph.cspline": _pgl_cspline}


_NotInShim = NotInVerdant


for _m in OPENALEA.values():
    _m.__vd_shim__ = True
    _m.__getattr__ = missing_attr(_m.__name__)


def _lpy_getattr(name, _missing=_lpy.__getattr__):
    """openalea.lpy's names beyond _LPY: the predefined module classes by name and alias."""
    c = _predefined_class(name) if not name.startswith("__") else None
    return c if c is not None else _missing(name)


_lpy.__getattr__ = _lpy_getattr

_BUILTINS = dict(_builtins.__dict__)
_BUILTINS["__import__"] = _vd_import
_BUILTINS["print"] = _vd_print

BASE = {"__builtins__": _BUILTINS, "__name__": "__lpy__"}
for _n in _MATH + _SCENEGRAPH + _LPY + _DISPLAY:
    BASE[_n] = globals()[_n]
BASE["__vd_p"] = _vd.p
BASE["__vd_kw"] = _vd.kw
BASE["__vd_mk"] = _vd_mk

