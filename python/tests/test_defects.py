# SPDX-License-Identifier: MIT
"""The defects of issue 23, each with the test that failed before its fix: Cloud.xyz built twice
by two threads, Sim.stress reusing one buffer, writable empty arrays, HarvestEnv.close() keeping
the episode, verdant.render's renderer cache without limit, Ctrl-C ignored during Sim.step(n),
C functions without signatures and no type stubs, FileError without errno, numpy arrays
refused where a list of numbers is taken, and pip's bare "invalid command 'bdist_wheel'"."""
import _thread
import ast
import errno
import inspect
import os
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import verdant
from conftest import SRC, data

PICK = os.path.join(SRC, "data", "scenes", "mini_pick.json")


@pytest.fixture(scope="module")
def tomato():
    return verdant.grow(data("tomato.lpy"), seed=3)


def test_cloud_xyz_one_array_under_a_race(tomato):
    for trial in range(4):
        c = tomato.cloud(points=400000, seed=trial, threads=1)
        got, start = [], threading.Barrier(2)

        def read():
            start.wait()
            got.append(c.xyz)

        ts = [threading.Thread(target=read) for _ in range(2)]
        [t.start() for t in ts]
        [t.join() for t in ts]
        assert got[0] is got[1] and got[0] is c.xyz


def test_stress_arrays_keep_their_values(tomato):
    s = verdant.Sim(tomato)
    s.step(5)
    a = s.stress
    kept = a.copy()
    s.step(20)
    b = s.stress
    assert a is not b and np.array_equal(a, kept) and not np.array_equal(a, b)
    assert not a.flags.writeable or a.base is None


def test_empty_arrays_are_read_only():
    p = verdant.grow("Axiom: F(0.1)\nderivation length: 0\n")
    assert len(p.spheres) == 0 and len(p.mesh_labels) == 0
    for name in ("spheres", "sphere_radii", "mesh_labels", "vertices", "triangles"):
        arr = getattr(p, name)
        assert arr.size == 0 and not arr.flags.writeable, name
        with pytest.raises(ValueError):
            arr[...] = 0
    assert not p.nodes.flags.writeable


def test_close_frees_the_episode():
    b0 = verdant.alloc_bytes()
    env = verdant.HarvestEnv(PICK)
    env.reset(seed=0)
    env.step(np.zeros(7))
    b1 = verdant.alloc_bytes()
    env.close()
    b2 = verdant.alloc_bytes()
    assert b1 - b0 > 100000 and b2 - b0 < 0.01 * (b1 - b0), (b0, b1, b2)
    with pytest.raises(verdant.env.ResetNeeded):
        env.step(np.zeros(7))
    with pytest.raises(verdant.Error):
        env._h.observe()


def test_render_cache_is_bounded(tomato):
    try:
        verdant.Renderer(size=(8, 8))
    except verdant.UnsupportedError as e:
        pytest.skip(f"no OpenGL context: {e}")
    import verdant as v

    def cache():
        return getattr(v._local, "renderers", {})

    for k in range(7):
        v.render(tomato, size=(16 + k, 12), masks=False, depth=False, legend=False)
        assert len(cache()) <= v.RENDERER_CACHE
    assert len(cache()) == v.RENDERER_CACHE
    assert (16 + 6, 12) in [key[0] for key in cache()]            # the latest is kept


def test_ctrl_c_stops_a_long_step(tomato):
    s = verdant.Sim(tomato)
    s.step(20)
    t0 = time.perf_counter()
    s.step(200)
    per_step = (time.perf_counter() - t0) / 200
    n = int(30.0 / per_step)                                       # about 30 s of steps
    timer = threading.Timer(0.3, _thread.interrupt_main)
    timer.start()
    t0 = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        s.step(n)
    took = time.perf_counter() - t0
    timer.join()
    assert took < 10 and 220 < s.nstep < 220 + n                  # stopped between steps
    s.step(3)                                                      # and usable again


