#!/usr/bin/env python3
"""Regenerates venues/bodies/ansur2-thorax.csv, the small extract of ANSUR II
that crowdrecon ships (docs/bodies.md), from the public ANSUR II CSV files.

    scripts/make-ansur-extract.py ../shared/data/anthropometry venues/bodies/ansur2-thorax.csv

Source: Gordon et al. 2014, "2012 Anthropometric Survey of U.S. Army Personnel:
Methods and Summary Statistics", NATICK/TR-15/007; public U.S. Government data.
Kept columns (units as in the source): subjectid, sex (from Gender), chestbreadth,
chestdepth, biacromialbreadth, bideltoidbreadth, stature (mm), weightkg (0.1 kg).
Rows: male file then female file, in file order. Output: UTF-8 (ASCII), LF line
endings (the sources are CRLF). The sources' only non-ASCII character (a U+FFFD
in an Ethnicity value of the male file) is in a dropped column; the output is
written as ASCII, which would fail loudly if any other such character got through.
"""
import csv
import sys
from pathlib import Path

COLUMNS = ["subjectid", "sex", "chestbreadth", "chestdepth", "biacromialbreadth",
           "bideltoidbreadth", "weightkg", "stature"]


def main() -> int:
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    source, target = Path(sys.argv[1]), Path(sys.argv[2])
    rows = []
    for name, sex in (("ANSURIIMALEPublic.csv", "male"), ("ANSURIIFEMALEPublic.csv", "female")):
        # newline="" lets the csv module handle the CRLF line endings.
        with open(source / name, encoding="utf-8", errors="replace", newline="") as f:
            for record in csv.DictReader(f):
                if record["Gender"].lower() != sex:
                    raise SystemExit(f"{name}: subject {record['subjectid']}: Gender "
                                     f"{record['Gender']!r}, expected {sex}")
                row = [record["subjectid"], sex] + [record[c] for c in COLUMNS[2:]]
                for value in row[2:]:
                    if not value.isdigit():
                        raise SystemExit(f"{name}: subject {row[0]}: non-integer value {value!r}")
                rows.append(row)
    with open(target, "w", encoding="ascii", newline="\n") as out:
        out.write("# ANSUR II (Gordon et al. 2014, NATICK/TR-15/007), public U.S. Government data.\n")
        out.write("# Extract made by scripts/make-ansur-extract.py; lengths in mm, weightkg in 0.1 kg.\n")
        out.write(",".join(COLUMNS) + "\n")
        for row in rows:
            out.write(",".join(row) + "\n")
    print(f"{target}: {len(rows)} records")
    return 0


if __name__ == "__main__":
    sys.exit(main())
