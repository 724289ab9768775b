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

Needs numpy (python3-numpy).
"""
import glob, importlib.util, math, os, sys

import numpy as np

here = os.path.dirname(os.path.abspath(__file__))
spec = importlib.util.spec_from_file_location("truth_spread", os.path.join(here, "truth-spread.py"))
ts = importlib.util.module_from_spec(spec)
spec.loader.exec_module(ts)


def main():
    groups = [sorted(glob.glob(pattern)) for pattern in sys.argv[1:]]
    if len(groups) < 2 or any(len(g) < 3 for g in groups):
        sys.exit("block-scatter.py: give at least two globs of at least three observation CSVs each")
    keys = list(ts.statistics(groups[0][0]).keys())
    blocks = [np.array([[s[k] for k in keys] for s in map(ts.statistics, g)]) for g in groups]
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
    main()