def c_callables():
    """Every function of the extension and every method of its types."""
    m = verdant._verdant
    for name in dir(m):
        obj = getattr(m, name)
        if callable(obj) and type(obj).__name__ == "builtin_function_or_method":
            yield name, obj
        elif isinstance(obj, type) and obj.__module__ == "verdant._verdant" and not issubclass(obj, Exception):
            yield name, obj
            for k, v in vars(obj).items():
                if type(v).__name__ == "method_descriptor" and not k.startswith("__"):
                    yield f"{name}.{k}", v


def test_every_c_function_has_a_signature():
    missing = []
    for name, f in c_callables():
        try:
            inspect.signature(f)
        except (ValueError, TypeError):
            missing.append(name)
    assert not missing, missing
    assert list(inspect.signature(verdant._verdant.Sim.step).parameters) == ["self", "n"]
    assert "seed" in inspect.signature(verdant._verdant.grow).parameters


def test_type_stubs_shipped_and_complete():
    here = os.path.dirname(verdant.__file__)
    assert os.path.exists(os.path.join(here, "py.typed"))
    tree = ast.parse(open(os.path.join(here, "_verdant.pyi")).read())
    names = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    names |= {t.id for n in tree.body if isinstance(n, ast.AnnAssign) for t in [n.target]}
    public = {n for n in dir(verdant._verdant) if not n.startswith("__")}
    assert public - names == set()
    classes = {n.name: n for n in tree.body if isinstance(n, ast.ClassDef)}
    for name, f in c_callables():
        if "." in name:
            cls, meth = name.split(".")
            assert meth in {m.name for m in classes[cls].body if isinstance(m, ast.FunctionDef)}, name


def test_file_error_has_errno(tmp_path):
    with pytest.raises(verdant.FileError) as e:
        verdant.load(tmp_path / "none.json")
    assert e.value.errno == errno.ENOENT and e.value.filename == str(tmp_path / "none.json")
    assert isinstance(e.value, OSError) and "none.json" in str(e.value)
    (tmp_path / "dir.json").mkdir()
    with pytest.raises(verdant.FileError) as e:
        verdant.load(tmp_path / "dir.json")
    assert e.value.errno == errno.EISDIR


def test_numpy_numbers_accepted(tomato):
    c = tomato.cloud(points=np.int64(2000), scanners=np.array([[1.0, 0.0, 0.5], [0.0, 1.0, 0.5]]),
                     noise=np.float64(0.001), seed=np.int32(1), threads=1)
    ref = tomato.cloud(points=2000, scanners=[(1.0, 0.0, 0.5), (0.0, 1.0, 0.5)], noise=0.001,
                       seed=1, threads=1)
    assert np.array_equal(c.pos, ref.pos)
    s = verdant.Sim(tomato)
    k = s.add_collider("sphere", np.float64(0.02), pos=np.array([0.3, 0, 0.2]),
                       quat=np.array([1.0, 0, 0, 0]))
    s.move_collider(k, np.array([0.31, 0, 0.2], np.float32))
    node = s.apply_force("fruit", np.array([0, 0, -1.0]))
    s.add_tie(np.int64(node), np.array([0.1, 0.1, 0.5]))
    s.step(np.int64(2))


def test_pip_without_wheel_says_how(tmp_path):
    block = ("import sys, runpy; "
             "[sys.modules.__setitem__(m, None) for m in "
             "('wheel', 'wheel.bdist_wheel', 'setuptools.command.bdist_wheel')]; "
             "sys.argv = ['setup.py', 'bdist_wheel']; "
             f"runpy.run_path({os.path.join(SRC, 'python', 'setup.py')!r}, run_name='__main__')")
    r = subprocess.run([sys.executable, "-c", block], capture_output=True, text=True,
                       cwd=tmp_path)
    assert r.returncode != 0 and "pip install wheel" in r.stderr and "invalid command" not in r.stderr
