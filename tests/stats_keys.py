# SPDX-License-Identifier: MIT
"""The keys a command printed against the keys docs/formats.md documents (issue 19, item 5).

    python3 tests/stats_keys.py docs/formats.md "SECTION" FILE [FILE...]

SECTION is the text of a `### ` heading of docs/formats.md's key contract (for example
"`verdant grow --stats`"); a FILE is JSON (every key path: `a.b`, `list[].c`) or, ending in .csv,
a CSV file (its header's columns). The documented keys are the backquoted names in the first cell
of the section's table rows; a name in capitals (LABEL, SYMBOL...) stands for any one key.
Prints each key that is printed but not documented, and exits 1 when there is one.
"""
import csv
import json
import re
import sys


def section_keys(md_path, title):
    lines = open(md_path, encoding="utf-8").read().splitlines()
    start = [i for i, l in enumerate(lines) if l.startswith("### ") and l[4:].strip() == title]
    if len(start) != 1:
        sys.exit(f"stats_keys: docs/formats.md has {len(start)} sections titled '### {title}' (expected 1)")
    keys = []
    for l in lines[start[0] + 1:]:
        if l.startswith("## ") or l.startswith("### "):
            break
        if l.startswith("| ") and not l.startswith("| ---"):
            first = l.split("|")[1]
            keys += re.findall(r"`([^`]+)`", first)
    if not keys:
        sys.exit(f"stats_keys: section '### {title}' of docs/formats.md documents no key")
    return keys


def paths(value, prefix=""):
    """Every key path of a JSON value: objects give a.b, lists of objects a[].b."""
    out = set()
    if isinstance(value, dict):
        for k, v in value.items():
            p = f"{prefix}.{k}" if prefix else k
            sub = paths(v, p)
            out |= sub if sub else {p}
        if not value and prefix:
            out.add(prefix + "{}")  # an empty object: documented when its keys are
    elif isinstance(value, list):
        for e in value:
            if isinstance(e, (dict, list)):
                out |= paths(e, prefix + "[]")
        if not value and prefix:
            out.add(prefix + "[]")  # an empty list: documented when its elements are
    return out


def matches(key, pattern):
    if key.endswith("{}"):
        return any(matches_exact(key[:-2], ".".join(pattern.split(".")[:n]))
                   for n in range(1, pattern.count(".") + 1))
    if key.endswith("[]"):
        # an empty list: documented as a list (`nodes`) or by the keys of its elements
        # (`events[].time`)
        b = pattern.split(".")[:key.count(".") + 1]
        return matches(key[:-2], pattern) or matches_exact(key, ".".join(b))
    return matches_exact(key, pattern)


def matches_exact(key, pattern):
    a, b = key.split("."), pattern.split(".")
    if len(a) != len(b):
        return False
    for x, y in zip(a, b):
        xs, ys = x.endswith("[]"), y.endswith("[]")
        if xs != ys:
            return False
        x, y = x.rstrip("[]"), y.rstrip("[]")
        if not (x == y or re.fullmatch(r"[A-Z][A-Z_]*", y)):
            return False
    return True


def main():
    md, title, files = sys.argv[1], sys.argv[2], sys.argv[3:]
    documented = section_keys(md, title)
    printed = set()
    for f in files:
        if f.endswith(".csv"):
            with open(f, newline="") as fh:
                printed |= set(next(csv.reader(fh)))
        else:
            printed |= paths(json.load(open(f)))
    missing = sorted(k for k in printed if not any(matches(k, p) for p in documented))
    for k in missing:
        print(f"undocumented key: {title} prints '{k}', which docs/formats.md section '### {title}' "
              f"does not list (add a table row for it)")
    return 1 if missing else 0


if __name__ == "__main__":
    sys.exit(main())
