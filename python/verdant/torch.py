# SPDX-License-Identifier: MIT
"""PyTorch helpers: labelled point clouds of plants as a Dataset, one plant per seed.

    from torch.utils.data import DataLoader
    from verdant.torch import PlantCloudDataset

    ds = PlantCloudDataset("data/tomato.lpy", 1000, points=4096)   # item i: seed i
    for batch in DataLoader(ds, batch_size=8, num_workers=2):
        batch["xyz"]      # float32 (8, 4096, 3)
        batch["label"]    # int64 (8, 4096)

Items are made on demand in the worker that asks for them (growing and sampling release the
GIL), and item i depends on i alone: the same tensors in any worker, any run, any batch order.
Needs Debian's python3-torch.
"""
import numpy as np
import torch
from torch.utils.data import Dataset

import verdant


class PlantCloudDataset(Dataset):
    """Item i is the plant `source` grown with seed `seed + i` (verdant.grow), sampled as a
    labelled cloud of `points` points with the same seed (Plant.cloud), as a dict of tensors:

    xyz: float32 (points, 3), positions (m); label: int64 (points), semantic label ids (or
    instance ids with cloud={"labels": "instance"}); instance: int64 (points); normals:
    float32 (points, 3) when normals=True; seed: int64, the item's seed.

    grow: keywords of verdant.grow (steps, set, labels); cloud: keywords of Plant.cloud
    (sensor, scanners, noise, occlusion, ...; threads defaults to 1: the DataLoader's workers
    are the parallelism); transform: a function applied to each item dict.
    With sensor='scan' the point count varies: batch with collate_ragged.
    """

    def __init__(self, source, length, *, seed=0, points=2048, grow=None, cloud=None,
                 normals=False, transform=None):
        if length < 0:
            raise ValueError("length must be >= 0")
        self.source = source
        self.length = int(length)
        self.seed = int(seed)
        self.points = points
        self.grow_kw = dict(grow or {})
        self.cloud_kw = dict(cloud or {})
        self.cloud_kw.setdefault("threads", 1)
        if self.cloud_kw.get("sensor") != "scan":
            self.cloud_kw.setdefault("points", points)
        self.normals = normals
        self.transform = transform

    def __len__(self):
        return self.length

    def cloud(self, i):
        """The verdant.Cloud of item i."""
        if not -self.length <= i < self.length:
            raise IndexError(f"item {i} of {self.length}")
        s = self.seed + (i % self.length)
        return verdant.grow(self.source, seed=s, **self.grow_kw).cloud(**self.cloud_kw)

    def __getitem__(self, i):
        c = self.cloud(i)
        item = {
            "xyz": torch.from_numpy(np.array(c.xyz)),
            "label": torch.from_numpy(c.label.astype(np.int64)),
            "instance": torch.from_numpy(c.instance.astype(np.int64)),
            "seed": torch.tensor(c.seed, dtype=torch.int64),
        }
        if self.normals:
            item["normals"] = torch.from_numpy(c.normals.astype(np.float32))
        return self.transform(item) if self.transform else item


def collate_ragged(items):
    """Batch items of different point counts: per-point tensors concatenated, with "batch"
    (int64, the item index of each point) and "counts" (points per item)."""
    out = {}
    for k in items[0]:
        vals = [it[k] for it in items]
        out[k] = torch.cat(vals) if vals[0].dim() else torch.stack(vals)
    counts = torch.tensor([len(it["xyz"]) for it in items], dtype=torch.int64)
    out["batch"] = torch.repeat_interleave(torch.arange(len(items)), counts)
    out["counts"] = counts
    return out
