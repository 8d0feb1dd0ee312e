#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""L-Py conformance runner: verdant on the .lpy files and unit tests of an openalea/lpy checkout.

    python3 bench/lpy_suite.py /path/to/lpy [--verdant build/verdant] [--jobs 2] [--csv FILE]

1. Every .lpy file under share/ and test/lpytest/ is grown with `verdant grow` (engine chosen
   automatically, run from the file's folder as L-Py does) and counted as
   ok        the derivation, interpretation and turtle ran (the file's own asserts in its hooks
             and rule bodies passed),
   refused   exit 2 with an `unsupported: ...` message naming the construct,
   failed    any other error (a Python exception in the file, a syntax error, ...),
   crashed   killed by a signal, or over the time limit: --timeout seconds of CPU time (user +
             system, so a busy machine does not count a file as crashed), or ten times that of
             wall-clock time for a process that waits without computing.
2. The L-Py unit tests that check the language (test_matching.py, test_fibonacci.py,
   test_nproduce.py, test_endeach.py, test_kwd.py, test_starmatching.py, test_regexpmatching.py)
   are run unchanged, with an `openalea.lpy` module written here whose Lsystem runs the
   verdant command line (`--lstring` gives the derived string back): each test function passes
   when its asserts hold.

L-Py's files are read from the checkout and never copied. The summary goes to stdout, one line
per file or test to the CSV file.
"""
import argparse
import concurrent.futures
import contextlib
import csv
import importlib
import inspect
import json
import os
import re
import resource
import signal
import subprocess
import sys
import tempfile
import textwrap
import threading
import traceback
import types
import warnings

UNIT_TESTS = ["test_matching.py", "test_fibonacci.py", "test_nproduce.py", "test_endeach.py",
              "test_kwd.py", "test_starmatching.py", "test_regexpmatching.py"]

VERDANT = "verdant"
TIMEOUT = 60      # CPU seconds per run
WALL_FACTOR = 10  # a run that waits (no CPU) is stopped after WALL_FACTOR * TIMEOUT wall seconds


def run_limited(cmd, cwd):
    """Run cmd in cwd under TIMEOUT seconds of CPU time (RLIMIT_CPU: SIGXCPU, then SIGKILL 5 s
    later) and WALL_FACTOR * TIMEOUT seconds of wall-clock time. Returns (rc, stdout, stderr,
    cpu seconds, over the limit); rc is -signal when a signal ended it."""
    def limit():
        resource.setrlimit(resource.RLIMIT_CPU, (TIMEOUT, TIMEOUT + 5))

    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        p = subprocess.Popen(cmd, cwd=cwd, stdout=out, stderr=err, preexec_fn=limit)
        lock, state = threading.Lock(), {"done": False, "walled": False}

        def wall_kill():
            with lock:
                if not state["done"]:
                    state["walled"] = True
                    os.kill(p.pid, signal.SIGKILL)

        timer = threading.Timer(WALL_FACTOR * TIMEOUT, wall_kill)
        timer.start()
        _, status, ru = os.wait4(p.pid, 0)
        with lock:
            state["done"] = True
        timer.cancel()
        rc = os.waitstatus_to_exitcode(status)
        p.returncode = rc  # reaped here (wait4 gives its CPU time): Popen must not wait again
        cpu = ru.ru_utime + ru.ru_stime
        over = state["walled"] or rc in (-signal.SIGXCPU, -signal.SIGKILL) and cpu >= TIMEOUT
        out.seek(0)
        err.seek(0)
        text = [f.read().decode("utf-8", "replace") for f in (out, err)]
    if over:
        what = "%d s of wall-clock time" % (WALL_FACTOR * TIMEOUT) if state["walled"] else "%d s of CPU time" % TIMEOUT
        text[1] += "\nno answer within %s (%.1f s of CPU used)" % (what, cpu)
    return rc, text[0], text[1], cpu, over


# ---------------------------------------------------------------------------------------------
# the .lpy files

def classify(rc, err, timed_out):
    """ok, refused, failed or crashed (see the module's comment)."""
    if timed_out or rc < 0 or rc > 128:
        return "crashed"
    if rc == 0:
        return "ok"
    if rc == 2 and "unsupported" in err:
        return "refused"
    return "failed"


def reason(err):
    """The last line of the error, without the command name."""
    lines = [x for x in err.strip().splitlines() if x and not x.startswith("warning")]
    line = lines[-1] if lines else ""
    return re.sub(r"^verdant grow: ", "", line)[:300]


def run_file(root, rel):
    path = os.path.join(root, rel)
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [VERDANT, "grow", os.path.basename(path), "-o", os.path.join(tmp, "plant.json"),
               "--stats", "--no-progress", "--max-modules", "5000000"]
        rc, out, err, cpu, to = run_limited(cmd, os.path.dirname(path))
    engine = ""
    if rc == 0:
        try:
            engine = json.loads(out).get("engine", "")
        except ValueError:
            pass
    else:
        m = re.search(r"\(engine (\w+)\)", err)
        engine = m.group(1) if m else ""
    return rel, classify(rc, err, to), engine, reason(err) if rc else "", cpu


def lpy_files(root):
    files = []
    for top in ("share", os.path.join("test", "lpytest")):
        for d, _, names in os.walk(os.path.join(root, top)):
            files += [os.path.relpath(os.path.join(d, n), root) for n in names if n.endswith(".lpy")]
    return sorted(files)


# ---------------------------------------------------------------------------------------------
# the unit tests: an openalea.lpy module over the verdant command line

class Module:
    """A module of a derived L-string: name and parameters."""

    def __init__(self, name, args):
        self.name = name
        self.args = list(args)

    def __getitem__(self, i):
        return self.args[i]

    def __len__(self):
        return len(self.args)

    def __eq__(self, other):
        return isinstance(other, Module) and (self.name, self.args) == (other.name, other.args)

    def __repr__(self):
        if not self.args:
            return self.name
        return "%s(%s)" % (self.name, ",".join(repr(a) for a in self.args))


class AxialTree(list):
    """A derived L-string: a list of modules."""

    def __str__(self):
        return "".join(repr(m) for m in self)

    __repr__ = __str__


class Options:
    def __init__(self):
        self.values = {}

    def setSelection(self, name, value):
        self.values[name] = value


class Context:
    """What the tests set on a context: options, and globals given to the file. A function of
    the file read back (l.context()['check']) runs inside verdant: the last run again, with
    `--call NAME` after it (the same seed gives the same run)."""

    def __init__(self, lsystem):
        self.options = Options()
        self.names = {}
        self.lsystem = lsystem

    def __setitem__(self, name, value):
        self.names[name] = value

    def __getitem__(self, name):
        if name in self.names:
            return self.names[name]
        if self.lsystem.last_run is None:
            raise KeyError("%s: the file's objects stay inside verdant (run it first)" % name)
        return lambda: self.lsystem._run(*self.lsystem.last_run, call=name)


class LsystemError(Exception):
    pass


class Lsystem:
    def __init__(self, filename=None):
        self.code = ""
        self.filename = filename
        if filename:
            with open(filename, encoding="utf-8") as f:
                self.code = f.read()
        self._context = Context(self)
        self.last_run = None

    def set(self, code):
        self.code = code

    def context(self):
        return self._context

    def _text(self, axiom=None):
        # globals given through context(): functions by their source, values as assignments
        # at the top (and --set, which replaces the file's own assignment, see _run)
        head = []
        for name, value in self._context.names.items():
            if callable(value):
                head.append(textwrap.dedent(inspect.getsource(value)))
            else:
                head.append("%s = %r" % (name, value))
        code = self.code
        if axiom is not None:
            # replace the axiom (a line, or a line and its indented block)
            lines, out, skip = code.split("\n"), [], False
            for line in lines:
                if skip and (not line.strip() or line[:1] in " \t"):
                    continue
                skip = False
                m = re.match(r"^\s*[Aa]xiom\s*:(.*)$", line)
                if m:
                    skip = not m.group(1).strip()
                    out.append("Axiom: " + axiom)
                else:
                    out.append(line)
            code = "\n".join(out)
        opts = "".join("\tcontext.options.setSelection(%r, %r)\n" % kv
                       for kv in self._context.options.values.items())
        text = "\n".join(head) + "\n" + code + "\n"
        if opts:
            if "INITIALISATION" in text and "__initialiseContext__" in text:
                text = text.rstrip("\n") + "\n" + opts
            else:
                text += "###### INITIALISATION ######\ndef __initialiseContext__(context):\n" + opts
        return text

    def _run(self, steps=None, axiom=None, animate=False, call=None):
        self.last_run = (steps, axiom, animate)
        with tempfile.TemporaryDirectory() as tmp:
            src = os.path.join(tmp, "model.lpy")
            with open(src, "w", encoding="utf-8") as f:
                f.write(self._text(axiom))
            cmd = [VERDANT, "grow", src, "-o", os.path.join(tmp, "plant.json"), "--lstring",
                   os.path.join(tmp, "lstring.json"), "--no-progress"]
            if steps is not None:
                cmd += ["-n", str(steps)]
            if animate:
                cmd += ["--animate"]
            if call:
                cmd += ["--call", call]
            for name, value in self._context.names.items():
                if not callable(value) and re.search(r"^%s\s*=" % re.escape(name), self.code, re.M):
                    cmd += ["--set", "%s=%r" % (name, value)]
            cwd = os.path.dirname(self.filename) if self.filename else tmp
            rc, _, err, _, _ = run_limited(cmd, cwd)
            if rc:
                raise LsystemError(reason(err))
            with open(os.path.join(tmp, "lstring.json"), encoding="utf-8") as f:
                mods = json.load(f)["modules"]
        return AxialTree(Module(m[0], m[1:]) for m in mods)

    def iterate(self, *args):
        return self.derive(*args)

    def derive(self, *args):
        if args and isinstance(args[0], AxialTree):
            # derive(string, [start,] steps): from a given string (iteration numbers restart at 0)
            steps = args[-1] if len(args) > 1 else None
            return self._run(steps, str(args[0]) or "")
        return self._run(args[0] if args else None)

    def animate(self, *args):
        # L-Py's animate(dt): interpret after every step (the time step is for a viewer)
        return self._run(None, None, True)

    @property
    def axiom(self):
        return self._run(0)


class PatternModule:
    """The values of the 'Module matching' option."""
    eSimple, eWithStar, eWithStarNValueConstraint = 0, 1, 2


def lpy_module():
    """The openalea.lpy stand-in the unit tests import."""
    lpy = types.ModuleType("openalea.lpy")
    lpy.PatternModule = PatternModule
    lpy.Lsystem = Lsystem
    lpy.AxialTree = AxialTree
    lpy.Lstring = AxialTree
    lpy.registerPlotter = lambda plotter: None
    lpy.cleanPlotter = lambda: None
    lpy.__all__ = ["Lsystem", "AxialTree", "Lstring", "PatternModule"]
    pkg = types.ModuleType("openalea")
    pkg.__path__ = []
    pkg.lpy = lpy
    return pkg, lpy


def run_unit_tests(root):
    testdir = os.path.join(root, "test")
    pkg, lpy = lpy_module()
    saved = {k: sys.modules.get(k) for k in ("openalea", "openalea.lpy")}
    sys.modules["openalea"], sys.modules["openalea.lpy"] = pkg, lpy
    sys.path.insert(0, testdir)
    results = []
    try:
        for fname in UNIT_TESTS:
            modname = fname[:-3]
            try:
                mod = importlib.import_module(modname)
            except Exception as e:  # noqa: BLE001 - a test file that does not import is a result
                results.append((fname, "(import)", "failed", str(e)[:300]))
                continue
            for name, fn in sorted(inspect.getmembers(mod, inspect.isfunction),
                                   key=lambda kv: kv[1].__code__.co_firstlineno):
                if not name.startswith("test") or fn.__module__ != modname:
                    continue
                try:
                    with open(os.devnull, "w") as null, contextlib.redirect_stdout(null), \
                            warnings.catch_warnings():
                        warnings.simplefilter("ignore")
                        fn()
                    results.append((fname, name, "passed", ""))
                except Exception as e:  # noqa: BLE001
                    msg = str(e) or traceback.format_exception_only(type(e), e)[-1].strip()
                    results.append((fname, name, "failed", msg.splitlines()[-1][:300] if msg else ""))
    finally:
        sys.path.remove(testdir)
        for k, v in saved.items():
            if v is None:
                sys.modules.pop(k, None)
            else:
                sys.modules[k] = v
    return results


# ---------------------------------------------------------------------------------------------

def main():
    global VERDANT, TIMEOUT
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("lpy", help="an openalea/lpy checkout")
    ap.add_argument("--verdant", default=os.path.join(os.path.dirname(__file__), "..", "build", "verdant"))
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--timeout", type=int, default=60,
                    help="CPU seconds per run (default 60; a run that waits without computing is "
                         "stopped after ten times that of wall-clock time)")
    ap.add_argument("--csv", help="write one line per file and unit test")
    ap.add_argument("--files-only", action="store_true")
    ap.add_argument("--tests-only", action="store_true")
    a = ap.parse_args()
    VERDANT, TIMEOUT = os.path.abspath(a.verdant), a.timeout
    rows = []
    if not a.tests_only:
        files = lpy_files(a.lpy)
        with concurrent.futures.ThreadPoolExecutor(a.jobs) as ex:
            res = list(ex.map(lambda rel: run_file(a.lpy, rel), files))
        counts = {}
        for rel, cls, engine, why, cpu in res:
            counts[cls] = counts.get(cls, 0) + 1
            rows.append(("file", rel, cls, engine, why, "%.2f" % cpu))
        by_engine = {}
        for _, cls, engine, _, _ in res:
            if cls == "ok":
                by_engine[engine] = by_engine.get(engine, 0) + 1
        print("files: %d  ok %d (%s)  refused %d  failed %d  crashed %d" % (
            len(res), counts.get("ok", 0), ", ".join("%s %d" % kv for kv in sorted(by_engine.items())),
            counts.get("refused", 0), counts.get("failed", 0), counts.get("crashed", 0)))
        print("CPU time: %.1f s in all, the most %.1f s (%s)" % (
            sum(r[4] for r in res), max(r[4] for r in res), max(res, key=lambda r: r[4])[0]))
        for rel, cls, engine, why, _ in res:
            if cls != "ok":
                print("  %-8s %s: %s" % (cls, rel, why))
    if not a.files_only:
        tests = run_unit_tests(a.lpy)
        passed = sum(1 for t in tests if t[2] == "passed")
        print("unit tests: %d of %d passed" % (passed, len(tests)))
        for fname, name, cls, why in tests:
            rows.append(("test", "%s::%s" % (fname, name), cls, "", why, ""))
            if cls != "passed":
                print("  failed   %s::%s: %s" % (fname, name, why))
    if a.csv:
        with open(a.csv, "w", newline="", encoding="utf-8") as f:
            w = csv.writer(f)
            w.writerow(["kind", "name", "result", "engine", "reason", "cpu_s"])
            w.writerows(rows)


if __name__ == "__main__":
    main()
