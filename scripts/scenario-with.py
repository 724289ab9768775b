#!/usr/bin/env python3
"""Writes a copy of a scenario with values changed, usable from any folder.

usage: scripts/scenario-with.py SCENARIO OUT [PATH=JSON ...] [--force]
  PATH is a dotted key path (run.duration_s, population.seed), JSON its new
  value (20, 7, "paper"). The venue and the reference body are made absolute
  paths, so that OUT works wherever it is written. OUT is never SCENARIO (nor
  the same file by another name or link); an existing OUT that is not a
  scenario is replaced only with --force; it is written whole
  (scripts/script_guard.py). Standard library only.
"""
import argparse
import json
import os
import sys

import script_guard as guard  # (this folder: the scripts are run as files, so it is on the path)


def change(text):
    """argparse type=: PATH=JSON."""
    path, eq, value = text.partition("=")
    if not eq or not path or any(not k for k in path.split(".")):
        raise argparse.ArgumentTypeError(f"{text!r} is not PATH=JSON; expected a dotted key path and a JSON "
                                               "value, such as run.duration_s=20 or population.body.mode='\"paper\"'")
    try:
        return path.split("."), json.loads(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text}: {value!r} is not JSON; expected a JSON value, such as 20, "
                                               "true or '\"paper\"' (a string in double quotes)") from None


def main(argv):
    p = guard.ArgumentParser(prog=os.path.basename(argv[0]), description=__doc__.splitlines()[0])
    p.add_argument("scenario", type=guard.existing_file, help="the scenario (JSON) to copy")
    p.add_argument("out", help="the copy to write")
    p.add_argument("changes", nargs="*", type=change, metavar="PATH=JSON")
    guard.add_force(p)
    args = p.parse_args(argv[1:])
    d = guard.read_json_file(args.scenario, "a crowdrecon scenario (JSON)")
    if not isinstance(d, dict) or not isinstance(d.get("venue"), str):
        raise guard.ScriptError(f"{args.scenario}: has no \"venue\" path; expected a crowdrecon scenario")
    guard.check_outputs([guard.Output("OUT", args.out, "a crowdrecon scenario",
                                      guard.is_json_with("format", "crowdrecon-scenario"))],
                        [("SCENARIO", args.scenario)], args.force)
    base = os.path.dirname(os.path.abspath(args.scenario))
    d["venue"] = os.path.normpath(os.path.join(base, d["venue"]))
    body = d.get("population", {}).get("body", {})
    if "reference" in body:
        body["reference"] = os.path.normpath(os.path.join(base, body["reference"]))
    for keys, value in args.changes:
        node = d
        for k in keys[:-1]:
            node = node.setdefault(k, {})
            if not isinstance(node, dict):
                raise guard.ScriptError(f"{'.'.join(keys)}: {k} is {json.dumps(node)[:40]}, not an object; "
                                        "expected a key path through objects")
        node[keys[-1]] = value
    guard.write_whole(args.out, json.dumps(d))


if __name__ == "__main__":
    guard.run_main(main, sys.argv)
