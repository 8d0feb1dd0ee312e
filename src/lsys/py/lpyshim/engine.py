# SPDX-License-Identifier: MIT
# verdant's Python engine: the names an .lpy file sees (L-Py's openalea.lpy and a small
# openalea.plantgl), written for verdant. The C side (lsys_py.c) runs this file once per process
# into a private module; `_vd` is its C module (produce, groups, iteration, the log). Nothing
# here is placed in sys.modules: a file's `import openalea...` is answered from OPENALEA through
# the namespace's own __import__, so a host process with a real openalea keeps it.
#
# PlantGL semantics follow openalea/plantgl (scenegraph/geometry/nurbscurve.cpp, beziercurve.cpp,
# polyline.cpp, curve.cpp, function/function.cpp): default knot vectors, homogeneous control
# points (x, y, w), [firstKnot, lastKnot] parameter ranges, stride 30, QuantisedFunction's
# sampling 100, arc length by the stride's chords.
import builtins as _builtins
import itertools as _itertools
import math as _math
import os as _os
import random as _random
import sys as _sys
import types as _types

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
    try:
        mod = _real_import(name, globals, locals, fromlist, level)
    except ModuleNotFoundError:
        mod = _import_beside(name, globals, fromlist, level)
        if mod is None and level == 0 and name in ("pylab", "matplotlib", "matplotlib.pyplot"):
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
        setattr(m, n, _NoDisplay())
    m.subplots = lambda *a, **k: (_NoDisplay(), _NoDisplay())
    m.savefig = _unsupported("savefig (matplotlib is not installed)")
    m.__vd_shim__ = True
    if name == "pylab":
        return m
    pkg = _types.ModuleType("matplotlib")
    pkg.pyplot = m
    pkg.use = _NoDisplay()
    pkg.__vd_shim__ = True
    return m if fromlist and name == "matplotlib.pyplot" else pkg


def _import_beside(name, globals, fromlist, level):
    """A module file next to the .lpy file (L-Py runs files from their folder)."""
    if level != 0 or not globals or not globals.get("__file__"):
        return None
    top = name.split(".")[0]
    path = _os.path.join(_os.path.dirname(_os.path.abspath(globals["__file__"])), top + ".py")
    if not _os.path.isfile(path):
        return None
    mod = _local_modules.get(path)
    if mod is None:
        import importlib.util as iu
        spec = iu.spec_from_file_location(top, path)
        mod = iu.module_from_spec(spec)
        # its own imports are answered as the file's are (openalea from this shim)
        mod.__builtins__ = _BUILTINS
        mod.__vd_local__ = True
        spec.loader.exec_module(mod)
        _local_modules[path] = mod
    return mod


# ---------------------------------------------------------------------------------------------
# L-strings and modules (openalea.lpy)


class Module:
    """A module: a name and its parameters (L-Py's Module / ParamModule)."""
    __slots__ = ("name", "args")

    def __init__(self, name, *args):
        if isinstance(name, Module):
            self.name, self.args = name.name, list(name.args)
            return
        if isinstance(name, tuple) and len(name) == 2 and not args:
            name, args = name[0], tuple(name[1])
        if not isinstance(name, str):
            raise TypeError("a module name must be a string")
        if not args and ("(" in name or " " in name.strip()):
            items = _parse_items(name, _sys._getframe(1).f_globals)
            if len(items) != 1:
                raise ValueError("'%s' is not one module" % name)
            name, args = items[0]
        self.name = name
        self.args = list(args)

    def __getitem__(self, i):
        return self.args[i]

    def __setitem__(self, i, v):
        self.args[i] = v

    def __len__(self):
        return len(self.args)

    def __iter__(self):
        return iter(self.args)

    def __eq__(self, o):
        if isinstance(o, Module):
            return self.name == o.name and self.args == o.args
        if isinstance(o, str):
            return self == Module(o) if "(" in o else (self.name == o and not self.args)
        return NotImplemented

    def __ne__(self, o):
        r = self.__eq__(o)
        return r if r is NotImplemented else not r

    def __hash__(self):
        return hash(self.name)

    def __repr__(self):
        if not self.args:
            return self.name
        return self.name + "(" + ",".join(_repr_param(a) for a in self.args) + ")"

    __str__ = __repr__

    def _item(self):
        return (self.name, tuple(self.args))

    # L-Py's accessors
    mname = property(lambda self: self.name)

    def getParameter(self, i):
        return self.args[i]

    def setParameter(self, i, v):
        self.args[i] = v

    def getParameters(self):
        return list(self.args)

    def getParameterNumber(self):
        return len(self.args)

    def hasParameter(self, name):
        return False

    def copy(self):
        return Module(self.name, *self.args)

    def isBracket(self):
        return self.name in ("[", "]")

    def isLeftBracket(self):
        return self.name == "["

    def isRightBracket(self):
        return self.name == "]"

    def isCut(self):
        return self.name == "%"

    def getName(self):
        return self.name

    def __add__(self, o):
        return Lstring([self]) + o


