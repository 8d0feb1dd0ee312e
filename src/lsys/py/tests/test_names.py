# SPDX-License-Identifier: MIT
"""Every name the shim answers to `import openalea...` is either real or raises naming itself:
no silent placeholder. The engine's modules are loaded here with a stand-in for the C module
`_vd` whose every function raises (the names are inspected and called without the engine)."""
import inspect
import sys
import types

import pytest


class NoEngine(RuntimeError):
    pass


def _fake_vd():
    m = types.ModuleType("lpyshim._vd")

    def __getattr__(name):
        if name == "predefined":  # no predefined module classes without the engine
            return lambda n: None

        def f(*a, **k):
            raise NoEngine("_vd.%s needs the engine" % name)
        return f
    m.__getattr__ = __getattr__
    return m


@pytest.fixture(scope="module")
def engine():
    sys.modules["lpyshim._vd"] = _fake_vd()
    from lpyshim import engine
    yield engine
    sys.modules.pop("lpyshim._vd", None)


# procedures of L-Py and PlantGL whose answer is None by design (they act, or they are
# display-only commands of a viewer that verdant does not have)
PROCEDURES = {"useGroup", "Stop", "forward", "backward", "frameDisplay", "nsproduce", "extern"}


def public_names(mod):
    return sorted(n for n in dir(mod) if not n.startswith("_"))


def test_every_name_is_real_or_refused(engine):
    """Call every public function and class of every openalea module without arguments: an
    answer, a TypeError (it needs arguments), a refusal naming it or the engine's own error
    are fine; None from anything but a procedure is a silent placeholder."""
    silent = []
    for modname, mod in sorted(engine.OPENALEA.items()):
        for name in public_names(mod):
            obj = getattr(mod, name)
            if isinstance(obj, types.ModuleType) or not callable(obj) or inspect.isclass(obj):
                continue
            try:
                r = obj()
            except (TypeError, ValueError, NoEngine):
                continue
            except (engine.NotInVerdant, engine.NotProvided) as e:
                assert name in str(e), "%s.%s refuses without naming itself: %s" % (modname, name, e)
                continue
            if r is None and name not in PROCEDURES:
                silent.append("%s.%s" % (modname, name))
    assert not silent, "silent placeholders: %s" % silent


def test_missing_names_are_refused_by_name(engine):
    for modname, mod in engine.OPENALEA.items():
        with pytest.raises(engine.NotInVerdant, match=modname.replace(".", r"\.") + r"\.NoSuchThing"):
            getattr(mod, "NoSuchThing")
        assert not hasattr(mod, "NoSuchThing")  # hasattr still sees an AttributeError


def test_tools_not_provided_raise_by_name(engine):
    light = engine.OPENALEA["openalea.plantgl.light.light"]
    for name in ("diffuseInterception", "directionalInterception"):
        with pytest.raises(engine.NotProvided, match=name):
            getattr(light, name)(None)


# PlantGL's Viewer API: queries with answers a model would use (the light models read the
# projection per shape) and commands that only draw
VIEWER_QUERIES = ["frameGL.getProjectionPerShape", "frameGL.grabZBuffer", "frameGL.grabZBufferPoints",
                  "frameGL.getProjectionSize", "frameGL.saveImage", "camera.getPosition", "camera.getDirection",
                  "getCurrentScene", "selection", "getSelection", "isRunning", "frameGL.getSize"]
VIEWER_COMMANDS = ["display", "add", "update", "redraw", "animation", "camera.lookAt", "camera.setOrthographic",
                   "frameGL.setBgColor"]


def _walk(root, path):
    obj = root
    for part in path.split("."):
        obj = getattr(obj, part)
    return obj


def test_viewer_queries_raise_by_name(engine):
    for q in VIEWER_QUERIES:
        with pytest.raises(engine.NotInVerdant, match=r"Viewer\." + q.replace(".", r"\.")):
            _walk(engine.Viewer, q)()


def test_viewer_commands_only_draw(engine):
    for c in VIEWER_COMMANDS:
        f = _walk(engine.Viewer, c)
        assert getattr(f, "__vd_display_only__", False), c
        assert f(1, 2) is None
    engine.Viewer.redrawPolicy = False  # a setting: nothing to set


def test_context_has_no_silent_attributes(engine):
    from lpyshim.lpy import _Context
    ctx = _Context({})
    with pytest.raises(engine.NotInVerdant, match=r"context\(\)\.animation_timestep_query"):
        ctx.animation_timestep_query
    with pytest.raises(engine.NotInVerdant, match=r"context\(\)\.options\.getAll"):
        ctx.options.getAll
    with pytest.raises(engine.NotInVerdant, match=r"context\(\)\.turtle\.getColor"):
        ctx.turtle.getColor
    ctx.turtle.setColorAt(1, 2)  # a display setting: recorded
    assert ctx.turtle.settings["setColorAt"] == (1, 2)
