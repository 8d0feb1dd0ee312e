# SPDX-License-Identifier: MIT
"""What the shim does not provide: every such name or call raises, naming it (the engine
reports `unsupported: ...`), never answers with a silent placeholder; and the display that has
no window here (PlantGL's Viewer), whose drawing commands do nothing and whose queries raise."""


class NotInVerdant(AttributeError):
    """A PlantGL or L-Py name the shim does not have: the engine refuses the file (unsupported),
    naming it; hasattr() and getattr(m, name, default) still see an AttributeError."""


class NotProvided(NotImplementedError):
    """A call the shim knows but cannot answer (light interception, a viewer query, ...): the
    engine refuses the file (unsupported), naming the call."""


def unsupported(what, why="verdant's PlantGL does not provide it"):
    """A function that raises NotProvided naming `what` when called."""
    def f(*a, **k):
        raise NotProvided("%s: %s" % (what, why))
    f.__name__ = what.rsplit(".", 1)[-1]
    f.__vd_not_provided__ = True
    return f


def missing_attr(modname):
    """A module's __getattr__ for the names it does not have."""
    def __getattr__(name):
        if name.startswith("__"):
            raise AttributeError(name)
        raise NotInVerdant("%s.%s (verdant's PlantGL / L-Py does not have it)" % (modname, name))
    return __getattr__


# PlantGL's Viewer: the commands that only change what a window shows are accepted and do
# nothing (a command-line run has no window, as L-Py's batch runs); every other attribute,
# queries included (camera.getPosition, frameGL.getProjectionPerShape, grabZBuffer, saveImage:
# answers or files a model would use), raises naming it
VIEWER_COMMANDS = {
    "Viewer": {"display", "add", "update", "redraw", "animation", "start", "stop", "show", "hide", "wait",
               "setAnimation", "setBatchMode", "clear", "setSelection", "waitSelection"},
    "Viewer.camera": {"lookAt", "setOrthographic", "setPerspective", "setPosition", "setAngles", "setElevation",
                      "setAzimuth", "setPositionVector", "setViewAngle", "setDirection", "lock", "unlock"},
    "Viewer.frameGL": {"setBgColor", "setSize", "maximize", "setCamera", "setLight", "setLineWidth"},
    "Viewer.grids": {"setXYPlane", "setYZPlane", "setXZPlane", "setAxis"},
    "Viewer.light": {"setEnabled", "setPosition", "setAmbient", "setDiffuse", "setSpecular"},
    "Viewer.widgetGeometry": {"setSize", "setPosition"},
}


class _NoWindow:
    """A part of PlantGL's Viewer without a window (see VIEWER_COMMANDS)."""

    def __init__(self, path):
        object.__setattr__(self, "_path", path)

    def __getattr__(self, name):
        if name.startswith("__"):
            raise AttributeError(name)
        path = self._path + "." + name
        if path in VIEWER_COMMANDS:
            return _NoWindow(path)
        if name in VIEWER_COMMANDS.get(self._path, ()):
            return _display_only(path)
        raise NotInVerdant("%s (verdant has no viewer: it draws nothing and answers no query)" % path)

    def __setattr__(self, name, value):
        """Settings of the window (redrawPolicy, ...): nothing to set."""

    def __repr__(self):
        return "<%s: no window in verdant>" % self._path


def _display_only(path):
    def f(*a, **k):
        """A command that only changes what a window shows: nothing to do."""
    f.__name__ = path.rsplit(".", 1)[-1]
    f.__vd_display_only__ = True
    return f


Viewer = _NoWindow("Viewer")
