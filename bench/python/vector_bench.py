# SPDX-License-Identifier: MIT
"""VectorHarvestEnv throughput: env-steps/s for num_envs N = 1, 8, 64 on T = 1, 2 threads, with
the process CPU time beside the wall time and the machine's load, and the Python layer's share
of one HarvestEnv step (HarvestEnv.step against the C call under it, Harvest.act).

    PYTHONPATH=build/python /usr/bin/python3 bench/python/vector_bench.py [--steps S] [--csv F]
"""
import argparse
import csv
import os
import sys
import time

import numpy as np

import verdant

HERE = os.path.dirname(os.path.abspath(__file__))
ap = argparse.ArgumentParser()
ap.add_argument("--scene", default=os.path.join(HERE, "..", "..", "data", "scenes", "mini_pick.json"))
ap.add_argument("--steps", type=int, default=64, help="vector steps per measurement (N=1: x8)")
ap.add_argument("--sizes", default="1,8,64")
ap.add_argument("--threads", default="1,2")
ap.add_argument("--csv", default=None)
ap.add_argument("--share-only", action="store_true", help="only the Python layer's share")
a = ap.parse_args()


def actions(n, rng, space):
    return space.low + (space.high - space.low) * rng.random((n, 7))


def measure(n, t):
    envs = verdant.VectorHarvestEnv(a.scene, num_envs=n, threads=t, max_episode_steps=200)
    envs.reset(seed=0)
    rng = np.random.default_rng(0)
    sp = envs.single_action_space
    steps = a.steps * (8 if n == 1 else 1)
    acts = [actions(n, rng, sp) for _ in range(steps)]
    envs.step(acts[0])   # warm
    load = os.getloadavg()[0]
    w0, c0 = time.perf_counter(), time.process_time()
    for x in acts:
        envs.step(x)
    wall, cpu = time.perf_counter() - w0, time.process_time() - c0
    envs.close()
    return n * steps / wall, n * steps / cpu, wall, cpu, load


def python_share(repeats=5):
    """CPU seconds per HarvestEnv.step and per Harvest.act alone (the C step with its reward),
    on the same episode's steps; each the least of `repeats` runs taken in turn, so that a
    machine's clock or a neighbour's burst does not land on one side only."""
    env = verdant.HarvestEnv(a.scene, max_episode_steps=10 ** 6)
    w = env._weights
    rng = np.random.default_rng(1)
    acts = actions(400, rng, env.action_space)
    full = core = float("inf")
    for _ in range(repeats):
        env.reset(seed=0)
        t0 = time.process_time()
        for x in acts:
            env.step(x)
        full = min(full, (time.process_time() - t0) / len(acts))
        env.reset(seed=0)
        h = env._h
        t0 = time.process_time()
        for x in acts:
            x = np.clip(x, env.action_space.low, env.action_space.high)
            h.act(x[:3], x[3:6], x[6], w, True, None)
        core = min(core, (time.process_time() - t0) / len(acts))
    return full, core


rows = []
print(f"# {os.path.basename(a.scene)}, {a.steps} vector steps per row; load = 1-min load average")
print(f"{'N':>4} {'T':>2} {'env-steps/s':>12} {'per CPU-s':>10} {'wall s':>7} {'CPU s':>7} {'load':>5}")
base = {}
for n in [] if a.share_only else [int(v) for v in a.sizes.split(",")]:
    for t in [int(v) for v in a.threads.split(",")]:
        rate, crate, wall, cpu, load = measure(n, t)
        base.setdefault(n, rate)
        rows.append(dict(N=n, T=t, env_steps_per_s=round(rate, 1), env_steps_per_cpu_s=round(crate, 1),
                         wall_s=round(wall, 3), cpu_s=round(cpu, 3), load=round(load, 2),
                         speedup_vs_T1=round(rate / base[n], 3)))
        print(f"{n:4d} {t:2d} {rate:12.1f} {crate:10.1f} {wall:7.2f} {cpu:7.2f} {load:5.2f}"
              f"   x{rate / base[n]:.2f} vs T=1")
        sys.stdout.flush()
full, core = python_share()
print(f"HarvestEnv.step {full * 1e3:.3f} ms CPU, Harvest.act {core * 1e3:.3f} ms CPU: Python layer "
      f"{100 * (full - core) / full:.1f} % of a step")
if a.csv and rows:
    with open(a.csv, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
