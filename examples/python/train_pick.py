# SPDX-License-Identifier: MIT
"""Learn to pick a tomato with numpy only: the cross-entropy method (CEM) over the 8 parameters of
a small residual policy on top of a scripted approach, each generation's policies run side by
side as one verdant.VectorHarvestEnv (one environment per candidate, stepped in native threads).

The policy: go to the target fruit plus a learnt offset (3, m) with a learnt gain (1/s), close the
gripper once within a learnt distance (m), then pull along a learnt direction (3) at 0.05 m/s.
The initial distribution knows none of it (offsets of a few cm, any pull direction), so few
early candidates pick the fruit; CEM keeps the best quarter each generation and refits a
Gaussian. Success is the target fruit coming off the plant within the episode. Every generation
runs on the same plants (environment i: seed s + i), so the curve shows the policy improving
rather than the luck of the draw; the final mean policy is then run on as many other plants.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/train_pick.py [--iterations 8]
        [--population 12] [--threads 2] [--plot train_pick.png]

Prints the success rate and mean return per iteration and writes the curve as a PNG (no
plotting library needed: a small rasteriser below).
"""
import argparse
import os
import struct
import zlib

import numpy as np

import verdant

HERE = os.path.dirname(os.path.abspath(__file__))
ap = argparse.ArgumentParser()
ap.add_argument("--scene", default=os.path.join(HERE, "..", "..", "data", "scenes", "mini_pick.json"))
ap.add_argument("--iterations", type=int, default=6)
ap.add_argument("--population", type=int, default=12)
ap.add_argument("--elite", type=float, default=0.25, help="fraction kept each iteration")
ap.add_argument("--steps", type=int, default=600, help="control steps per episode (0.01 s each)")
ap.add_argument("--threads", type=int, default=2)
ap.add_argument("--seed", type=int, default=0)
ap.add_argument("--plot", default="train_pick.png")
a = ap.parse_args()

# parameters: offset (3, m), gain (1/s), close distance (m), pull direction (3)
MEAN0 = np.array([0.0, 0.0, 0.0, 2.0, 0.006, 0.0, 0.0, 0.0])
STD0 = np.array([0.015, 0.015, 0.015, 1.0, 0.004, 1.0, 1.0, 1.0])


def run_generation(envs, params, seed):
    """One episode per candidate (row of params), all stepped together; returns (success,
    return) per candidate."""
    n = len(params)
    obs, _ = envs.reset(seed=seed)
    offset, gain = params[:, 0:3], np.abs(params[:, 3:4])
    close_at = np.abs(params[:, 4])
    pull = params[:, 5:8] / (np.linalg.norm(params[:, 5:8], axis=1, keepdims=True) + 1e-9)
    phase = np.zeros(n, int)              # 0 go, 1 close, 2 pull
    wait = np.zeros(n, int)
    live = np.ones(n, bool)               # still in its first episode
    success, total = np.zeros(n, bool), np.zeros(n)
    for _ in range(a.steps):
        e = obs["fruit_pos"] + offset - obs["ee_pos"]
        v = np.where(phase[:, None] == 0, np.clip(gain * e, -0.1, 0.1), 0.0)
        v = np.where(phase[:, None] == 2, 0.05 * pull, v)
        grip = (phase > 0).astype(float)
        act = np.concatenate([v, np.zeros((n, 3)), grip[:, None]], axis=1)
        obs, reward, terminated, truncated, info = envs.step(act)
        total += np.where(live, reward, 0.0)
        success |= live & (obs["detached"][:, 0] == 1)
        wait += phase == 1
        phase = np.where((phase == 0) & (np.linalg.norm(e, axis=1) < close_at), 1, phase)
        phase = np.where((phase == 1) & ((obs["held"][:, 0] == 1) | (wait > 60)), 2, phase)
        live &= ~(terminated | truncated)
        if not live.any():
            break
    return success, total


def write_png(path, iters, rates):
    """A line plot of success (0-1) against iteration, as an RGB PNG."""
    w, h, m = 480, 300, 40
    img = np.full((h, w, 3), 255, np.uint8)
    img[h - m, m:w - m + 1] = img[m:h - m + 1, m] = 0                    # axes
    for k in range(11):                                                  # grid every 10 %
        y = h - m - round(k / 10 * (h - 2 * m))
        img[y, m + 1:w - m + 1:4] = 180
        img[y, m - 4:m] = 0
    xs = [m + round(i / max(len(iters) - 1, 1) * (w - 2 * m)) for i in range(len(iters))]
    ys = [h - m - round(r * (h - 2 * m)) for r in rates]
    for x, y in zip(xs, ys):
        img[h - m:h - m + 5, x] = 0                                       # x ticks
    for (x0, y0), (x1, y1) in zip(zip(xs, ys), zip(xs[1:], ys[1:])):
        for t in np.linspace(0, 1, 4 * max(abs(x1 - x0), abs(y1 - y0), 1)):
            x, y = round(x0 + t * (x1 - x0)), round(y0 + t * (y1 - y0))
            img[y - 1:y + 2, x - 1:x + 2] = (30, 120, 40)
    for x, y in zip(xs, ys):
        img[y - 4:y + 5, x - 4:x + 5] = (200, 40, 40)
    raw = b"".join(b"\0" + row.tobytes() for row in img)
    chunk = lambda t, d: struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d))
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


rng = np.random.default_rng(a.seed)
envs = verdant.VectorHarvestEnv(a.scene, num_envs=a.population, threads=a.threads,
                                max_episode_steps=a.steps)
mean, std = MEAN0.copy(), STD0.copy()
nelite = max(2, int(round(a.elite * a.population)))
rates = []
print("iteration  success  mean return  best return")
for it in range(a.iterations):
    params = mean + std * rng.standard_normal((a.population, len(mean)))
    # every generation on the same plants (common random numbers: the curve shows the policy's
    # progress, not the draw of plants), a held-out set at the end
    success, ret = run_generation(envs, params, seed=a.seed * 1000)
    score = ret + 10.0 * success
    elite = params[np.argsort(-score)[:nelite]]
    mean, std = elite.mean(axis=0), elite.std(axis=0) + 0.02 * STD0      # CEM refit, a noise floor
    rates.append(success.mean())
    print(f"{it:9d}  {success.mean():7.0%}  {ret.mean():11.2f}  {ret.max():11.2f}", flush=True)
held, _ = run_generation(envs, np.tile(mean, (a.population, 1)), seed=a.seed * 1000 + 500)
envs.close()
print(f"the final mean policy on {a.population} other plants: {held.mean():.0%} picked")
print("final mean policy: offset", np.round(mean[:3], 4), "gain", round(abs(mean[3]), 2),
      "close at", round(abs(mean[4]), 4), "pull", np.round(mean[5:] / np.linalg.norm(mean[5:]), 2))
write_png(a.plot, list(range(a.iterations)), rates)
print("wrote", a.plot)
