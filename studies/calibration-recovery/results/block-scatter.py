#!/usr/bin/env python3
"""Do means over blocks of seeds differ between blocks more than the runs'
own spread says? (The question the 24-recording recovery raised: its
calibration seeds 1-24 walked slower at the true values than its recordings.)

Each argument is a glob of observation CSVs of runs at the true values, one
block of seeds per glob, made and observed as the recordings are (see
truth-spread.py). Prints, per window statistic, the block means' chi2 about
their weighted mean over (blocks - 1) (1 when the blocks differ only by s^2/n),
the multivariate version (the sum over blocks of n (mean - grand)^T S^-1
(mean - grand) with S the pooled within-block covariance, against its
expectation), and the participation ratio of the statistics' correlation
matrix (how many independent statistics they amount to).

  block-scatter.py 'blockA/*.observation.csv' 'blockB/*.observation.csv' ...

Needs numpy (python3-numpy): said in one line where it is missing. Bad
arguments (fewer than two globs, a glob of fewer than three files, a file that
is not an observation CSV) are one line, exit status 2 (scripts/script_guard.py).
"""
import glob, importlib.util, math, os, sys

here = os.path.dirname(os.path.abspath(__file__))
spec = importlib.util.spec_from_file_location("truth_spread", os.path.join(here, "truth-spread.py"))
ts = importlib.util.module_from_spec(spec)
spec.loader.exec_module(ts)
guard = ts.guard  # scripts/script_guard.py, put on the path by truth-spread.py


def main():
    p = guard.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("globs", nargs="+", help="globs of observation CSVs (quoted), one block of seeds each")
    args = p.parse_args()
    if len(args.globs) < 2:
        raise guard.ScriptError(f"{len(args.globs)} glob; expected at least two globs of at least three "
                                "observation CSVs each")
    groups = [ts.files_of(pattern, 3) for pattern in args.globs]
    stats = [[ts.statistics(f) for f in g] for g in groups]
    try:
        import numpy as np
    except ImportError:
        raise guard.ScriptError("numpy is not installed; expected python3-numpy (apt) or numpy (pip)") from None
    keys = list(stats[0][0].keys())
    blocks = [np.array([[s[k] for k in keys] for s in g]) for g in stats]
    b = len(blocks)
    means = np.array([np.nanmean(x, axis=0) for x in blocks])
    counts = np.array([np.sum(~np.isnan(x), axis=0) for x in blocks])
    within = np.vstack([x - np.nanmean(x, axis=0) for x in blocks])
    s2 = np.nansum(within ** 2, axis=0) / np.sum(counts - 1, axis=0)
    print("%d blocks of %s runs" % (b, "/".join(str(len(g)) for g in groups)))
    ratios = []
    for i, k in enumerate(keys):
        w = counts[:, i] / s2[i]
        mu = np.sum(w * means[:, i]) / np.sum(w)
        ratios.append(np.sum(w * (means[:, i] - mu) ** 2) / (b - 1))
        print("  %-36s block means %s; scatter / expected %.2f" % (
            " ".join(map(str, k)), " ".join("%.3f" % m for m in means[:, i]), ratios[-1]))
    print("mean over the %d statistics: %.2f (1 when blocks differ by s^2/n only; each from %d dof)" % (
        len(keys), np.mean(ratios), b - 1))
    rows = within[~np.isnan(within).any(axis=1)]
    dof = len(rows) - b
    s = rows.T @ rows / dof
    si = np.linalg.inv(s)
    grand = np.nanmean(np.vstack(blocks), axis=0)
    t = [len(g) * (m - grand) @ si @ (m - grand) for g, m in zip(groups, means)]
    p = len(keys)
    expected = (b - 1) * p * dof / (dof - p - 1)
    print("multivariate: per block %s; sum %.1f against about %.1f (sd about %.1f)" % (
        " ".join("%.1f" % x for x in t), sum(t), expected, math.sqrt(2 * expected)))
    d = np.sqrt(np.diag(s))
    e = np.linalg.eigvalsh(s / np.outer(d, d))
    print("the statistics' correlations: participation ratio %.2f of %d" % (e.sum() ** 2 / (e ** 2).sum(), p))


if __name__ == "__main__":
    guard.run_main(main)
