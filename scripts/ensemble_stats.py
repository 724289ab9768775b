"""Two ensembles of runs compared as distributions (issue 42, point 2).

A chaotic crowd diverges from any change, so two ways of running it (the
fixed and the adaptive step) are compared over seeds, not run by run: the
exact two-sided permutation test of the difference of the two ensembles'
means over every split of the pooled runs into two groups of the first's
size. "Same" when p >= 0.05 (with K runs a side the test sees differences
of about one seed-to-seed standard deviation, no smaller).
"""
import itertools
import math


def permutation_p(a, b):
    pooled = list(a) + list(b)
    k = len(a)
    observed = abs(sum(a) / k - sum(b) / len(b))
    count = total = 0
    for chosen in itertools.combinations(range(len(pooled)), k):
        s = set(chosen)
        x = [pooled[i] for i in chosen]
        y = [pooled[i] for i in range(len(pooled)) if i not in s]
        total += 1
        count += abs(sum(x) / len(x) - sum(y) / len(y)) >= observed - 1e-12
    return count / total


def mean_sd(v):
    m = sum(v) / len(v)
    return m, math.sqrt(sum((x - m) ** 2 for x in v) / max(1, len(v) - 1))
