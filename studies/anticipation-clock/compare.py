#!/usr/bin/env python3
"""Per-seed statistics of a validation test's runs for several profiles, and
each profile against the first (the exact one): the mean and the seeds'
standard deviation of each per-run statistic, the difference of the means
and its standard error (Welch), and whether it passes the study's test
(README.md: |difference| < 2 standard errors of the difference).

    studies/anticipation-clock/compare.py TEST_ID FOLDER:PROFILE [FOLDER:PROFILE ...]
"""
import glob
import json
import math
import pathlib
import statistics as st
import sys


def per_run(folder, profile, test):
    """Per statistic (and per case of the test, when it has several: the
    measure files are NNNN-CASE-seedK.json), the value of each run."""
    runs = {}
    files = sorted(glob.glob(f"{folder}/runs/{profile}/{test}-*/measures/*.json"))
    cases = {pathlib.Path(f).stem.split("-", 1)[1].rsplit("-seed", 1)[0] for f in files}
    for f in files:
        d = json.load(open(f))
        case = pathlib.Path(f).stem.split("-", 1)[1].rsplit("-seed", 1)[0]
        prefix = f"{case}: " if len(cases) > 1 else ""
        for k, v in d["statistics"].items():
            if len(v) == 1 and v[0] is not None:  # (one value per run; lists of events are summarised elsewhere)
                runs.setdefault(prefix + k, []).append(float(v[0]))
            elif k == "lapse_s" and v:
                runs.setdefault(prefix + "lapse_s_mean", []).append(st.mean(v))
    return runs


def main():
    test, specs = sys.argv[1], sys.argv[2:]
    data = [(spec.split(":")[1], per_run(*spec.split(":"), test)) for spec in specs]
    base_name, base = data[0]
    print(f"{test}: each against {base_name}")
    print(f"| statistic | {' | '.join(n for n, _ in data)} | " +
          " | ".join(f"{n} - {base_name} (2 s.e.)" for n, _ in data[1:]) + " |")
    print("|" + " --- |" * (1 + 2 * len(data) - 1))
    verdict = {n: True for n, _ in data[1:]}
    for k in base:
        cells = [f"{st.mean(r[k]):.3f} ± {st.stdev(r[k]):.3f}" if len(r.get(k, [])) > 1 else "-" for _, r in data]
        diffs = []
        for n, r in data[1:]:
            a, b = base[k], r.get(k, [])
            if len(a) < 2 or len(b) < 2:
                diffs.append("-")
                continue
            d = st.mean(b) - st.mean(a)
            se = math.sqrt(st.variance(a) / len(a) + st.variance(b) / len(b))
            ok = abs(d) <= 2 * se if se > 0 else d == 0
            verdict[n] = verdict[n] and ok
            diffs.append(f"{d:+.3f} ({2 * se:.3f}) {'ok' if ok else 'DIFFERS'}")
        print(f"| {k} | " + " | ".join(cells) + " | " + " | ".join(diffs) + " |")
    for n, ok in verdict.items():
        print(f"{n}: {'the same statistics within the seeds spread' if ok else 'differs'}")


if __name__ == "__main__":
    main()
