# SPDX-License-Identifier: MIT
"""Plants: growing from files and text, the arrays, stats and files against the command line."""
import json
import os
import pathlib

import numpy as np
import pytest

import verdant
from conftest import data, read

TINY = """LABELS = {1: "stem", 2: "leaf", 3: "fruit"}
module I, Leaf, Fruit
Axiom: SetWidth(0.005) A(6)
derivation length: 7
production:
A(n) :
    if n > 0: produce I(0.05) [ +(50) Leaf(0.06) ] /(137.5) A(n - 1)
    else: produce Fruit(0.012)
interpretation:
I(l) --> ;(1) F(l, 0.004)
Leaf(s) --> ;(2) ~l(s)
Fruit(r) --> ;(3) @O(r)
endlsystem
"""


def test_grow_tomato_arrays():
    p = verdant.grow(data("tomato.lpy"), seed=3)
    assert isinstance(p, verdant.Plant)
    m = len(p.segments)
    assert p.nodes.shape == (len(p.nodes), 3) and p.nodes.dtype == np.float64
    assert p.segments.shape == (m, 2) and p.segments.dtype == np.int32
    assert p.radii.shape == (m, 2) and p.labels.shape == (m,) and p.instances.shape == (m,)
    assert p.frames.shape == (m, 4)
    assert p.spheres.shape == (len(p.sphere_radii), 3)
    assert p.triangles.max() < len(p.vertices)
    assert 0 <= p.segments.min() and p.segments.max() < len(p.nodes)
    assert set(p.label_names) == {1, 2, 3, 4, 5, 6} and p.label_names[5] == "fruit"
    assert p.seed == 3 and p.source.endswith("tomato.lpy")
    # views of the plant's memory: read-only, kept alive by the array
    a = p.nodes
    assert not a.flags.writeable and a.base is p
    with pytest.raises(ValueError):
        a[0, 0] = 1.0
    del p
    assert np.isfinite(a).all()


def test_stats_equal_cli(cli):
    p = verdant.grow(data("tomato.lpy"), seed=3)
    ref = json.loads(cli("grow", data("tomato.lpy"), "--seed", "3", "--stats").stdout)
    assert "seconds" not in ref  # timings only with --profile
    got = p.stats
    assert list(got) == list(ref)
    for k in ref:
        if k in ("bbox_min", "bbox_max"):
            assert got[k] == pytest.approx(ref[k], abs=1e-12)
        elif k == "organs":  # cJSON prints 15 digits when they read back within DBL_EPSILON
            assert list(got[k]) == list(ref[k])
            for name in ref[k]:
                assert got[k][name] == pytest.approx(ref[k][name], rel=1e-14), name
        else:
            assert got[k] == ref[k], k


@pytest.mark.parametrize("ext", ["json", "obj", "ply"])
def test_save_equals_cli(tmp_path, cli, ext):
    p = verdant.grow(data("arabidopsis.lpy"), seed=7, set={"ROSETTE_MAX": 12}, labels={3: "flower"})
    (tmp_path / "py").mkdir()
    (tmp_path / "cli").mkdir()
    p.save(tmp_path / "py" / f"a.{ext}")
    cli("grow", data("arabidopsis.lpy"), "--seed", "7", "--set", "ROSETTE_MAX=12", "--label", "3=flower",
        "-o", tmp_path / "cli" / f"a.{ext}")
    assert read(tmp_path / "py" / f"a.{ext}") == read(tmp_path / "cli" / f"a.{ext}")
    if ext == "obj":  # its material library names the file
        assert read(tmp_path / "py" / "a.mtl") == read(tmp_path / "cli" / "a.mtl")


def test_ascii_ply_and_mesh(tmp_path, cli):
    p = verdant.grow(data("tomato.lpy"), seed=1)
    p.save(str(tmp_path / "a.ply"), ascii=True)
    cli("grow", data("tomato.lpy"), "--seed", "1", "--ascii", "-o", tmp_path / "b.ply")
    assert read(tmp_path / "a.ply") == read(tmp_path / "b.ply")
    m = p.mesh()
    assert m.vertices.shape[1] == 3 and m.triangles.shape[1] == 3
    assert len(m.label) == len(m.triangles) and set(np.unique(m.label)) <= set(p.label_names)
    assert np.allclose(np.linalg.norm(m.normals, axis=1), 1)
    m.save(tmp_path / "m.ply")
    p.save(tmp_path / "c.ply")
    assert read(tmp_path / "m.ply") == read(tmp_path / "c.ply")
    coarse = p.mesh(slices=4)
    assert len(coarse.triangles) < len(m.triangles)


