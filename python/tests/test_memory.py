# SPDX-License-Identifier: MIT
"""Reference counts and memory stay flat over 10,000 calls of each kind (success and failure)."""
import gc
import os
import sys

import numpy as np
import pytest

import verdant
from test_plant import TINY

N = 10000
# under the sanitizers (make test SANITIZE=1) freed memory sits in quarantine: RSS is not checked
RSS_LIMIT = float("inf") if os.environ.get("VERDANT_SANITIZE") else 4096


def rss_kib():
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    return 0


def run(fn, n=N):
    """Call fn n times after a warm-up; returns (library bytes, RSS KiB, gc objects) growth."""
    for _ in range(200):
        fn()
    gc.collect()
    b0, r0, o0 = verdant.alloc_bytes(), rss_kib(), len(gc.get_objects())
    for _ in range(n):
        fn()
    gc.collect()
    return verdant.alloc_bytes() - b0, rss_kib() - r0, len(gc.get_objects()) - o0


def test_grow_cloud_arrays_flat():
    plant = verdant.grow(TINY)
    refs = sys.getrefcount(plant)

    def once():
        p = verdant.grow(TINY, seed=1, labels={4: "bud"})
        c = p.cloud(points=64, threads=1)
        a, b, x = c.pos, c.label, c.xyz
        assert a.base is c and b.shape == (64,) and x.dtype == np.float32
        m = p.mesh()
        t = m.triangles
        n = plant.nodes + plant.radii[:, :1].sum()
        del a, b, x, c, p, n, m, t
        _ = plant.stats

    grown, rss, objs = run(once)
    assert grown == 0, f"library memory grew by {grown} bytes"
    assert rss < RSS_LIMIT, f"RSS grew by {rss} KiB over {N} calls"
    assert abs(objs) < 50, f"{objs} more live objects"
    assert sys.getrefcount(plant) == refs


def test_errors_flat(tmp_path):
    bad = "Axiom: A\nproduction:\nA --> B(1 +)\n"

    def once():
        for call in (lambda: verdant.grow(bad), lambda: verdant.grow(TINY, seed=-1),
                     lambda: verdant.grow("/nonexistent.lpy"),
                     lambda: verdant.grow(TINY, set={"NOPE": 1})):
            try:
                call()
            except (verdant.Error, ValueError, TypeError) as e:
                del e
            else:
                raise AssertionError("no error")

    grown, rss, objs = run(once, N // 4)
    assert grown == 0 and rss < RSS_LIMIT and abs(objs) < 50, (grown, rss, objs)


def test_library_memory_returns_to_zero():
    # everything the library allocated for objects that are gone is given back
    gc.collect()
    b0 = verdant.alloc_bytes()
    p = verdant.grow(TINY)
    c = p.cloud(points=1000)
    assert verdant.alloc_bytes() > b0
    v = c.pos
    del c, p
    gc.collect()
    assert verdant.alloc_bytes() > b0          # v keeps the cloud alive
    del v
    gc.collect()
    assert verdant.alloc_bytes() == b0
