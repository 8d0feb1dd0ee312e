# SPDX-License-Identifier: MIT
"""verdant's Python engine's stand-in for L-Py and PlantGL (the names an .lpy file sees).

The C side (src/lsys/py/lsys_py.c) compiles these modules into the library and runs them once
per process, in the order of __all__, as the private package `_verdant_lpyshim`; `engine` (the
last) builds what the engine uses. The PlantGL geometry modules are plain Python, importable
and tested on their own (src/lsys/py/tests); `lpy` and `engine` call back into the engine's C
module `_vd`, which only exists inside it.
"""
__all__ = ["errors", "pgl_math", "pgl_appearance", "pgl_geometry", "pgl_curves", "pgl_surfaces", "pgl_algo", "lpy", "engine"]
