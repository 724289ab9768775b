#!/usr/bin/env python3
"""The Madrid night's inflow scale with the validated crowd, from its whole
nights' own hazards (issue 67, point 2).

The validated crowd's hallway jams only above about 1.4 times the
reconstructed inflow (studies/night-validated-calibration/README.md), and a
night there costs up to an hour and a half of a core: the calibration's
grid of 4-night sets (venues/madrid-arena/calibrations/
madrid-night-validated.json) is out of reach of a 2-core machine. What the
nights already run can say is carried by the cheap forward model's form
(issue 41; studies/night-cheap-model/night-cheap-model.py, whose definitions
this script imports): a hazard log-linear in the arrivals,

    h(m, c) = exp(b0 + b1 (m - 2.25) + b2 (c - 1.6)),

m(t) = s (3 - 2 t/5700) leaving and c(t) = s (0.2 + 3.8 t/5700) entering
persons/s (the scenario's schedule times its scale s), fitted by maximum
likelihood to the whole nights themselves (each night from 300 s to its
event or its end). Two events, each its own hazard:

* the first jam (the cheap model's definition: the hallway's mean speed
  below 0.1 m/s for 30 s), read from night-path.py's CSV;
* the clog for good (the timeline's: from when the night stays clogged to
  its end), read from the nights' ensemble summaries (crowdrecon timeline
  --summaries). A night stopped before its end (no summary; --unfinished)
  is censored at its first jam for it: its clog for good is no earlier.

Along the night ln h is linear in t, so the survival S(t) = exp(-H(t)) has
a closed form (checked here against the numerical integral of the cheap
model's code). The recorded night's scale: for each reading of the record
(its first stop before the 02:18 avalanche as a first jam; the fatal clog
at 03:33 as the clog for good), the likelihood h(t) S(t) of the recorded
time, averaged over draws of the coefficients from their covariance, on a
grid of s; the best s and the values within Δ(-2 ln L) < 3.84.

The intervals' coverage is checked by simulation: synthetic nights drawn
from the fitted hazard at the study's own design (the same scales, the same
number of nights), the hazard refitted to them, a synthetic record drawn at
a known scale (conditioned on happening within the night, as the record's
did), its interval computed as above; the share of intervals that contain
the known scale, with its binomial standard error.

Usage:
  night-hazard.py --paths paths.csv --summaries DIR [--summaries DIR ...]
                  [--unfinished RUN:SCALE ...] -o OUT [--coverage N]

Writes OUT/hazard.md (the tables), OUT/nights.csv (each night's events and
exposure), OUT/hazard.svg and .png (with chromium).

Before any work (scripts/script_guard.py): the CSV must be night-path.py's,
each --summaries a folder of ensemble summaries, every night of the CSV
either summarised or named with --unfinished; OUT must be new, empty or a
previous output of this script (else --force), never an input; every file
is written whole. A bad argument is one line, exit status 2.
"""
import csv
import importlib.util
import json
import math
import os
import random
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
from svg_png import svg_to_png  # noqa: E402
import script_guard as guard  # noqa: E402

_spec = importlib.util.spec_from_file_location("cheap", os.path.join(ROOT, "studies", "night-cheap-model",
                                                                     "night-cheap-model.py"))
cheap = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(cheap)

USE = [0, 1, 2]  # the cheap model's covariates: 1, m - 2.25, c - 1.6
START_S = cheap.NIGHT_AFTER_S
END_S = cheap.NIGHT_END_S
SCALES = [k / 100.0 for k in range(50, 301)]  # the calibration file's range of the scale, 0.5-3
READINGS = [
    ("first jam", "the first stop, released by the first recorded avalanche (02:18)", 1080.0),
    ("clog for good", "the fatal clog (03:33)", cheap.FATAL_CLOG_S),
]
DRAWS = 100
KNOWN_SCALES = (1.3, 1.45, 1.6)


def line(beta, s):
    """ln h(t) = a + b t along the night at scale s (m and c are linear in t)."""
    b0, b1, b2 = beta
    a = b0 + b1 * (3.0 * s - cheap.M0) + b2 * (0.2 * s - cheap.C0)
    b = s * (-2.0 * b1 + 3.8 * b2) / END_S
    return a, b


def cumulative(beta, s, t):
    """H(t) = ∫ h from START_S to t."""
    a, b = line(beta, s)
    if abs(b) * (t - START_S) < 1e-9:
        return math.exp(a + b * START_S) * (t - START_S)
    return (math.exp(a + b * t) - math.exp(a + b * START_S)) / b