ParamModule = Module


def _repr_param(a):
    if isinstance(a, float) and a == int(a) and abs(a) < 1e15:
        return repr(a)
    return repr(a)


def _parse_items(text, globs):
    """The modules of an L-string text, parameters evaluated in globs."""
    out = []
    for name, params in _vd.parse(text):
        out.append((name, tuple(eval(p, globs) for p in params)))
    return out


def _as_module(x):
    if isinstance(x, Module):
        return x
    if isinstance(x, tuple) and len(x) == 2 and isinstance(x[0], str):
        return Module(x[0], *x[1])
    if isinstance(x, str):
        return Module(x)
    raise TypeError("not a module: %r" % (x,))


class Lstring(list):
    """An L-string: a list of modules (L-Py's Lstring / AxialTree), with the axial-tree helpers."""

    def __init__(self, x=None):
        if x is None:
            super().__init__()
        elif isinstance(x, str):
            super().__init__(Module(n, *p) for n, p in _parse_items(x, _sys._getframe(1).f_globals))
        else:
            super().__init__(_as_module(m) for m in x)

    @classmethod
    def _from_items(cls, items):
        s = cls()
        list.extend(s, (Module(n, *p) for n, p in items))
        return s

    def _items(self):
        return [m._item() for m in self]

    def __getitem__(self, i):
        r = list.__getitem__(self, i)
        return Lstring(r) if isinstance(i, slice) else r

    def __add__(self, o):
        r = Lstring(self)
        r += o
        return r

    def __radd__(self, o):
        return Lstring(o) + self

    def __iadd__(self, o):
        if isinstance(o, (Module, str)) and not isinstance(o, Lstring):
            o = Lstring(o) if isinstance(o, str) else [o]
        list.extend(self, (_as_module(m) for m in o))
        return self

    def append(self, m):
        list.append(self, _as_module(m))

    def insertAt(self, i, m):
        list.insert(self, i, _as_module(m))

    def __repr__(self):
        return "".join(repr(m) for m in self)

    __str__ = __repr__

    def __eq__(self, o):
        if isinstance(o, str):
            o = Lstring(o)
        return list.__eq__(self, o)

    def __ne__(self, o):
        return not self.__eq__(o)

    __hash__ = None

    # axial-tree navigation (indices)
    def wellBracketed(self):
        d = 0
        for m in self:
            if m.name == "[":
                d += 1
            elif m.name == "]":
                d -= 1
                if d < 0:
                    return False
        return d == 0

    def endBracket(self, i):
        d = 0
        for j in range(i + 1, len(self)):
            n = list.__getitem__(self, j).name
            if n == "[":
                d += 1
            elif n == "]":
                if d == 0:
                    return j
                d -= 1
        return len(self)

    def beginBracket(self, i):
        d = 0
        for j in range(i - 1, -1, -1):
            n = list.__getitem__(self, j).name
            if n == "]":
                d += 1
            elif n == "[":
                if d == 0:
                    return j
                d -= 1
        return -1

    def parent(self, i):
        j = i - 1
        while j >= 0:
            n = list.__getitem__(self, j).name
            if n == "]":
                j = self.beginBracket(j) - 1
            elif n == "[":
                j -= 1
            else:
                return j
        return None

    def children(self, i):
        out, j = [], i + 1
        while j < len(self):
            n = list.__getitem__(self, j).name
            if n == "[":
                if j + 1 < len(self) and list.__getitem__(self, j + 1).name not in "[]":
                    out.append(j + 1)
                j = self.endBracket(j) + 1
            elif n == "]":
                break
            else:
                out.append(j)
                break
        return out

    def lateral_children(self, i):
        return self.children(i)[:-1] if self.direct_child(i) is not None else self.children(i)

    def direct_child(self, i):
        c = self.children(i)
        if c and (c[-1] == i + 1 or list.__getitem__(self, c[-1] - 1).name != "["):
            return c[-1]
        return None

    father = parent
    sons = children