def test_text_and_paths(tmp_path):
    a = verdant.grow(TINY)
    f = tmp_path / "tiny.lpy"
    f.write_text(TINY)
    b = verdant.grow(f)                   # os.PathLike
    c = verdant.grow(str(f).encode())     # bytes path
    for q in (b, c):
        assert np.array_equal(a.nodes, q.nodes) and np.array_equal(a.segments, q.segments)
    assert a.source == "<string>" and b.source == str(f)
    assert a.label_names == {1: "stem", 2: "leaf", 3: "fruit"}
    assert len(a.spheres) == 1 and len(a.mesh_labels) == 6


def test_load_and_json_text(tmp_path):
    p = verdant.grow(data("tomato.lpy"), seed=2)
    p.save(tmp_path / "t.json")
    q = verdant.load(tmp_path / "t.json", seed=2)
    assert np.array_equal(p.nodes, q.nodes) and q.label_names == p.label_names
    r = verdant.grow(read(tmp_path / "t.json").decode())
    assert np.array_equal(p.radii, r.radii)
    q.save(tmp_path / "u.json")
    assert read(tmp_path / "t.json") == read(tmp_path / "u.json")
    assert q.stats["modules"] == 0 and q.stats["module_counts"] == {}


def test_curves(tmp_path, cli):
    p = verdant.grow(data("curves_tomato.json"), curve_distance=0.04)
    p.save(tmp_path / "a.json")
    cli("grow", data("curves_tomato.json"), "--curve-distance", "0.04", "-o", tmp_path / "b.json")
    assert read(tmp_path / "a.json") == read(tmp_path / "b.json")
    with pytest.raises(verdant.ArgumentError):
        verdant.grow(data("tomato.lpy"), curve_step=0.01)


def test_steps_set_seed():
    a = verdant.grow(data("tomato.lpy"), seed=3, steps=5)
    b = verdant.grow(data("tomato.lpy"), seed=3)
    assert len(a.segments) < len(b.segments)
    c = verdant.grow(data("tomato.lpy"), seed=4)
    assert not (len(c.nodes) == len(b.nodes) and np.array_equal(c.nodes, b.nodes))
    d = verdant.grow(data("tomato.lpy"), seed=3, set={"NODES": 10})
    assert len(d.segments) < len(b.segments)
    e = verdant.grow(data("tomato.lpy"), seed=3, set={"NODES": "5 * 2"})
    assert np.array_equal(d.nodes, e.nodes)


def test_python_engine_equals_cli(tmp_path, cli):
    # a file beyond the native subset runs in embedded CPython: inside this interpreter, with the
    # GIL let go while growing; the same plant as the command line's
    p = verdant.grow(data("python_bud.lpy"), seed=4)
    assert p.stats["engine"] == "python"
    p.save(tmp_path / "py.json")
    cli("grow", data("python_bud.lpy"), "--seed", "4", "-o", tmp_path / "cli.json")
    assert read(tmp_path / "py.json") == read(tmp_path / "cli.json")
    assert verdant.grow(data("tomato.lpy"), engine="python").stats["engine"] == "python"
    assert verdant.grow(TINY).stats["engine"] == "native"
    with pytest.raises(verdant.UnsupportedError):
        verdant.grow(data("python_bud.lpy"), engine="native")
    with pytest.raises(verdant.ArgumentError):
        verdant.grow(TINY, engine="jython")


def test_python_engine_in_threads():
    import threading
    ref = verdant.grow(data("python_bud.lpy"), seed=2).nodes.copy()
    out = []
    ts = [threading.Thread(target=lambda: out.append(verdant.grow(data("python_bud.lpy"), seed=2).nodes))
          for _ in range(3)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    assert len(out) == 3 and all(np.array_equal(o, ref) for o in out)


def test_organ_instances_and_traits(tmp_path, cli):
    # one instance per organ by default, as the command line; instances="modules" per module
    organs = verdant.grow(data("tomato.lpy"), seed=3)
    modules = verdant.grow(data("tomato.lpy"), seed=3, instances="modules")
    so, sm = organs.stats, modules.stats
    assert so["labels"]["pedicel"] == so["labels"]["fruit"] + so["labels"]["flower"]
    assert sm["labels"]["pedicel"] == 3 * so["labels"]["pedicel"]
    cli("grow", data("tomato.lpy"), "--seed", "3", "--traits", tmp_path / "t.csv")
    rows = (tmp_path / "t.csv").read_text().splitlines()[1:]
    assert len(rows) == len(organs.traits) == so["instances"]
    assert [int(r.split(",")[0]) for r in rows] == [t["instance"] for t in organs.traits]
    with pytest.raises(verdant.ArgumentError):
        verdant.grow(data("tomato.lpy"), instances="leaves")