def density(beta, s, t):
    """h(t) S(t): the likelihood of an event at t."""
    a, b = line(beta, s)
    return math.exp(a + b * t - cumulative(beta, s, t))


def time_of(beta, s, target):
    """The time t in the night where H(t) = target (H increases: bisection)."""
    lo, hi = START_S, END_S
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if cumulative(beta, s, mid) < target:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def draw_time(beta, s, rng, within=False):
    """An event time from S (None: not by the night's end); within: conditioned on happening by the end."""
    h_end = cumulative(beta, s, END_S)
    if within:
        if h_end < 1e-12:
            return None
        e = -math.log(1.0 - rng.random() * (1.0 - math.exp(-h_end)))
    else:
        e = rng.expovariate(1.0)
        if e >= h_end:
            return None
    return time_of(beta, s, e)


def fit(nights, event):
    """The hazard of `event` fitted to the nights (each night's 10-s pieces to its event or censoring)."""
    return cheap.fit_hazard([p for n in nights for p in cheap.night_pieces(n["scale"], *n[event])], USE)


def scale_interval(draws, target, threshold=3.84):
    """Best scale and the scales within Δ(-2 ln L) < threshold, the coefficients' uncertainty averaged over."""
    return cheap.profile_over(lambda s: sum(density(b, s, target) for b in draws) / len(draws), SCALES, threshold)


def quantile(beta, s, q):
    """The time by which a share q of nights have had the event (None: not within the night)."""
    h = -math.log(1.0 - q)
    if cumulative(beta, s, END_S) < h:
        return None
    return time_of(beta, s, h)


def coverage(nights, event, beta, cov, target_scales, reps, seed):
    """Per known scale, the synthetic studies' Δ(-2 ln L) at the known scale (an interval at threshold q contains it
    when Δ < q), and the count of studies without a fit."""
    rng = random.Random(seed)
    out = {}
    for true_s in target_scales:
        deltas, failed = [], 0
        for _ in range(reps):
            fake = []
            for n in nights:
                t = draw_time(beta, n["scale"], rng)
                fake.append({"scale": n["scale"], event: (t, t if t is not None else END_S)})
            if sum(1 for f in fake if f[event][0] is not None) < 3:
                failed += 1
                continue
            try:
                b_rep, c_rep, _ = fit(fake, event)
            except ZeroDivisionError:
                failed += 1
                continue
            if any(not math.isfinite(x) for x in b_rep) or max(abs(x) for x in b_rep) > 50:
                failed += 1  # no finite maximum (every synthetic event at one end): not an estimate
                continue
            record = draw_time(beta, true_s, rng, within=True)
            if record is None:
                failed += 1
                continue
            draws = cheap.coefficient_draws(b_rep, c_rep, 30, rng.randrange(1 << 30))
            _, _, _, rows = scale_interval(draws, record)
            low = min(v for _, v in rows)
            at_true = min(rows, key=lambda r: abs(r[0] - true_s))[1]
            deltas.append(at_true - low)
        out[true_s] = (deltas, failed)
    return out


def percentile(values, q):
    v = sorted(values)
    if not v:
        return float("nan")
    k = (len(v) - 1) * q
    i = int(math.floor(k))
    return v[i] if i + 1 >= len(v) else v[i] + (v[i + 1] - v[i]) * (k - i)


