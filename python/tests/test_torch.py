# SPDX-License-Identifier: MIT
"""verdant.torch: a DataLoader with 2 workers gets distinct, reproducible items (needs Debian's
python3-torch, which scripts/deps.sh --dev installs for CI)."""
import numpy as np
import pytest

torch = pytest.importorskip("torch")
from torch.utils.data import DataLoader  # noqa: E402

import verdant  # noqa: E402
from conftest import data  # noqa: E402
from verdant.torch import PlantCloudDataset, collate_ragged  # noqa: E402


def test_dataloader_two_workers():
    # the parent has used OpenMP threads before the workers fork: they still sample
    verdant.grow(data("arabidopsis.lpy"), seed=1).cloud(points=20000, threads=2)
    ds = PlantCloudDataset(data("arabidopsis.lpy"), 8, seed=100, points=1024)

    def epoch():
        out = []
        for b in DataLoader(ds, batch_size=2, num_workers=2):
            assert b["xyz"].shape == (2, 1024, 3) and b["xyz"].dtype == torch.float32
            assert b["label"].dtype == torch.int64 and b["instance"].shape == (2, 1024)
            out += [(int(s), x, l) for s, x, l in zip(b["seed"], b["xyz"], b["label"])]
        return out

    a, b = epoch(), epoch()
    assert [s for s, _, _ in a] == list(range(100, 108))
    # distinct: every item is another plant
    for i in range(len(a)):
        for j in range(i):
            assert not torch.equal(a[i][1], a[j][1])
    # reproducible: the same tensors in a second epoch and in this process
    for (s, x, l), (s2, x2, l2) in zip(a, b):
        assert s == s2 and torch.equal(x, x2) and torch.equal(l, l2)
    direct = ds[3]
    assert torch.equal(direct["xyz"], a[3][1])
    c = verdant.grow(data("arabidopsis.lpy"), seed=103).cloud(points=1024)
    assert np.array_equal(direct["xyz"].numpy(), c.xyz) and np.array_equal(direct["label"].numpy(), c.label)


def test_ragged_scans_and_options():
    ds = PlantCloudDataset(data("tomato.lpy"), 3, normals=True, grow={"steps": 8},
                           cloud={"sensor": "scan", "scanners": [(1.2, 0, 0.5)], "res": (40, 30)},
                           transform=lambda it: {**it, "n": torch.tensor(len(it["xyz"]))})
    items = [ds[i] for i in range(3)]
    assert len({len(it["xyz"]) for it in items}) > 1
    b = collate_ragged(items)
    assert b["xyz"].shape == (sum(len(it["xyz"]) for it in items), 3) and b["normals"].shape == b["xyz"].shape
    assert b["batch"].tolist() == sum(([k] * len(it["xyz"]) for k, it in enumerate(items)), [])
    assert b["counts"].tolist() == [int(it["n"]) for it in items]
    with pytest.raises(IndexError):
        ds[3]
    assert torch.equal(ds[-1]["xyz"], items[2]["xyz"])
