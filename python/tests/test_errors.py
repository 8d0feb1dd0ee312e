# SPDX-License-Identifier: MIT
"""Errors: library failures raise verdant.Error subclasses with file, line, column and message
(the command line's text); bad arguments raise TypeError or verdant.ArgumentError, never crash."""
import os

import numpy as np
import pytest

import verdant
from conftest import data


def test_syntax_error_location(tmp_path, cli):
    bad = tmp_path / "bad.lpy"
    bad.write_text("Axiom: A\nproduction:\nA --> B(1 +)\nendlsystem\n")
    with pytest.raises(verdant.ParseError) as e:
        verdant.grow(bad)
    err = e.value
    assert isinstance(err, verdant.Error)
    assert err.status == "syntax" and err.file == str(bad) and err.line == 3 and err.column > 0
    assert err.message and str(err) == f"{bad}:{err.line}:{err.column}: {err.message}"
    # the command line says the same
    r = cli("grow", bad, "-o", tmp_path / "x.json", check=False)
    assert r.returncode == 2 and r.stderr.strip() == f"verdant grow: {err}"
    # text: the name is <string>
    with pytest.raises(verdant.ParseError) as e:
        verdant.grow("Axiom: A\nproduction:\nA --> B(1 +)\n")
    assert e.value.file == "<string>" and e.value.line == 3


def test_error_classes():
    with pytest.raises(verdant.FileError) as e:
        verdant.grow("/nonexistent/plant.lpy")
    assert isinstance(e.value, OSError) and e.value.file == "/nonexistent/plant.lpy"
    with pytest.raises(verdant.UndefinedNameError):
        verdant.grow(data("tomato.lpy"), set={"NO_SUCH_GLOBAL": 1})
    with pytest.raises(verdant.LimitError):
        verdant.grow(data("tomato.lpy"), max_modules=10)
    with pytest.raises(verdant.FormatError):
        verdant.grow('{"format": "verdant-plant", "version": 1, "nodes": "x"}\n')
    assert issubclass(verdant.ArgumentError, ValueError)
    assert issubclass(verdant.BadValueError, ValueError)
    assert issubclass(verdant.WrongTypeError, TypeError)
    assert issubclass(verdant.OutOfMemoryError, MemoryError)


BAD_GROW = [
    ((42,), {}, TypeError),
    ((None,), {}, TypeError),
    (("",), {}, verdant.ArgumentError),
    (("a\0b",), {}, verdant.ArgumentError),
    (("x" * 5000,), {}, verdant.ArgumentError),
    ((data("tomato.lpy"),), {"seed": -1}, verdant.ArgumentError),
    ((data("tomato.lpy"),), {"seed": 2 ** 70}, verdant.ArgumentError),
    ((data("tomato.lpy"),), {"seed": 1.5}, TypeError),
    ((data("tomato.lpy"),), {"seed": "3"}, TypeError),
    ((data("tomato.lpy"),), {"seed": True}, TypeError),
    ((data("tomato.lpy"),), {"steps": -2}, verdant.ArgumentError),
    ((data("tomato.lpy"),), {"set": [1]}, TypeError),
    ((data("tomato.lpy"),), {"set": {1: 2}}, TypeError),
    ((data("tomato.lpy"),), {"set": {"NODES": object()}}, TypeError),
    ((data("tomato.lpy"),), {"set": {"NODES": "1 +"}}, verdant.ParseError),
    ((data("tomato.lpy"),), {"labels": {"a": "b"}}, TypeError),
    ((data("tomato.lpy"),), {"labels": {70000: "b"}}, verdant.ArgumentError),
    ((data("tomato.lpy"),), {"labels": {3: 4}}, TypeError),
    ((data("tomato.lpy"),), {"labels": {3: ""}}, verdant.ArgumentError),
    ((data("tomato.lpy"),), {"max_modules": 0}, verdant.ArgumentError),
    ((data("tomato.lpy"),), {"curve_step": float("nan")}, verdant.ArgumentError),
    ((data("tomato.lpy"),), {"bogus": 1}, TypeError),
]


@pytest.mark.parametrize("args,kw,exc", BAD_GROW)
def test_bad_grow_arguments(args, kw, exc):
    with pytest.raises(exc):
        verdant._verdant.grow(*args, **kw)


