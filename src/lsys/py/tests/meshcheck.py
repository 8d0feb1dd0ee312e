# SPDX-License-Identifier: MIT
"""Checks of triangle meshes shared by the shim's tests."""
from collections import Counter


def signed_volume(v, t):
    """The volume a closed mesh encloses (divergence theorem); positive when it faces outward."""
    s = 0.0
    for a, b, c in t:
        (ax, ay, az), (bx, by, bz), (cx, cy, cz) = v[a], v[b], v[c]
        s += ax * (by * cz - bz * cy) - ay * (bx * cz - bz * cx) + az * (bx * cy - by * cx)
    return s / 6.0


def area(v, t):
    s = 0.0
    for a, b, c in t:
        u = [v[b][k] - v[a][k] for k in range(3)]
        w = [v[c][k] - v[a][k] for k in range(3)]
        n = (u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0])
        s += 0.5 * (n[0] ** 2 + n[1] ** 2 + n[2] ** 2) ** 0.5
    return s


def is_closed(t):
    """Every directed edge has its reverse exactly once: a closed, consistently oriented surface."""
    e = Counter()
    for a, b, c in t:
        for x, y in ((a, b), (b, c), (c, a)):
            e[(x, y)] += 1
    return all(n == 1 and e.get((y, x)) == 1 for (x, y), n in e.items())


def in_range(v, t):
    return all(0 <= i < len(v) for f in t for i in f)
