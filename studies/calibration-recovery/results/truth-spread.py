#!/usr/bin/env python3
"""Do the recordings of the recovery problem look like other runs at the same
(true) values? Compares the 21 window statistics (speeds, shares, flows per
direction, 5-s windows from 5 to 20 s) of sets of observation CSVs:
per statistic the difference of the sets' means in units of its standard
error (z), then the mean, rms and largest |z| over the statistics.

  # other runs at the true values, observed as the recordings are:
  #   (copy venues/madrid-arena/calibrations/hallway-recovery-truth.json with
  #    "seeds": [1, ..., 16] and an absolute "scenario", then)
  crowdrecon sweep truth-other-seeds.json -o other -q
  for r in other/runs/*.sqlite; do crowdrecon observe trajectories "$r" \\
      --spec venues/madrid-arena/observations/hallway.json -o "other/${r##*/}.observation.json" -q; done
  truth-spread.py 'other/*.observation.csv' 'OUT-truth/observations/*.csv'

Two globs, each of two or more observation CSVs (columns quantity, where,
direction, value, time_s); anything else is one line, exit status 2
(scripts/script_guard.py).
"""
import csv, glob, math, os, statistics as S, sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))  # studies/NAME/results/
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import script_guard as guard  # noqa: E402

COLUMNS = ("quantity", "where", "direction", "value", "time_s")
EXPECTED = "an observation CSV of `crowdrecon observe` (columns quantity, where, direction, value, time_s)"

SERIES = [("speed", "hallway", "forward"), ("speed", "hallway", "backward"),
          ("share_moving", "hallway", "forward"), ("share_moving", "hallway", "backward"),
          ("share_still", "hallway", "all"), ("flow", "middle", "forward"), ("flow", "middle", "backward")]


def statistics(path):
    guard.require_csv_columns(path, COLUMNS, EXPECTED)
    rows = list(csv.DictReader(open(path)))
    try:
        for r in rows:
            if r["value"]:
                float(r["value"])
            float(r["time_s"])
    except (TypeError, ValueError):
        raise guard.ScriptError(f"{path}: a row whose value or time_s is not a number; expected {EXPECTED}") from None
    out = {}
    for q, w, d in SERIES:
        for a in (5, 10, 15):
            v = [float(r["value"]) for r in rows if (r["quantity"], r["where"], r["direction"]) == (q, w, d)
                 and r["value"] and a <= float(r["time_s"]) < a + 5]
            out[(q, w, d, a)] = sum(v) / len(v) if v else float("nan")
    return out


def files_of(pattern, least):
    """The files a glob matches (sorted); ScriptError if fewer than `least`."""
    files = sorted(glob.glob(pattern))
    if len(files) < least:
        raise guard.ScriptError(f"{pattern!r}: matches {len(files)} file{'s' if len(files) != 1 else ''}; expected a "
                                f"glob of at least {least} observation CSVs (quoted, so that the script expands it)")
    return files


def main():
    p = guard.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("a", help="a glob of observation CSVs (quoted)")
    p.add_argument("b", help="another glob of observation CSVs (quoted)")
    args = p.parse_args()
    groups = [files_of(pattern, 2) for pattern in (args.a, args.b)]
    sets = [[statistics(f) for f in files] for files in groups]
    zs = []
    for key in sets[0][0]:
        a, b = ([s[key] for s in group if not math.isnan(s[key])] for group in sets)
        se = math.sqrt(S.variance(a) / len(a) + S.variance(b) / len(b))
        z = (S.mean(a) - S.mean(b)) / se if se > 0 else 0.0
        zs.append(z)
        print("%-40s %.3f +- %.3f  %.3f +- %.3f  z %+.2f" % (" ".join(map(str, key)), S.mean(a),
              S.stdev(a) / math.sqrt(len(a)), S.mean(b), S.stdev(b) / math.sqrt(len(b)), z))
    print("%d and %d files: mean z %.2f, rms z %.2f, largest |z| %.2f" % (len(sets[0]), len(sets[1]), S.mean(zs),
          math.sqrt(S.mean([z * z for z in zs])), max(abs(z) for z in zs)))


if __name__ == "__main__":
    guard.run_main(main)
