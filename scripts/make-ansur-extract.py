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
The target is checked before any work (never a source file; an existing file
that is not a previous extract only with --force) and written whole
(scripts/script_guard.py); a source folder without the two files, or a file
without the kept columns, is one line and exit status 2.
"""
import csv
import sys
from pathlib import Path

import script_guard as guard  # (this folder: the scripts are run as files, so it is on the path)

COLUMNS = ["subjectid", "sex", "chestbreadth", "chestdepth", "biacromialbreadth",
           "bideltoidbreadth", "weightkg", "stature"]


SOURCES = (("ANSURIIMALEPublic.csv", "male"), ("ANSURIIFEMALEPublic.csv", "female"))
HEADER = "# ANSUR II (Gordon et al. 2014, NATICK/TR-15/007), public U.S. Government data.\n"


def main() -> int:
    p = guard.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("source", type=guard.existing_dir, help="the folder of the ANSUR II CSV files "
                   "(../shared/data/anthropometry)")
    p.add_argument("target", help="the extract to write (venues/bodies/ansur2-thorax.csv)")
    guard.add_force(p)
    args = p.parse_args()
    source, target = Path(args.source), Path(args.target)
    for name, _ in SOURCES:
        guard.require_csv_columns(source / name, ["subjectid", "Gender"] + COLUMNS[2:],
                                  f"the ANSUR II public file {name} (Gordon et al. 2014)")
    guard.check_outputs([guard.Output("TARGET", target, "an ANSUR II extract of this script", guard.starts_with(HEADER))],
                        [("an ANSUR II source", source / name) for name, _ in SOURCES], args.force)
    rows = []
    for name, sex in SOURCES:
        # newline="" lets the csv module handle the CRLF line endings.
        with open(source / name, encoding="utf-8", errors="replace", newline="") as f:
            for record in csv.DictReader(f):
                if record["Gender"].lower() != sex:
                    raise guard.ScriptError(f"{name}: subject {record['subjectid']}: Gender "
                                            f"{record['Gender']!r}; expected {sex}")
                row = [record["subjectid"], sex] + [record[c] for c in COLUMNS[2:]]
                for value in row[2:]:
                    if value is None or not value.isdigit():
                        raise guard.ScriptError(f"{name}: subject {row[0]}: non-integer value {value!r}; "
                                                "expected whole numbers in the kept columns")
                rows.append(row)
    text = HEADER + "# Extract made by scripts/make-ansur-extract.py; lengths in mm, weightkg in 0.1 kg.\n"
    text += ",".join(COLUMNS) + "\n" + "".join(",".join(row) + "\n" for row in rows)
    try:
        data = text.encode("ascii")
    except UnicodeEncodeError as e:
        raise guard.ScriptError(f"a non-ASCII character {text[e.start]!r} in a kept column; expected ASCII values") from None
    guard.write_whole(target, data)
    print(f"{target}: {len(rows)} records")
    return 0


if __name__ == "__main__":
    guard.run_main(main)