def read_nights(args):
    paths = cheap.read_paths(args.paths)
    summaries = {}
    for folder in args.summaries:
        for name in sorted(os.listdir(folder)):
            if name.endswith(".json"):
                d = guard.read_json_file(os.path.join(folder, name), "an ensemble run summary (crowdrecon timeline --summaries)")
                if d.get("format") != "crowdrecon-ensemble-run":
                    raise guard.ScriptError(f"{os.path.join(folder, name)}: format {d.get('format')!r}; "
                                            "expected an ensemble run summary (crowdrecon-ensemble-run)")
                summaries[os.path.splitext(name)[0]] = d
    unfinished = {}
    for item in args.unfinished:
        run, _, scale = item.rpartition(":")
        try:
            unfinished[run] = float(scale)
        except ValueError:
            raise guard.ScriptError(f"--unfinished {item}: expected RUN:SCALE (a run of the paths CSV and its inflow scale)")
    nights = []
    for run, rows in paths.items():
        onset = cheap.first_jam([(t, v) for t, v, _, _ in rows], START_S)
        last = rows[-1][0]
        if run in summaries:
            d = summaries[run]
            scale = float(d["scenario"]["timeline"].get("rate_scale", 1.0))
            clog = d.get("clog_for_good_s")
            end = float(d["end_s"])
            if end < END_S - 1.0:
                raise guard.ScriptError(f"{run}: its summary ends at {end:g} s; expected a whole night (to {END_S:g} s)")
            finished = True
            avalanches = [float(a) for a in d.get("avalanche_s", [])]
            falls = [float(f) for f in d.get("fall_s", [])]
        elif run in unfinished:
            scale, clog, end, finished, avalanches, falls = unfinished[run], None, last, False, None, None
        else:
            raise guard.ScriptError(f"{args.paths}: night {run} has no summary in {', '.join(args.summaries)} and is not "
                                    "named with --unfinished RUN:SCALE; expected every night of the CSV accounted for")
        nights.append({
            "run": run, "scale": scale, "finished": finished,
            "first jam": (onset, onset if onset is not None else end),
            # an unfinished night's clog for good is no earlier than its first jam (censored there), or than its end
            "clog for good": ((clog, clog) if clog is not None else (None, end if finished or onset is None else onset)),
            "avalanches": avalanches, "falls": falls, "end_s": end,
        })
    missing = sorted(set(unfinished) - set(paths))
    if missing:
        raise guard.ScriptError(f"--unfinished {missing[0]}: not a night of {args.paths}")
    return nights


def fmt_time(t):
    return cheap.clock(t) if t is not None else "—"


