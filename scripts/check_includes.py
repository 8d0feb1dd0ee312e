#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The module dependency rules (docs/architecture.md, "Modules"): every module under src/ and its
public header include/verdant/<module>.h reach, directly or through the public headers they
include, only the modules of its row below, and the outside libraries of its row. A private
header of another module (src/<other>/...) counts as that module. Exit 1 with one line per
forbidden include (file:line: what, and what the module may include); 0 when the graph keeps the
rules. Run by ctest (include_rules) and scripts/lint.sh."""
import os
import re
import sys

# module: (modules it may include, outside libraries it may include)
RULES = {
    "core": ([], []),
    "plant": (["core"], ["cjson"]),
    "lsys": (["core", "plant"], ["python"]),
    "geom": (["core", "plant"], []),
    "collide": (["core", "geom"], []),
    "cloud": (["core", "plant", "geom"], ["cjson"]),
    "phys": (["core", "plant"], []),
    "sim": (["core", "plant", "geom", "collide", "phys"], ["cjson"]),
    "mss": (["core", "plant", "phys"], []),
    "growth": (["core", "plant", "lsys", "phys", "sim", "mss", "collide", "geom"], []),
    "mjtrap": (["core"], ["mujoco"]),
    "robot": (["core", "plant", "geom", "collide", "phys", "sim", "mjtrap"], ["mujoco", "cjson"]),
    "render": (["core", "plant", "geom", "mjtrap"], ["mujoco", "png", "egl", "gl", "cjson"]),
}
# outside libraries by the header's path
LIBS = [("cjson", r"^cjson/"), ("python", r"^(Python|structmember|frameobject)\.h$"), ("mujoco", r"^mujoco/"),
        ("png", r"^png\.h$"), ("egl", r"^EGL/"), ("gl", r"^GL/")]
INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]')


def module_of(path, root):
    """The module a header the preprocessor reaches belongs to, or None for libc and the like."""
    m = re.match(r"verdant/(\w+)\.h$", path)
    if m:
        return m.group(1)
    m = re.match(r"(\w+)/", path)
    if m and os.path.isdir(os.path.join(root, "src", m.group(1))):
        return m.group(1)
    return None


def lib_of(path):
    for name, pat in LIBS:
        if re.search(pat, path):
            return name
    return None


def includes(path):
    with open(path, encoding="utf-8", errors="replace") as f:
        for n, line in enumerate(f, 1):
            m = INCLUDE.match(line)
            if m:
                yield n, m.group(1), m.group(2)


def check(root):
    bad = []
    files = []
    for mod in sorted(os.listdir(os.path.join(root, "src"))):
        d = os.path.join(root, "src", mod)
        if not os.path.isdir(d):
            continue
        if mod not in RULES:
            bad.append(f"src/{mod}/: a module without a row in scripts/check_includes.py (and docs/architecture.md)")
            continue
        files += [(mod, os.path.join(d, f)) for f in sorted(os.listdir(d)) if f.endswith((".c", ".h"))]
        pub = os.path.join(root, "include", "verdant", mod + ".h")
        if os.path.exists(pub):
            files.append((mod, pub))
    for mod, path in files:
        allowed, libs = RULES[mod]
        rel = os.path.relpath(path, root)
        for n, kind, inc in includes(path):
            lib = lib_of(inc)
            if lib:
                if lib not in libs:
                    bad.append(f"{rel}:{n}: {mod} includes {inc} ({lib}); it may include {', '.join(libs) or 'no outside library'}")
                continue
            if kind == "<" and not inc.startswith("verdant/"):
                continue  # libc, POSIX, OpenMP
            other = module_of(inc, root)
            if inc == "verdant/verdant.h":
                bad.append(f"{rel}:{n}: {mod} includes the umbrella verdant/verdant.h; name the modules it uses")
            elif other and other != mod and other not in allowed:
                bad.append(f"{rel}:{n}: {mod} includes {inc} ({other}); it may include {', '.join(allowed) or 'nothing'}")
    # through public headers: what a module's files include must not bring in a module off its row
    for mod, path in files:
        allowed = RULES[mod][0]
        rel = os.path.relpath(path, root)
        for n, _, inc in includes(path):
            first = module_of(inc, root) if inc.startswith("verdant/") else None
            if not first or first == mod or first not in allowed:
                continue
            reach, todo = set(), [first]
            while todo:
                h = todo.pop()
                if h in reach:
                    continue
                reach.add(h)
                p = os.path.join(root, "include", "verdant", h + ".h")
                if os.path.exists(p):
                    todo += [module_of(i, root) for _, _, i in includes(p) if module_of(i, root)]
            for r in sorted(reach - set(allowed) - {mod}):
                bad.append(f"{rel}:{n}: {inc} brings {r} into {mod}, which may include {', '.join(allowed)}")
    return bad


if __name__ == "__main__":
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    bad = check(root)
    for b in bad:
        print(b)
    print(f"include rules: {'ok' if not bad else str(len(bad)) + ' forbidden include(s)'}", file=sys.stderr)
    sys.exit(1 if bad else 0)
