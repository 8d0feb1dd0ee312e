# SPDX-License-Identifier: MIT
"""Clouds: the same bytes as `verdant cloud` for the same options, views without copies, files,
the GIL released while sampling, Open3D when it is installed."""
import threading

import numpy as np
import pytest

import verdant
from conftest import data, read

# (Plant.cloud keywords, the same as command-line flags)
CASES = [
    ({"points": 20000}, ["--points", "20000"]),
    ({"points": 5000, "seed": 11, "threads": 1, "slices": 6}, ["--points", "5000", "--cloud-seed", "11", "--threads", "1", "--slices", "6"]),
    ({"points": 5000, "labels": "instance", "interior": False}, ["--points", "5000", "--labels", "instance", "--no-interior"]),
    ({"points": 8000, "sensor": "distance", "scanners": [(1.5, 0, 0.8), (-1, 1, 1, 0, 0, 0.5)], "occlusion": True,
      "noise": (0.0005, 0.001), "density_law": [(0.5, 1), (2, 0.2)]},
     ["--points", "8000", "--sensor", "distance", "--scanner", "1.5,0,0.8", "--scanner", "-1,1,1,0,0,0.5",
      "--occlusion", "--noise", "0.0005,0.001", "--density-law", "table:0.5:1,2:0.2"]),
    ({"sensor": "scan", "scanners": [(1.2, 0.3, 0.7)], "pattern": "pinhole", "fov": (50, 40), "res": (64, 48)},
     ["--sensor", "scan", "--scanner", "1.2,0.3,0.7", "--pattern", "pinhole", "--fov", "50,40", "--res", "64,48"]),
    ({"sensor": "scan", "scanners": data("scanners/turntable8.json"), "res": (40, 30)},
     ["--sensor", "scan", "--scanners", data("scanners/turntable8.json"), "--res", "40,30"]),
]


@pytest.mark.parametrize("kw,flags", CASES)
@pytest.mark.parametrize("ext", ["ply"])
def test_cloud_bytes_equal_cli(tmp_path, cli, kw, flags, ext):
    p = verdant.grow(data("tomato.lpy"), seed=3)
    c = p.cloud(**kw)
    c.save(tmp_path / f"py.{ext}")
    cli("cloud", data("tomato.lpy"), "--seed", "3", *flags, "-o", tmp_path / f"cli.{ext}")
    assert read(tmp_path / f"py.{ext}") == read(tmp_path / f"cli.{ext}")


@pytest.mark.parametrize("ext,flags", [("pcd", []), ("las", []), ("xyz", []), ("csv", []),
                                        ("ply", ["--ascii"]), ("ply", ["--ply-scalar-prefix"])])
def test_formats_equal_cli(tmp_path, cli, ext, flags):
    c = verdant.grow(data("arabidopsis.lpy"), seed=5).cloud(points=3000)
    c.save(tmp_path / f"py.{ext}", ascii="--ascii" in flags,
           ply_prefix="scalar_" if "--ply-scalar-prefix" in flags else None)
    cli("cloud", data("arabidopsis.lpy"), "--seed", "5", "--points", "3000", *flags, "-o", tmp_path / f"cli.{ext}")
    assert read(tmp_path / f"py.{ext}") == read(tmp_path / f"cli.{ext}")


def test_arrays_are_views():
    p = verdant.grow(data("tomato.lpy"), seed=3)
    c = p.cloud(points=100000)
    assert c.xyz.shape == (100000, 3) and c.xyz.dtype == np.float32
    assert set(c.label) == {1, 2, 3, 4, 5, 6} and len(c) == 100000
    for name, shape, dtype in (("pos", (100000, 3), np.float64), ("normals", (100000, 3), np.float64),
                               ("label", (100000,), np.int32), ("instance", (100000,), np.int32),
                               ("view", (100000,), np.int32), ("range", (100000,), np.float64)):
        a = getattr(c, name)
        assert a.shape == shape and a.dtype == dtype and a.base is c and not a.flags.writeable, name
    # two views of one array share the library's memory; xyz is one float32 copy, made once
    assert np.shares_memory(c.pos, c.pos) and c.xyz is c.xyz
    assert np.array_equal(c.xyz, c.pos.astype(np.float32))
    assert np.allclose(np.linalg.norm(c.normals, axis=1), 1)
    assert c.labels == p.label_names and c.seed == 3 and c.stats["drawn"] >= 100000
    assert c.nview == 0 and not c.view.any()
    # the arrays outlive the Python names of their owners
    label = c.label
    del c, p
    assert label.sum() > 0


def test_read_cloud_round_trip(tmp_path):
    c = verdant.grow(data("tomato.lpy"), seed=1).cloud(points=2000, scanners=[(1, 0, 0.5)])
    for ext in ("ply", "pcd", "las", "csv"):
        c.save(tmp_path / f"c.{ext}")
        r = verdant.read_cloud(tmp_path / f"c.{ext}")
        assert len(r) == 2000 and np.array_equal(r.label, c.label) and np.array_equal(r.instance, c.instance)
        assert np.allclose(r.pos, c.pos, atol=1e-3)


def test_seeds_and_threads():
    p = verdant.grow(data("tomato.lpy"), seed=3)
    a = p.cloud(points=10000, threads=1)
    b = p.cloud(points=10000, threads=2)
    c = p.cloud(points=10000, seed=4)
    assert np.array_equal(a.pos, b.pos) and np.array_equal(a.label, b.label)
    assert not np.array_equal(a.pos, c.pos)


def test_threads_sample_in_parallel():
    # the GIL is released while sampling: threads run their own clouds side by side, and the
    # results are the ones a single thread gets
    p = verdant.grow(data("tomato.lpy"), seed=3)
    ref = {s: p.cloud(points=20000, seed=s, threads=1).pos.copy() for s in range(4)}
    out = {}

    def work(s):
        out[s] = p.cloud(points=20000, seed=s, threads=1).pos

    ts = [threading.Thread(target=work, args=(s,)) for s in range(4)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    assert all(np.array_equal(out[s], ref[s]) for s in range(4))


def test_open3d():
    o3d = pytest.importorskip("open3d")
    p = verdant.grow(data("tomato.lpy"), seed=3)
    pc = p.cloud(points=5000).to_open3d()
    assert isinstance(pc, o3d.geometry.PointCloud) and len(pc.points) == 5000 and pc.has_normals()
    assert np.asarray(pc.colors).shape == (5000, 3)
    m = p.to_open3d()
    assert len(m.triangles) == len(p.mesh().triangles) and m.has_vertex_colors()
    assert len(m.sample_points_uniformly(number_of_points=1000).points) == 1000