AxialTree = Lstring
PatternString = Lstring


def _vd_lstring(items):
    return Lstring._from_items(items)


def _vd_items(x):
    """What a rule body or hook returned, as (name, params) items."""
    if isinstance(x, Module):
        return [x._item()]
    if isinstance(x, str):
        return [(n, p) for n, p in _parse_items(x, {})]
    return [_as_module(m)._item() for m in x]


def _vd_mk(*args):
    return Lstring._from_items(_vd.mk(*args))


# L-Py's functions of the running L-system
def useGroup(n):
    _vd.use_group(int(n))


def getGroup():
    return _vd.get_group()


def inLeftContext(pattern, params=None):
    """In a rule's body: does the pattern match left of where the rule's left context ended?
    Its variables go into params; on a match the next call reads on from there."""
    return _vd.in_context(0, str(pattern), params)


def inRightContext(pattern, params=None):
    """The same on the right of the rule's right context."""
    return _vd.in_context(1, str(pattern), params)


InLeftContext = inLeftContext     # the file's InLeftContext(A(x), params) is translated to a string
InRightContext = inRightContext


def _vd_make_vec3(c):
    """A Vector3 the turtle fills into a query module (?P, ?F ...)."""
    return Vector3(*c)


def getIterationNb():
    return _vd.iteration()


def isFirstIteration():
    return _vd.iteration() == 0


def Stop():
    _vd.stop()


def forward():
    """Derive left to right from the next step on (the default)."""
    _vd.set_backward(False)


def backward():
    """Derive right to left from the next step on (new right contexts >> apply)."""
    _vd.set_backward(True)


def isForward():
    return not _vd.is_backward()


def frameDisplay(enabled=True):
    """Whether the step's frame is drawn (an animation skips it when False)."""
    _vd.set_frame_displayed(bool(enabled))


def isFrameDisplayed():
    """True during the last step, or any step of an animation (L-Py computes a scene for the
    hooks then)."""
    return _vd.frame_displayed()


def isAnimationEnabled():
    """True while verdant animates (vd_lsys_animate, grow --animate)."""
    return _vd.animating()


class Lsystem:
    """An L-system inside a file (L-Py's Lsystem): its code (L-Py's simple Python subset) is
    derived by verdant's native engine, seeded 0; iterate()/derive() give its string."""

    def __init__(self, filename=None):
        self.code = ""
        if filename:
            with open(filename, encoding="utf-8") as f:
                self.code = f.read()

    def set(self, code):
        self.code = code

    def iterate(self, n=None):
        return Lstring._from_items(_vd.nested(self.code, -1 if n is None else int(n)))

    def derive(self, n=None):
        return self.iterate(n)


class ModuleClass:
    """A module's class, as L-Py's ModuleClass: its name and its declared bases
    (`module B : base = A`)."""

    def __init__(self, name):
        self.name = name

    @staticmethod
    def get(name):
        return ModuleClass(name)

    def issubclass(self, other):
        """Is this module other's module or one of its subclasses?"""
        return _vd.isa(self.name, other.name)

    def __eq__(self, other):
        return isinstance(other, ModuleClass) and other.name == self.name

    def __hash__(self):
        return hash(self.name)

    def __repr__(self):
        return "ModuleClass(%r)" % self.name


