# SPDX-License-Identifier: MIT
"""The L-system Python engine inside a Python process: it runs in this interpreter (not a second
one), leaves this process's random state alone, and gives the same plant for the same seed."""
import random
import threading

import verdant
from conftest import data

MODEL = """import random
class Bud:
    def __init__(self, n):
        self.n = n
Axiom: A(Bud(0))
derivation length: 6
production:
A(b) :
    if random.random() < 0.8:
        produce F(0.1) [ +(random.uniform(20, 60)) A(Bud(b.n + 1)) ] A(Bud(b.n + 1))
    else:
        produce F(0.05)
"""


def test_engine_runs_in_this_interpreter(tmp_path):
    f = tmp_path / "buds.lpy"
    f.write_text(MODEL)
    random.seed(11)
    expected = [random.random() for _ in range(3)]
    random.seed(11)
    p = verdant.grow(str(f), seed=3)
    assert p.stats["engine"] == "python"
    assert [random.random() for _ in range(3)] == expected  # the host's generator untouched
    q = verdant.grow(str(f), seed=3)
    assert p.stats == q.stats and (p.nodes == q.nodes).all()
    assert verdant.grow(str(f), seed=4).stats != p.stats


def test_engine_from_threads(tmp_path):
    f = tmp_path / "buds.lpy"
    f.write_text(MODEL)
    serial = [verdant.grow(str(f), seed=s).stats for s in range(4)]
    out = [None] * 4

    def run(s):
        out[s] = verdant.grow(str(f), seed=s).stats

    threads = [threading.Thread(target=run, args=(s,)) for s in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert out == serial


def test_bundled_python_model():
    p = verdant.grow(data("python_bud.lpy"))
    assert p.stats["engine"] == "python" and p.stats["labels"]["fruit"] == 1
