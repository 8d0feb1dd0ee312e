# SPDX-License-Identifier: MIT
"""openalea.lpy: L-strings and modules, the functions of the running L-system, parameter sets,
the per-file modules (__lpyfuture__, tableparameterset), the context and its options."""
import sys as _sys
import types as _types

from . import _vd
from .errors import NotInVerdant
from .pgl_appearance import Material
from .pgl_math import Vector3

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

    def __call__(self, *args):
        """A module of this class with these parameters (L-Py's generate_module)."""
        return Module(self.name, *args)


class _NewModuleClass(ModuleClass):
    """L-Py's predefined module `new` (alias newmodule): newmodule('B', 1, 2) is the module
    B(1, 2)."""

    def __call__(self, name, *args):
        if not isinstance(name, str):
            raise TypeError("newmodule(name, ...): the first argument is the new module's name, got %r" % (name,))
        return Module(name, *args)


newmodule = _NewModuleClass("new")


def _predefined_class(name):
    """openalea.lpy.NAME for a predefined module (F, Left, Sphere, SetGuide, ...): its class, or
    None when name is no predefined module."""
    if name in ("new", "newmodule"):
        return newmodule
    short = _vd.predefined(name)
    return ModuleClass(short) if short is not None else None


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
        raise NotInVerdant("context().options.%s (verdant's options are setSelection, selection and find)" % name)


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
        if name.startswith("__") or not name.startswith(("set", "clear", "add", "remove")):
            raise (AttributeError if name.startswith("__") else NotInVerdant)(
                "context().turtle.%s (verdant's turtle settings take commands set..., clear..., add..., remove...)"
                % name)

        def record(*a, **k):
            """A display setting of the turtle: recorded (the turtle's defaults come from the
            settings that change the geometry: setAngleIncrement, setWidthIncrement, ...)."""
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
        raise NotInVerdant("context().%s (verdant's L-system context does not have it)" % k)

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


