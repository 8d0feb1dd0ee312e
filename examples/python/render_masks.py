# SPDX-License-Identifier: MIT
"""Render a plant with depth and label masks, then lift the depth image back to a labelled
point cloud with the intrinsics K and the camera pose: what a depth camera would give.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/render_masks.py
"""
import os

import numpy as np

import verdant

here = os.path.dirname(os.path.abspath(__file__))
plant = verdant.grow(os.path.join(here, "..", "..", "data", "tomato.lpy"), seed=3)
f = verdant.render(plant, camera="orbit", azimuth=30, elevation=15, size=(640, 480))
print("colour", f["rgb"].shape, "depth", f["depth"].shape, "masks", f["label"].dtype)
for e in f["legend"]:
    print(f"  {e['name']:>10}: {np.count_nonzero(f['label'] == e['id']):6d} pixels")

# pixels -> camera frame (OpenCV: X right, Y down, Z forward) -> world
K, pose = f["K"], f["pose"]
v, u = np.nonzero(f["label"])
z = f["depth"][v, u].astype(np.float64)
cam = np.stack([(u - K[0, 2]) / K[0, 0] * z, (v - K[1, 2]) / K[1, 1] * z, z])
world = (pose[:3, :3] @ cam).T + pose[:3, 3]
labels = f["label"][v, u]
print(f"{len(world)} labelled points from one view; their box "
      f"{world.min(axis=0).round(3)} .. {world.max(axis=0).round(3)} m")
