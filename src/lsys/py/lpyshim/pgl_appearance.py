# SPDX-License-Identifier: MIT
"""Colours, materials and textures: display settings, recorded (verdant's label is the colour
index)."""
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


