# SPDX-License-Identifier: MIT
"""Train a tiny per-point classifier (organ labels from xyz) on plants made on the fly: a
DataLoader with two workers over verdant.torch.PlantCloudDataset. Needs python3-torch.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/torch_dataset.py [--steps 20]
"""
import argparse
import os

import torch
from torch.utils.data import DataLoader

from verdant.torch import PlantCloudDataset

here = os.path.dirname(os.path.abspath(__file__))
ap = argparse.ArgumentParser()
ap.add_argument("--steps", type=int, default=20)
ap.add_argument("--points", type=int, default=2048)
a = ap.parse_args()

ds = PlantCloudDataset(os.path.join(here, "..", "..", "data", "arabidopsis.lpy"), 10000,
                       points=a.points)
loader = DataLoader(ds, batch_size=4, num_workers=2)
torch.manual_seed(0)
net = torch.nn.Sequential(torch.nn.Linear(3, 64), torch.nn.ReLU(), torch.nn.Linear(64, 64),
                          torch.nn.ReLU(), torch.nn.Linear(64, 16))
opt = torch.optim.Adam(net.parameters(), lr=3e-3)
for step, batch in enumerate(loader):
    xyz, label = batch["xyz"], batch["label"]                 # (4, N, 3) float32, (4, N) int64
    xyz = xyz - xyz.mean(dim=1, keepdim=True)                 # centre each plant
    loss = torch.nn.functional.cross_entropy(net(xyz).reshape(-1, 16), label.reshape(-1))
    opt.zero_grad()
    loss.backward()
    opt.step()
    if step % 5 == 0:
        print(f"step {step:3d}: seeds {batch['seed'].tolist()}, loss {loss.item():.3f}")
    if step + 1 == a.steps:
        break
