#!/usr/bin/env python3
"""The hallway's Γ and λ sweep with the validated crowd against its base (issue 64): per variant and grid point
the two seeds' regimes, and per variant the counts of runs in each regime, the mean clogged fraction of the
counter-flow group, the mean speed and the mean lane order, beside the bodies sweep's thorax runs at the same
points (the profile's Γ 1.2, λ 27).

Usage: gamma-lambda-table.py GAMMA-LAMBDA-RESULTS.csv BODIES-RESULTS.csv -o TABLE.md [--base-variant thorax]

Both CSVs are crowdrecon sweep results (results.csv); -o must not be one of them. Written whole.
"""
import csv
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(HERE)), "scripts"))
import script_guard as guard  # noqa: E402

LETTER = {"lanes": "l", "clogging": "c", "avalanches": "a", "unclassified": "u", "free flow": "f", "frozen": "z"}
DENS, CF = "population.density_per_m2", "population.counter_flow_fraction"
METRICS = [("clogged_fraction_g1", "clogged fraction, counter-flow group"), ("mean_speed_m_per_s", "mean speed, m/s"),
           ("mean_lane_order", "mean lane order"), ("max_load_n", "max load, N")]


def main():
    ap = guard.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("sweep", type=guard.existing_file)
    ap.add_argument("base", type=guard.existing_file)
    ap.add_argument("-o", "--out", required=True)
    ap.add_argument("--base-variant", default="thorax", help="the base's variant in BODIES-RESULTS.csv (default thorax)")
    guard.add_force(ap)
    args = ap.parse_args()
    for path in (args.sweep, args.base):
        guard.require_csv_columns(path, ["variant", "seed", DENS, CF, "regime"], "a crowdrecon sweep's results.csv")
    guard.check_outputs([guard.Output("-o", args.out, "a table of gamma-lambda-table.py",
                                      guard.starts_with("# The hallway's Γ and λ"))],
                        [("the sweep's results", args.sweep), ("the base's results", args.base)], args.force)
    rows = list(csv.DictReader(open(args.sweep)))
    points = sorted({(float(r[DENS]), float(r[CF])) for r in rows})
    base = [dict(r, variant="base (Γ 1.2, λ 27)") for r in csv.DictReader(open(args.base))
            if r["variant"] == args.base_variant and (float(r[DENS]), float(r[CF])) in points]
    if not base:
        raise guard.ScriptError(f"{args.base}: no runs of the variant {args.base_variant!r} at the sweep's points; "
                                "expected the base's runs at the same densities and counter-flows (--base-variant)")
    variants = ["base (Γ 1.2, λ 27)"] + sorted({r["variant"] for r in rows})
    allrows = base + rows
    dens = sorted({p[0] for p in points})
    cfs = sorted({p[1] for p in points}, reverse=True)

    def cell(v, d, c):
        rs = sorted((r for r in allrows if r["variant"] == v and float(r[DENS]) == d and float(r[CF]) == c),
                    key=lambda r: int(r["seed"]))
        return "".join(LETTER.get(r["regime"], "?") for r in rs) or "—"

    md = ["# The hallway's Γ and λ with the validated crowd (thorax bodies, 2 seeds a point)", "",
          f"Written by `gamma-lambda-table.py` from `{args.sweep}` and the base's thorax rows of `{args.base}`. "
          "Regimes per seed (seeds 1, 2): l lanes, c clogging, a avalanches, u unclassified (intermittent: stops "
          "and releases, fewer than two avalanches in the stationary stage, not frozen).", "",
          "| variant | counter-flow | " + " | ".join(f"{d:g} /m²" for d in dens) + " |",
          "| --- | --- | " + " | ".join("---" for _ in dens) + " |"]
    for v in variants:
        for c in cfs:
            md.append(f"| {v} | {100 * c:.0f} % | " + " | ".join(cell(v, d, c) for d in dens) + " |")

    def per_point(v, key):
        out = []
        for d, c in points:
            vals = [float(r[key]) for r in allrows if r["variant"] == v and float(r[DENS]) == d
                    and float(r[CF]) == c and r.get(key) not in (None, "")]
            out.append(sum(vals) / len(vals) if vals else float("nan"))
        return out

    def sign_flip(diffs):
        """Exact two-sided sign-flip test of the mean difference over the points."""
        n, obs = len(diffs), abs(sum(diffs))
        hits = sum(1 for mask in range(1 << n)
                   if abs(sum(x if mask >> i & 1 else -x for i, x in enumerate(diffs))) >= obs - 1e-12)
        return hits / (1 << n)

    md += ["", "| variant | runs | lanes | clogging | avalanches | unclassified | "
           + " | ".join(name for _, name in METRICS) + " | clogged fraction against the base: mean difference over "
           f"the {len(points)} points, exact sign-flip p |", "| --- | --- | --- | --- | --- | --- | "
           + " | ".join("---" for _ in METRICS) + " | --- |"]
    ref = per_point(variants[0], "clogged_fraction_g1")
    for v in variants:
        rs = [r for r in allrows if r["variant"] == v]
        counts = [sum(1 for r in rs if r["regime"] == k) for k in ("lanes", "clogging", "avalanches", "unclassified")]
        means = []
        for key, _ in METRICS:
            vals = [float(r[key]) for r in rs if r.get(key) not in (None, "")]
            means.append(f"{sum(vals) / len(vals):.3g}" if vals else "—")
        diffs = [a - b for a, b in zip(per_point(v, "clogged_fraction_g1"), ref)]
        test = "—" if v == variants[0] else f"{sum(diffs) / len(diffs):+.3f}, p = {sign_flip(diffs):.3f}"
        md.append(f"| {v} | {len(rs)} | " + " | ".join(map(str, counts)) + " | " + " | ".join(means) + f" | {test} |")
    with guard.whole_file(args.out) as f:
        f.write("\n".join(md) + "\n")
    print("\n".join(md))


if __name__ == "__main__":
    guard.run_main(main)