class _PatternModuleType(type):
    @property
    def matchingMethod(cls):
        return _vd.module_matching()


class PatternModule(metaclass=_PatternModuleType):
    """The 'Module matching' option's values, and the one in force (matchingMethod)."""
    eSimple, eWithStar, eWithStarNValueConstraint = 0, 1, 2
    eDefaultModuleMatching = 2


def nsproduce(lstring):
    """Append an L-string object to the current production (L-Py's nsproduce)."""
    _vd.append(_vd_items(lstring))


def extern(**kw):
    """extern(name=default): a global the caller may set beforehand (--set)."""
    g = _sys._getframe(1).f_globals
    over = g.get("__vd_set", {})
    for k, v in kw.items():
        g[k] = over.get(k, v)


class ParameterSet:
    """A bag of named parameters (L-Py's ParameterSet): attributes, item access, defaults."""

    def __init__(self, **kw):
        self.__dict__.update(kw)

    def setdefault(self, *args, **kw):
        pairs = list(zip(args[0::2], args[1::2])) + list(kw.items())
        for k, v in pairs:
            if not hasattr(self, k):
                setattr(self, k, v)

    def hasattr(self, k):
        return hasattr(self, k)

    def get(self, k, default=None):
        return getattr(self, k, default)

    def set(self, **kw):
        self.__dict__.update(kw)

    def rename(self, old, new):
        setattr(self, new, getattr(self, old))
        delattr(self, old)

    def parameter_names(self):
        return list(self.__dict__)

    def copy(self, deep=True):
        import copy
        return copy.deepcopy(self) if deep else copy.copy(self)

    def __getitem__(self, k):
        return getattr(self, k)

    def __setitem__(self, k, v):
        setattr(self, k, v)

    def __delitem__(self, k):
        delattr(self, k)

    def __contains__(self, k):
        return hasattr(self, k)

    def __repr__(self):
        return "ParameterSet(%s)" % ",".join("%s=%r" % kv for kv in self.__dict__.items())


def _future_module():
    """openalea.lpy.__lpyfuture__, a fresh one for every run: DiscardNewString() drops a step's
    result (the EndEach it provides, or decorates, gives the string before the step back);
    pushString/popString keep strings by name."""
    m = _types.ModuleType("openalea.lpy.__lpyfuture__")
    m.__vd_shim__ = True
    state = {"discard": False, "last": None, "push": None, "pop": None, "stack": {}}

    def DiscardNewString():
        state["discard"] = True

    def enable_string_discard(endeach):
        n = endeach.__code__.co_argcount

        def wrapped(lstring, lscene=None):
            if not state["discard"]:
                res = endeach(*((lstring, lscene)[:n]))
                if not state["discard"]:
                    state["last"] = Lstring(lstring)
                    return res
            state["discard"] = False
            return state["last"]
        return wrapped

    def pushString(name):
        state["push"] = name

    def popString(name):
        if name not in state["stack"]:
            raise ValueError("no string pushed under the name %r" % (name,))
        state["pop"] = name
        return state["stack"][name]

    def enable_string_pushpop(endeach):
        n = endeach.__code__.co_argcount

        def wrapped(lstring, lscene=None):
            res = endeach(*((lstring, lscene)[:n]))
            if state["push"] is not None:
                state["stack"][state["push"]] = Lstring(lstring)
                state["push"] = None
            if state["pop"] is not None:
                res = state["stack"].pop(state["pop"])
                state["pop"] = None
            return res
        return wrapped

    @enable_string_discard
    def EndEach():
        pass

    # by name: EndEach is the decorator's wrapper, whose own __name__ is "wrapped"
    for name, f in (("DiscardNewString", DiscardNewString), ("enable_string_discard", enable_string_discard),
                    ("pushString", pushString), ("popString", popString),
                    ("enable_string_pushpop", enable_string_pushpop), ("EndEach", EndEach)):
        setattr(m, name, f)
    m.__all__ = ["DiscardNewString", "enable_string_discard", "pushString", "popString", "enable_string_pushpop",
                 "EndEach"]
    return m


