# SPDX-License-Identifier: MIT
"""Many plants on all cores from plain Python threads: growing, sampling and stepping release
the GIL, so a thread pool runs them side by side (each Sim stays in its thread).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/parallel_plants.py [--count 8]
"""
import argparse
import os
import time
from concurrent.futures import ThreadPoolExecutor

import verdant

here = os.path.dirname(os.path.abspath(__file__))
ap = argparse.ArgumentParser()
ap.add_argument("--count", type=int, default=8)
ap.add_argument("--steps", type=int, default=200)
a = ap.parse_args()
path = os.path.join(here, "..", "..", "data", "tomato.lpy")


def one(seed):
    p = verdant.grow(path, seed=seed)
    s = verdant.Sim(p, sag_free=True, wind=(4, 0, 0))
    s.step(a.steps)
    c = s.cloud(points=20000, threads=1)
    return seed, s.stats["tip_displacement"], len(c)


t0 = time.perf_counter()
with ThreadPoolExecutor(max_workers=os.cpu_count()) as pool:
    for seed, tip, n in pool.map(one, range(a.count)):
        print(f"seed {seed}: tip moved {tip * 1000:6.1f} mm in the wind, cloud of {n} points")
print(f"{a.count} plants in {time.perf_counter() - t0:.2f} s on {os.cpu_count()} cores")