def draw_figure(path, nights, fits, intervals):
    """Left: the share of nights with each event by t at several scales, the nights' own events marked;
    right: -2 ln L of the scale for each reading."""
    w, h = 1100, 520
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" font-size="12">',
           f'<rect width="{w}" height="{h}" fill="white"/>']
    colours = {1.0: "#4d4d4d", 1.3: "#1b9e77", 1.4: "#7570b3", 1.45: "#d95f02", 1.5: "#e7298a", 1.6: "#66a61e"}
    panels = [("first jam", 60), ("clog for good", 380)]
    top, height, width = 60, 330, 270

    def tx(x0, t):
        return x0 + (t - START_S) / (END_S - START_S) * width

    for event, x0 in panels:
        beta = fits[event][0]
        out.append(f'<text x="{x0}" y="{top - 22}" font-weight="bold">{event}: share of nights by then</text>')
        out.append(f'<rect x="{x0}" y="{top}" width="{width}" height="{height}" fill="none" stroke="#999"/>')
        for k in range(0, 11, 2):
            y = top + height - k / 10 * height
            out.append(f'<line x1="{x0}" y1="{y}" x2="{x0 + width}" y2="{y}" stroke="#eee"/>')
            out.append(f'<text x="{x0 - 6}" y="{y + 4}" text-anchor="end">{k / 10:.1f}</text>')
        for clock_t in range(300, 5701, 1200):
            x = tx(x0, clock_t)
            out.append(f'<text x="{x}" y="{top + height + 16}" text-anchor="middle">{cheap.clock(clock_t)[:5]}</text>')
        rec = 1080.0 if event == "first jam" else cheap.FATAL_CLOG_S
        out.append(f'<line x1="{tx(x0, rec)}" y1="{top}" x2="{tx(x0, rec)}" y2="{top + height}" stroke="black" stroke-dasharray="4 3"/>')
        out.append(f'<text x="{tx(x0, rec) + (4 if rec < 3000 else -4)}" y="{top + 14}" '
                   f'text-anchor="{"start" if rec < 3000 else "end"}">recorded {cheap.clock(rec)[:5]}</text>')
        for s, col in colours.items():
            pts = []
            for i in range(0, 101):
                t = START_S + i / 100 * (END_S - START_S)
                p = 1.0 - math.exp(-cumulative(beta, s, t))
                pts.append(f"{tx(x0, t):.1f},{top + height - p * height:.1f}")
            out.append(f'<polyline points="{" ".join(pts)}" fill="none" stroke="{col}" stroke-width="2"/>')
            # the nights run at this scale: their events as marks on the curve's scale, censored ones at the right edge
            for n in nights:
                if abs(n["scale"] - s) > 1e-9:
                    continue
                t, stop = n[event]
                if t is not None:
                    p = 1.0 - math.exp(-cumulative(beta, s, t))
                    out.append(f'<circle cx="{tx(x0, t):.1f}" cy="{top + height - p * height:.1f}" r="5" fill="{col}" stroke="black"/>')
    # right panel: the scale's profile per reading
    x0 = 720
    out.append(f'<text x="{x0}" y="{top - 22}" font-weight="bold">the recorded night\'s scale: Δ(−2 ln L)</text>')
    out.append(f'<rect x="{x0}" y="{top}" width="{width + 60}" height="{height}" fill="none" stroke="#999"/>')
    smin, smax, dmax = 0.5, 3.0, 20.0

    def sx(s):
        return x0 + (s - smin) / (smax - smin) * (width + 60)

    def dy(d):
        return top + height - min(d, dmax) / dmax * height

    for s in (0.5, 1.0, 1.5, 2.0, 2.5, 3.0):
        out.append(f'<text x="{sx(s)}" y="{top + height + 16}" text-anchor="middle">{s:g}</text>')
    out.append(f'<text x="{x0 + (width + 60) / 2}" y="{top + height + 34}" text-anchor="middle">inflow scale s</text>')
    for d in (0, 5, 10, 15, 20):
        out.append(f'<text x="{x0 - 6}" y="{dy(d) + 4}" text-anchor="end">{d}</text>')
    out.append(f'<line x1="{x0}" y1="{dy(3.84)}" x2="{x0 + width + 60}" y2="{dy(3.84)}" stroke="#999" stroke-dasharray="3 3"/>')
    out.append(f'<text x="{x0 + width + 56}" y="{dy(3.84) - 4}" text-anchor="end" fill="#666">3.84</text>')
    for (event, label, _), col in zip(READINGS, ("#1b9e77", "#d95f02")):
        best, lo, hi, rows = intervals[event]
        low = min(v for _, v in rows)
        pts = " ".join(f"{sx(s):.1f},{dy(v - low):.1f}" for s, v in rows)
        out.append(f'<polyline points="{pts}" fill="none" stroke="{col}" stroke-width="2"/>')
    for i, ((event, label, _), col) in enumerate(zip(READINGS, ("#1b9e77", "#d95f02"))):
        best, lo, hi, _ = intervals[event]
        out.append(f'<text x="{x0 + 8}" y="{top + 18 + 16 * i}" fill="{col}">{event} ({label.split("(")[-1][:-1]}): '
                   f'{best:.2f}, {lo:.2f}–{hi:.2f}</text>')
    legend_y = top + height + 46
    out.append(f'<text x="60" y="{legend_y + 4}">inflow scale:</text>')
    for i, (s, col) in enumerate(colours.items()):
        lx = 150 + 90 * i
        out.append(f'<line x1="{lx}" y1="{legend_y}" x2="{lx + 20}" y2="{legend_y}" stroke="{col}" stroke-width="2"/>')
        out.append(f'<text x="{lx + 24}" y="{legend_y + 4}">{s:g}</text>')
    out.append(f'<text x="20" y="{h - 30}" fill="#444">Curves: the hazard fitted to the validated nights, ln h = b0 + b1 (m − 2.25) + b2 (c − 1.6), '
               'at each inflow scale; dots: the nights\' own events, at their scale.</text>')
    out.append(f'<text x="20" y="{h - 12}" fill="#444">Right: the recorded time\'s −2 ln L over the scale, less its least, '
               'averaged over the coefficients\' uncertainty; 3.84 marks the uncalibrated 95 % interval (table: the calibrated ones).</text>')
    out.append("</svg>")
    with guard.whole_file(path) as f:
        f.write("\n".join(out))


OUTPUTS = {"hazard.md": "# The Madrid night's inflow scale with the validated crowd", "nights.csv": "run,scale,",
           "hazard.svg": None, "hazard.png": None}