class _Table:
    """get_table() where pandas is not installed: the table's columns (parameter name -> {uid:
    value}); printed as rows."""

    def __init__(self, data, n):
        self.data, self.n = data, n

    @property
    def columns(self):
        return list(self.data)

    def to_dict(self):
        return {k: dict(v) for k, v in self.data.items()}

    def __len__(self):
        return self.n

    def __repr__(self):
        cols = list(self.data)
        rows = [[""] + cols] + [[str(i)] + [repr(self.data[c][i]) if i in self.data[c] else "NaN" for c in cols]
                                for i in range(self.n)]
        w = [max(len(r[k]) for r in rows) for k in range(len(cols) + 1)]
        return "\n".join("  ".join(x.rjust(w[k]) for k, x in enumerate(r)) for r in rows)


def _tableparam_module():
    """openalea.lpy.tableparameterset, a fresh one for every run: parameter sets whose values
    live in one table (parameter name -> {uid: value}); get_table() gives it as a pandas
    DataFrame when pandas is installed."""
    m = _types.ModuleType("openalea.lpy.tableparameterset")
    m.__vd_shim__ = True
    state = {"table": None}

    class ParamDictTable:
        def __init__(self):
            self.id = 0
            self.data = {}

        def dataframe(self):
            try:
                from pandas import DataFrame
            except ImportError:
                return _Table(self.data, self.id)
            return DataFrame(self.data)

        def pnames(self):
            return list(self.data)

        def get_new_id(self, att):
            uid = self.id
            self.id += 1
            for k, v in att.items():
                self.setattr(uid, k, v)
            return uid

        def hasattr(self, uid, name):
            return name in self.data and uid in self.data[name]

        def setattr(self, uid, name, value):
            self.data.setdefault(name, {})[uid] = value

        def getattr(self, uid, name):
            if not self.hasattr(uid, name):
                raise AttributeError("parameter set %d has no parameter %r" % (uid, name))
            return self.data[name][uid]

        def delattr(self, uid, name):
            if not self.hasattr(uid, name):
                raise AttributeError(name)
            del self.data[name][uid]

        def rename(self, old, new):
            self.data[new] = self.data.pop(old)

    def init_table(value=None):
        state["table"] = ParamDictTable() if value is None else value

    def init_dict_table(value=None):
        init_table(ParamDictTable() if value is None else value)

    def table():
        if state["table"] is None:
            init_table()
        return state["table"]

    def get_table():
        return table().dataframe()

    class TableParameterSet:
        """A parameter set whose values are a row of the module's table."""

        def __init__(self, **kw):
            self.__dict__["uid"] = table().get_new_id(kw)

        def rename(self, old, new):
            table().rename(old, new)

        def setdefault(self, *args, **kw):
            for k, v in list(zip(args[0::2], args[1::2])) + list(kw.items()):
                if not table().hasattr(self.uid, k):
                    table().setattr(self.uid, k, v)

        def hasattr(self, name):
            return table().hasattr(self.uid, name)

        def get(self, name, default=None):
            return table().getattr(self.uid, name) if table().hasattr(self.uid, name) else default

        def set(self, **kw):
            for k, v in kw.items():
                table().setattr(self.uid, k, v)

        def parameter_names(self):
            return table().pnames()

        def __getattr__(self, name):
            if name.startswith("__"):
                raise AttributeError(name)
            return table().getattr(self.__dict__["uid"], name)

        def __setattr__(self, name, value):
            if name == "uid":
                self.__dict__["uid"] = value
            else:
                table().setattr(self.uid, name, value)

        def __delattr__(self, name):
            table().delattr(self.uid, name)

        def __contains__(self, name):
            return table().hasattr(self.uid, name)

        def __repr__(self):
            t = table()
            return "TableParameterSet(%d,%s)" % (self.uid, ",".join(
                "%s=%r" % (k, t.getattr(self.uid, k)) for k in t.pnames() if t.hasattr(self.uid, k)))

    for name, f in (("init_table", init_table), ("init_dict_table", init_dict_table), ("get_table", get_table),
                    ("ParamDictTable", ParamDictTable), ("ParamTable", ParamDictTable),
                    ("TableParameterSet", TableParameterSet)):
        setattr(m, name, f)
    return m