BAD_CLOUD = [
    ({"points": 0}, verdant.ArgumentError),
    ({"points": -5}, verdant.ArgumentError),
    ({"points": 1e3}, TypeError),
    ({"points": "many"}, TypeError),
    ({"sensor": "lidar"}, verdant.ArgumentError),
    ({"sensor": 1}, TypeError),
    ({"sensor": "distance"}, verdant.ArgumentError),        # needs scanners
    ({"occlusion": True}, verdant.ArgumentError),           # needs scanners
    ({"scanners": 5}, TypeError),
    ({"scanners": [(1, 2)]}, TypeError),
    ({"scanners": [(1, 2, "z")]}, TypeError),
    ({"scanners": [(1, 2, float("inf"))]}, verdant.ArgumentError),
    ({"scanners": [(0, 0, 0, 0, 0, 0)]}, verdant.ArgumentError),
    ({"scanners": ["/nonexistent.json"]}, verdant.FileError),
    ({"noise": -1}, verdant.ArgumentError),
    ({"noise": (0.001, 0.01)}, verdant.ArgumentError),      # a slope needs scanners
    ({"noise": (1, 2, 3)}, TypeError),
    ({"density_law": "linear"}, verdant.ArgumentError),     # only with sensor='distance'
    ({"sensor": "distance", "scanners": [(1, 0, 1)], "density_law": [(1, 1)]}, verdant.ArgumentError),
    ({"sensor": "distance", "scanners": [(1, 0, 1)], "density_law": "steep"}, verdant.ArgumentError),
    ({"pattern": "pinhole"}, verdant.ArgumentError),        # only with sensor='scan'
    ({"sensor": "scan", "scanners": [(1, 0, 1)], "points": 5}, verdant.ArgumentError),
    ({"sensor": "scan", "scanners": [(1, 0, 1)], "fov": (0, 10)}, verdant.ArgumentError),
    ({"sensor": "scan", "scanners": [(1, 0, 1)], "res": (1.5, 10)}, verdant.ArgumentError),
    ({"labels": "organ"}, verdant.ArgumentError),
    ({"slices": 2}, verdant.ArgumentError),
    ({"threads": 0}, verdant.ArgumentError),
    ({"seed": -3}, verdant.ArgumentError),
    ({"points": 10 ** 6, "max_points": 1000}, verdant.LimitError),
    ({"pts": 10}, TypeError),
]


@pytest.fixture(scope="module")
def tomato():
    return verdant.grow(data("tomato.lpy"), seed=3)


@pytest.mark.parametrize("kw,exc", BAD_CLOUD)
def test_bad_cloud_arguments(tomato, kw, exc):
    with pytest.raises(exc):
        tomato._cloud(**kw)


def test_bad_files(tmp_path, tomato):
    c = tomato.cloud(points=100)
    for bad in ("x.txt", "noext", tmp_path):
        with pytest.raises(verdant.ArgumentError):
            c.save(bad)
    with pytest.raises(verdant.FileError):
        c.save("/nonexistent/dir/c.ply")
    with pytest.raises(verdant.ArgumentError):
        c.save(tmp_path / "c.ply", comment="two\nlines")
    with pytest.raises(verdant.ArgumentError):
        tomato.save(tmp_path / "p.stl")
    with pytest.raises(verdant.ArgumentError):
        verdant.load(data("tomato.lpy"))
    (tmp_path / "junk.ply").write_bytes(b"ply\nformat nonsense\n")
    with pytest.raises(verdant.Error):
        verdant.read_cloud(tmp_path / "junk.ply")
    assert not [f for f in os.listdir(tmp_path) if ".tmp." in f]


def test_not_constructible_or_picklable(tomato):
    import pickle
    with pytest.raises(TypeError):
        verdant.Plant()
    # plants and clouds pickle (test_state.py); a Sim and a Renderer do not
    with pytest.raises(TypeError):
        pickle.dumps(verdant.Sim(tomato))
    with pytest.raises(verdant.ArgumentError):
        verdant._verdant._cloud_unpickle(b"junk", {})
    with pytest.raises(TypeError):
        tomato.cloud(100)
    with pytest.raises(TypeError):
        tomato.mesh(slices=2.5)
    with pytest.raises(verdant.ArgumentError):
        tomato.mesh(slices=2)
    with pytest.raises(verdant.ArgumentError):
        verdant._verdant._register(plant=int)
    with pytest.raises(verdant.ArgumentError):
        verdant._verdant._register(plant=verdant.Cloud)