def main():
    ap = guard.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--paths", required=True, type=guard.existing_file, help="night-path.py's CSV of the whole nights")
    ap.add_argument("--summaries", action="append", required=True, type=guard.existing_dir,
                    help="a folder of the nights' ensemble summaries (repeatable)")
    ap.add_argument("--unfinished", action="append", default=[], help="RUN:SCALE, a night of the CSV stopped before its end")
    ap.add_argument("--coverage", type=guard.nonnegative_int, default=200, help="synthetic records per known scale (0: no check)")
    ap.add_argument("-o", "--out", required=True)
    guard.add_force(ap)
    args = ap.parse_args()
    guard.require_csv_columns(args.paths, cheap.PATHS_COLUMNS, cheap.PATHS_EXPECTED)
    checks = {name: guard.starts_with(head) if head else (guard.is_svg if name.endswith(".svg") else guard.is_png)
              for name, head in OUTPUTS.items()}
    guard.check_outputs(
        [guard.Output("-o", args.out, "a folder of night-hazard.py", folder=True, is_previous=guard.folder_with(checks))]
        + [guard.Output("", os.path.join(args.out, name), f"a {name} of night-hazard.py", check)
           for name, check in checks.items()],
        [("the --paths CSV", args.paths)] + [("a --summaries folder", d) for d in args.summaries], args.force)
    nights = read_nights(args)

    # The closed form against the cheap model's numerical integral (its survival_curve), at the first fit.
    fits = {}
    for event, _, _ in READINGS:
        if sum(1 for n in nights if n[event][0] is not None) < 3:
            raise guard.ScriptError(f"{args.paths}: fewer than 3 nights with a {event}; expected nights at inflow scales "
                                    f"where some jam (three coefficients need at least three events)")
        fits[event] = fit(nights, event)
    beta = fits["first jam"][0]
    for s in (1.0, 1.45):
        numeric = cheap.survival_curve(beta, USE, scale=s, dt=1.0)[-1][1]
        closed = math.exp(-cumulative(beta, s, END_S))
        if abs(numeric - closed) > 1e-4 * max(closed, 1e-3):
            raise RuntimeError(f"internal error: survival {closed} against the numerical {numeric} at s = {s}")

    intervals = {}
    for event, _, target in READINGS:
        b, cv, _ = fits[event]
        intervals[event] = scale_interval(cheap.coefficient_draws(b, cv, DRAWS, 11), target)

    # Coverage: one set of synthetic studies calibrates the threshold (the 95th percentile of Δ at the known scale),
    # an independent set checks both thresholds.
    checks, thresholds, calibrated = {}, {}, {}
    if args.coverage:
        for event, _, target in READINGS:
            b, cv, _ = fits[event]
            calibration = coverage(nights, event, b, cv, KNOWN_SCALES, args.coverage, 20261207)
            thresholds[event] = max(3.84, percentile([d for ds, _ in calibration.values() for d in ds], 0.95))
            checks[event] = coverage(nights, event, b, cv, KNOWN_SCALES, args.coverage, 20261208)
            calibrated[event] = scale_interval(cheap.coefficient_draws(b, cv, DRAWS, 11), target, thresholds[event])

    os.makedirs(args.out, exist_ok=True)
    with guard.whole_file(os.path.join(args.out, "nights.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["run", "scale", "finished", "first_jam_s", "first_jam_exposure_end_s", "clog_for_good_s",
                    "clog_exposure_end_s", "avalanches", "falls"])
        for n in nights:
            w.writerow([n["run"], n["scale"], int(n["finished"]), n["first jam"][0] or "", n["first jam"][1],
                        n["clog for good"][0] or "", n["clog for good"][1],
                        "" if n["avalanches"] is None else len(n["avalanches"]), "" if n["falls"] is None else len(n["falls"])])

    md = ["# The Madrid night's inflow scale with the validated crowd (its whole nights' own hazards)", "",
          f"{len(nights)} whole nights of `madrid-night.json` with the profile `validated` (the entering group's back force "
          f"{cheap.GAMMA0:g}, the profile's), at the inflow scales "
          + ", ".join(f"{s:g} ({sum(1 for n in nights if n['scale'] == s)})" for s in sorted({n['scale'] for n in nights}))
          + ". Written by `night-hazard.py` (its header says the model and the checks).", "",
          "## The nights", "",
          "| night | scale | first jam | clog for good | avalanches | falls |", "| --- | --- | --- | --- | --- | --- |"]
    for n in sorted(nights, key=lambda n: (n["scale"], n["run"])):
        cl = n["clog for good"]
        clog = fmt_time(cl[0]) if cl[0] is not None else (
            "none" if n["finished"] else f"not known (stopped at {fmt_time(n['end_s'])}; no earlier than {fmt_time(cl[1])})")
        md.append(f"| {n['run']} | {n['scale']:g} | {fmt_time(n['first jam'][0]) if n['first jam'][0] is not None else 'none'} | "
                  f"{clog} | {'—' if n['avalanches'] is None else len(n['avalanches'])} | "
                  f"{'—' if n['falls'] is None else len(n['falls'])} |")
    md += ["", "## The fitted hazards", "",
           "ln h = b0 + b1 (m − 2.25) + b2 (c − 1.6), h per s; maximum likelihood over each night's 10-s pieces from 02:05.", "",
           "| event | events / nights | b0 | b1 (per leaving person/s) | b2 (per entering person/s) |", "| --- | --- | --- | --- | --- |"]
    for event, _, _ in READINGS:
        b, cv, _ = fits[event]
        k = sum(1 for n in nights if n[event][0] is not None)
        md.append(f"| {event} | {k} / {len(nights)} | " + " | ".join(f"{b[i]:.2f} ± {math.sqrt(cv[i][i]):.2f}" for i in range(3)) + " |")
    md += ["", "Predicted from the fits (10 % / median / 90 % of nights; — : fewer by the night's end):", "",
           "| scale | first jam | clog for good |", "| --- | --- | --- |"]
    for s in (1.0, 1.2, 1.3, 1.4, 1.45, 1.5, 1.6, 1.8, 2.0):
        cells = []
        for event, _, _ in READINGS:
            b = fits[event][0]
            cells.append(" / ".join(fmt_time(quantile(b, s, q)) for q in (0.1, 0.5, 0.9)))
        md.append(f"| {s:g} | " + " | ".join(cells) + " |")
    md += ["", "## The recorded night's scale", "",
           f"Likelihood h(t) S(t) of the recorded time, averaged over {DRAWS} draws of the coefficients; s on a grid of 0.01 "
           "over 0.5–3 (the calibration file's range).", "",
           "| reading | best s | s within Δ(−2 ln L) < 3.84 | at the best s: 10 % / median / 90 % |", "| --- | --- | --- | --- |"]
    for event, label, _ in READINGS:
        best, lo, hi, _ = intervals[event]
        b = fits[event][0]
        md.append(f"| {label}, as the {event} | {best:.2f} | {lo:.2f}–{hi:.2f} | "
                  + " / ".join(fmt_time(quantile(b, best, q)) for q in (0.1, 0.5, 0.9)) + " |")
    if checks:
        md += ["", "## Coverage of the intervals (simulated)", "",
               f"Per known scale, {args.coverage} synthetic studies: the design's nights drawn from the fitted hazard, the hazard "
               "refitted, a record drawn at the known scale (within the night), its profile (30 coefficient draws). "
               "Studies where the synthetic nights had fewer than 3 events or no finite fit are not counted (\"no fit\"). "
               "A first set of studies gives the calibrated threshold (the 95th percentile of Δ(−2 ln L) at the known "
               "scale, pooled, at least 3.84); an independent second set checks both thresholds.", "",
               "| event | known scale | Δ < 3.84 contains it | Δ < calibrated threshold contains it | no fit |",
               "| --- | --- | --- | --- | --- |"]
        for event, _, _ in READINGS:
            q = thresholds[event]
            for s, (deltas, failed) in checks[event].items():
                cells = []
                for thr in (3.84, q):
                    n = len(deltas)
                    hits = sum(1 for d in deltas if d < thr)
                    share = hits / n if n else float("nan")
                    se = math.sqrt(share * (1 - share) / n) if n else float("nan")
                    cells.append(f"{hits} of {n}: {100 * share:.1f} % ± {100 * se:.1f}")
                md.append(f"| {event} | {s:g} | " + " | ".join(cells) + f" | {failed} |")
        md += ["", "The recorded night's scale with the calibrated thresholds:", "",
               "| reading | threshold | best s | s within it |", "| --- | --- | --- | --- |"]
        for event, label, _ in READINGS:
            best, lo, hi, _ = calibrated[event]
            md.append(f"| {label}, as the {event} | {thresholds[event]:.2f} | {best:.2f} | {lo:.2f}–{hi:.2f} |")
    with guard.whole_file(os.path.join(args.out, "hazard.md")) as f:
        f.write("\n".join(md) + "\n")
    svg = os.path.join(args.out, "hazard.svg")
    draw_figure(svg, nights, fits, intervals)
    svg_to_png(svg, os.path.join(args.out, "hazard.png"), 1100, 520)
    print("\n".join(md))


if __name__ == "__main__":
    guard.run_main(main)