# ---------------------------------------------------------------------------------------------
# the L-system context (context(), the editor trailer's __initialiseContext__(context))


class _Options:
    def __init__(self):
        self.values = {}

    def setSelection(self, name, value):
        self.values[name] = value
        if isinstance(value, int):
            _vd.set_option(name, value)  # the options that change results act at once

    def selection(self, name):
        return self.values.get(name)

    def find(self, name):
        """An option by its name: currentValue() names its selection (L-Py's LsysOption)."""
        return _Option(self, name)

    def __getattr__(self, name):
        if name.startswith("__"):
            raise AttributeError(name)
        return lambda *a, **k: None


# the values of the options that change results, by index, as L-Py names them
_OPTION_VALUES = {
    "String matching": ["As String", "As AxialTree", "As Multi-level AxialTree", "As Multiscale AxialTree"],
    "Module matching": ["Simple", "With Star", "With Star and Value Constraint"],
    "Early return when no matching": ["Disabled", "Enabled"],
    "Axiom decomposition": ["Disabled", "Enabled"],
    "Module inheritance": ["Disabled", "Enabled"],
}
_OPTION_DEFAULTS = {"String matching": 1, "Module matching": 1, "Early return when no matching": 1,
                    "Axiom decomposition": 0, "Module inheritance": 0}


class _Option:
    def __init__(self, options, name):
        self.options, self.name = options, name

    def selection(self):
        v = self.options.values.get(self.name, _OPTION_DEFAULTS.get(self.name))
        if v is None:
            raise KeyError("option %r: verdant knows the options that change results only" % self.name)
        return v

    def currentValue(self):
        v = self.selection()
        names = _OPTION_VALUES[self.name]
        return names[v] if isinstance(v, int) and 0 <= v < len(names) else v

    def setSelection(self, value):
        self.options.setSelection(self.name, value)

    def activateSelection(self):
        """The selection acts as soon as it is set."""


class _TurtleSettings:
    """context.turtle: settings the turtle would use; colours are kept, the rest recorded."""

    def __init__(self):
        self.materials = {}
        self.settings = {}

    def setMaterial(self, i, m):
        self.materials[int(i)] = m

    def getMaterial(self, i):
        return self.materials.get(int(i), Material())

    def setColorList(self, lst):
        for i, m in enumerate(lst):
            self.materials[i] = m

    def clearColorList(self):
        self.materials.clear()

    def setAngleIncrement(self, a):
        """The default angle of + - & ^ / \\ for this file (degrees)."""
        self.settings["setAngleIncrement"] = (a,)
        _vd.set_turtle_angle(float(a))

    def __getattr__(self, name):
        if name.startswith("__"):
            raise AttributeError(name)

        def record(*a, **k):
            self.settings[name] = a
        return record


class _Context:
    def __init__(self, ns):
        object.__setattr__(self, "_ns", ns)
        object.__setattr__(self, "options", _Options())
        object.__setattr__(self, "turtle", _TurtleSettings())
        object.__setattr__(self, "attrs", {})

    def __setitem__(self, k, v):
        over = self._ns.get("__vd_set", {})
        self._ns[k] = over.get(k, v)

    def __getitem__(self, k):
        return self._ns[k]

    def __contains__(self, k):
        return k in self._ns

    def __setattr__(self, k, v):
        self.attrs[k] = v

    def __getattr__(self, k):
        if k.startswith("__"):
            raise AttributeError(k)
        if k in self.attrs:
            return self.attrs[k]
        return lambda *a, **kw: None

    def hasObject(self, k):
        return k in self._ns

    def getObject(self, k):
        return self._ns[k]

    def setObject(self, k, v):
        self[k] = v


