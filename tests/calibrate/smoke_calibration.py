#!/usr/bin/env python3
"""Writes the smoke calibration's files into DIR: scenario.json (a sparse
2-s periodic hallway with a recorded fatal clog at 1.5 s), truth.json (the
same with Gamma 2.5 and another seed, for the observation) and
calibration.json (Gamma in [0.5, 4.5] from 4, two seeds, fitted to a speed
and a share-still series and the recorded clog). OPTIONS (JSON) replaces
keys of the calibration's "options". Used by smoke_test.sh and
sigint_background.sh.

usage: smoke_calibration.py SOURCE_DIR DIR [OPTIONS_JSON]
"""
import json
import sys


def main(argv):
    if len(argv) not in (3, 4):
        sys.exit(__doc__)
    src, d = argv[1], argv[2]
    s = json.load(open(src + "/tests/data/scenarios/sweep-tiny.json"))
    s["venue"] = src + "/venues/madrid-arena/hallway-periodic.json"
    s["population"]["body"]["reference"] = src + "/venues/bodies/thorax-18.json"
    s["population"]["density_per_m2"] = 2.0
    s["run"]["duration_s"] = 2.0
    # A recorded fatal clog (issue 41): compared as a time with each run's clog
    # for good (none in 2 s: the window's end).
    s["timeline"] = {"recorded": [{"time_s": 1.5, "label": "fatal clog", "kind": "fatal"}]}
    json.dump(s, open(d + "/scenario.json", "w"))
    s["model"] = {"back_force_gamma": 2.5}
    s["population"]["seed"] = 9
    json.dump(s, open(d + "/truth.json", "w"))
    c = {"format": "crowdrecon-calibration", "version": 1, "name": "smoke", "scenario": "scenario.json",
         "parameters": [{"path": "model.back_force_gamma", "min": 0.5, "max": 4.5}],
         "observations": [{"file": "truth.observation.json", "series": [
             {"quantity": "speed", "where": "hallway", "direction": "forward", "from_s": 0.4, "to_s": 2, "window_s": 0.8},
             {"quantity": "share_still", "where": "hallway", "direction": "all", "from_s": 0.4, "to_s": 2}]},
                          {"recorded": {"kind": "fatal", "uncertainty_s": 0.5}}],
         "seeds": {"first": 1, "count": 2}, "starts": [{"model.back_force_gamma": 4}],
         "options": {"refinements": 1, "bootstrap": 20, "profile_points": 3}}
    if len(argv) == 4:
        c["options"].update(json.loads(argv[3]))
    json.dump(c, open(d + "/calibration.json", "w"))


if __name__ == "__main__":
    main(sys.argv)
