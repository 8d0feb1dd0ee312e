# SPDX-License-Identifier: MIT
"""Grow the bundled tomato, sample a labelled point cloud, write it, count points per organ, and
(with --view and Open3D installed) look at it.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/grow_and_cloud.py [--seed 3] [--view]
"""
import argparse
import os

import numpy as np

import verdant

here = os.path.dirname(os.path.abspath(__file__))
ap = argparse.ArgumentParser()
ap.add_argument("--plant", default=os.path.join(here, "..", "..", "data", "tomato.lpy"))
ap.add_argument("--seed", type=int, default=3)
ap.add_argument("--points", type=int, default=200000)
ap.add_argument("-o", "--output", default="tomato_cloud.ply")
ap.add_argument("--view", action="store_true", help="open an Open3D window")
a = ap.parse_args()

plant = verdant.grow(a.plant, seed=a.seed)
print(plant)
print("organs per label:", plant.stats["labels"])

cloud = plant.cloud(points=a.points)                   # uniform, interior points removed
ids, counts = np.unique(cloud.label, return_counts=True)
for i, n in zip(ids, counts):
    print(f"  {cloud.labels[int(i)]:>10}: {n:7d} points")
cloud.save(a.output)                                   # binary PLY with label and instance
print(f"wrote {a.output}; the stage times (s):", cloud.stats["seconds"])

# what a scanner at 1.5 m sees: occlusion, noise growing with distance
scan = plant.cloud(points=a.points // 2, sensor="distance", scanners=[(1.5, 0, 0.8)],
                   occlusion=True, noise=(0.0005, 0.001))
print(f"one scanner: {len(scan)} points, range {scan.range.min():.2f}..{scan.range.max():.2f} m")

if a.view:
    import open3d as o3d
    o3d.visualization.draw_geometries([cloud.to_open3d()])