def _vd_turtle_settings(ns):
    """The turtle settings the file made through context().turtle: {setter name: arguments}."""
    ctx = ns.get("__vd_context")
    return dict(ctx.turtle.settings) if ctx is not None else {}


def _vd_init_context(ns):
    ctx = _Context(ns)
    ns["__vd_context"] = ctx
    init = ns.get("__initialiseContext__")
    if callable(init):
        init(ctx)


def _context_of_caller():
    g = _sys._getframe(2).f_globals
    ctx = g.get("__vd_context")
    if ctx is None:
        ctx = _Context(g)
        g["__vd_context"] = ctx
    return ctx


def context():
    return _context_of_caller()


def execContext():
    return _context_of_caller()


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


# ---------------------------------------------------------------------------------------------
# colours and appearance: display only in verdant (the label is the colour index)


class Color3:
    def __init__(self, r=0, g=0, b=0):
        if isinstance(r, (tuple, list, Color3)):
            r, g, b = tuple(r)[:3]
        elif g == 0 and b == 0 and isinstance(r, int) and r > 255:
            r, g, b = (r >> 16) & 255, (r >> 8) & 255, r & 255
        self.red, self.green, self.blue = int(r), int(g), int(b)

    def __iter__(self):
        return iter((self.red, self.green, self.blue))

    def __getitem__(self, i):
        return (self.red, self.green, self.blue)[i]

    def __eq__(self, o):
        return isinstance(o, Color3) and tuple(self) == tuple(o)

    __hash__ = None

    def __repr__(self):
        return "Color3(%d,%d,%d)" % tuple(self)


class Color4(Color3):
    def __init__(self, r=0, g=0, b=0, a=0):
        if isinstance(r, (tuple, list, Color3)):
            t = tuple(r)
            r, g, b = t[:3]
            a = t[3] if len(t) > 3 else 0
        Color3.__init__(self, r, g, b)
        self.alpha = int(a)

    def __repr__(self):
        return "Color4(%d,%d,%d,%d)" % (self.red, self.green, self.blue, self.alpha)


for _n, _c in (("BLACK", (0, 0, 0)), ("WHITE", (255, 255, 255)), ("RED", (255, 0, 0)), ("GREEN", (0, 255, 0)),
               ("BLUE", (0, 0, 255)), ("YELLOW", (255, 255, 0)), ("CYAN", (0, 255, 255)),
               ("MAGENTA", (255, 0, 255))):
    setattr(Color3, _n, Color3(*_c))
    setattr(Color4, _n, Color4(*_c))


class _Appearance:
    """Material, textures: recorded; verdant uses the name as a label name where one is given."""
    _fields = ()

    def __init__(self, *args, **kw):
        if args and isinstance(args[0], str):
            kw.setdefault("name", args[0])
            args = args[1:]
        for f, v in zip(self._fields, args):
            kw.setdefault(f, v)
        self.name = kw.pop("name", "")
        for k, v in kw.items():
            setattr(self, k, v)

    def __repr__(self):
        return "%s(%r)" % (type(self).__name__, self.name)


class Material(_Appearance):
    _fields = ("ambient", "diffuse", "specular", "emission", "shininess", "transparency")

    def __init__(self, *args, **kw):
        _Appearance.__init__(self, *args, **kw)
        if not isinstance(getattr(self, "ambient", None), Color3):
            self.ambient = Color3(80, 80, 80)
        for f, d in (("diffuse", 2.0), ("shininess", 0.2), ("transparency", 0.0)):
            if not hasattr(self, f):
                setattr(self, f, d)


Material.DEFAULT_MATERIAL = Material("Default")


class ImageTexture(_Appearance):
    _fields = ("filename",)


class Texture2D(_Appearance):
    _fields = ("image", "transformation", "baseColor")


class Texture2DTransformation(_Appearance):
    _fields = ("scale", "translation", "rotationCenter", "rotationAngle")


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


def _curve_fn(c):
    """A curve used as a function of x (the editor's __functions__)."""
    return c if isinstance(c, QuantisedFunction) else QuantisedFunction(c)


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
    _vd_pending = False

    def _vd_fill(self):
        if self._vd_pending:
            self._vd_pending = False
            list.extend(self, _vd_build_scene(_vd.scene()))

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


