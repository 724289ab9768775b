#!/usr/bin/env python3
"""The study's profiles: the profile validated (venues/profiles/validated.json,
read here, so that its values have one source) with the anticipation's clock
(anticipation_interval_s, issue 66) at each interval studied, written as
validated-clock-<ms>ms.json next to this script.

    studies/anticipation-clock/make_profiles.py [MS ...]   (default: 10 20 50)
"""
import json
import os
import pathlib
import sys

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]


def main():
    specs = sys.argv[1:] or ["10", "20", "50"]
    base = json.loads((ROOT / "venues/profiles/validated.json").read_text())
    for spec in specs:
        ms_text, _, near_text = spec.partition(":")
        ms = int(ms_text)
        p = json.loads(json.dumps(base))
        p["name"] = f"validated-clock-{ms}ms" + (f"-near{near_text}m" if near_text else "")
        p["description"] = (f"The profile validated (venues/profiles/validated.json, its values at {ms} ms of the "
                            "anticipation's clock: the force evaluated once per interval, each person keeping it in "
                            "between; issue 66, studies/anticipation-clock/README.md). Written by make_profiles.py.")
        p["model"]["anticipation_interval_s"] = ms / 1000.0
        if near_text:
            p["model"]["anticipation_near_m"] = float(near_text)
            p["description"] = p["description"].replace(" Written by", f" Pairs within {near_text} m evaluated at every step. Written by")
        # (the body's reference, if any, relative to this folder)
        ref = p.get("body", {}).get("reference")
        if ref:
            p["body"]["reference"] = os.path.relpath(ROOT / "venues/profiles" / ref, HERE)
        out = HERE / f"{p['name']}.json"
        out.write_text(json.dumps(p, indent=2) + "\n")
        print(out.relative_to(ROOT))


if __name__ == "__main__":
    main()
