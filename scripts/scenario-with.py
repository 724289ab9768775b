#!/usr/bin/env python3
"""Writes a copy of a scenario with values changed, usable from any folder.

usage: scripts/scenario-with.py SCENARIO OUT [PATH=JSON ...]
  PATH is a dotted key path (run.duration_s, population.seed), JSON its new
  value (20, 7, "paper"). The venue and the reference body are made absolute
  paths, so that OUT works wherever it is written. Standard library only.
"""
import json
import os
import sys


def main(argv):
    if len(argv) < 3:
        sys.exit(__doc__)
    src, dst = argv[1], argv[2]
    d = json.load(open(src))
    base = os.path.dirname(os.path.abspath(src))
    d["venue"] = os.path.normpath(os.path.join(base, d["venue"]))
    body = d.get("population", {}).get("body", {})
    if "reference" in body:
        body["reference"] = os.path.normpath(os.path.join(base, body["reference"]))
    for change in argv[3:]:
        path, _, value = change.partition("=")
        keys = path.split(".")
        node = d
        for k in keys[:-1]:
            node = node.setdefault(k, {})
        node[keys[-1]] = json.loads(value)
    json.dump(d, open(dst, "w"))


if __name__ == "__main__":
    main(sys.argv)