def _vd_lazy_scene(_=None):
    sc = Scene()
    sc._vd_pending = True
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


def _mesh_of(g):
    if g is None:
        return None
    if isinstance(g, _Curve):
        return None
    f = getattr(g, "_mesh", None)
    return f() if f is not None else None


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


# ---------------------------------------------------------------------------------------------
# display and extensions: verdant has no viewer (every Viewer call does nothing, as in L-Py's
# batch runs); tools it does not provide fail when called, not when imported


class _NoDisplay:
    """PlantGL's Viewer without a window: attributes and calls accepted, nothing shown."""

    def __getattr__(self, name):
        if name.startswith("__"):
            raise AttributeError(name)
        return _NoDisplay()

    def __setattr__(self, name, value):
        pass

    def __call__(self, *a, **k):
        return None


Viewer = _NoDisplay()
eStatic, eAnimatedPrimitives, eAnimatedScene = 0, 1, 2


def pgl_support_extension(name):
    """PlantGL's optional extensions (CGAL, ...): none here."""
    return False


def _unsupported(what):
    def f(*a, **k):
        raise NotImplementedError("%s is not available in verdant's PlantGL" % what)
    f.__name__ = what
    return f


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
               "EulerRotated", "Oriented", "Group", "Shape", "Scene"]
_LPY = ["Lstring", "AxialTree", "PatternString", "Module", "ParamModule", "useGroup", "getGroup",
        "getIterationNb", "isFirstIteration", "Stop", "forward", "backward", "isForward", "frameDisplay",
        "nsproduce", "extern", "context", "execContext", "isAnimationEnabled", "ParameterSet", "isFrameDisplayed",
        "PatternModule", "inLeftContext", "inRightContext", "InLeftContext", "InRightContext", "ModuleClass",
        "Lsystem"]

_DISPLAY = ["Viewer", "eStatic", "eAnimatedPrimitives", "eAnimatedScene", "pgl_support_extension"]
_pgl_math = _module("openalea.plantgl.math", _MATH)
_pgl_sg = _module("openalea.plantgl.scenegraph", _SCENEGRAPH)
_pgl_all = _module("openalea.plantgl.all", _MATH + _SCENEGRAPH + _DISPLAY)
_pgl_nd = _module("openalea.plantgl.scenegraph.nurbspatch_nd", ["NurbsPatch3D"])
_pgl_sg.nurbspatch_nd = _pgl_nd
_pgl_light = _types.ModuleType("openalea.plantgl.light.light")
_pgl_light.diffuseInterception = _unsupported("diffuseInterception")
_pgl_light.directionalInterception = _unsupported("directionalInterception")
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
            "openalea.lpy.parameterset": _lpy_ps, "openalea.plantgl.scenegraph.nurbspatch_nd": _pgl_nd}


class NotInVerdant(AttributeError):
    """A PlantGL or L-Py name the shim does not have: the engine refuses the file (unsupported),
    naming it; hasattr() and getattr(m, name, default) still see an AttributeError."""


def _missing_attr(modname):
    def __getattr__(name):
        if name.startswith("__"):
            raise AttributeError(name)
        raise NotInVerdant("%s.%s (verdant's PlantGL / L-Py does not have it)" % (modname, name))
    return __getattr__


_NotInShim = NotInVerdant


for _m in OPENALEA.values():
    _m.__vd_shim__ = True
    _m.__getattr__ = _missing_attr(_m.__name__)

_BUILTINS = dict(_builtins.__dict__)
_BUILTINS["__import__"] = _vd_import
_BUILTINS["print"] = _vd_print

BASE = {"__builtins__": _BUILTINS, "__name__": "__lpy__"}
for _n in _MATH + _SCENEGRAPH + _LPY + _DISPLAY:
    BASE[_n] = globals()[_n]
BASE["__vd_p"] = _vd.p
BASE["__vd_kw"] = _vd.kw
BASE["__vd_mk"] = _vd_mk
