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

The entering crowd's push (issue 67 point 2): each night's entering group's
back force Γ is read from its summary's scenario (an event at the start
setting the group "counter"'s back_force_gamma, else the model's). Where the
nights' Γ differ, both hazards get the cheap model's term b3 ln(Γ/1.2), the
single-reading intervals above are those at the profile's Γ 1.2, and both
readings together give the record's (s, Γ): their likelihoods multiplied
(the two events independent given s and Γ) on a grid of s (0.5-3) and Γ
(0.3-4.8, the calibration file's ranges), the region within Δ(-2 ln L) <
5.99, its threshold calibrated and checked by simulation as above (known
points (1.3, 1.2), (1.45, 1.2), (1.45, 4.8); a coarser grid).

Usage:
  night-hazard.py --paths paths.csv --summaries DIR [--summaries DIR ...]
                  [--unfinished RUN:SCALE[:GAMMA] ...] -o OUT [--coverage N]

Writes OUT/hazard.md (the tables), OUT/nights.csv (each night's events and
exposure), OUT/hazard.svg and .png (with chromium), and where the nights' Γ
differ OUT/joint.svg and .png (the record's (s, Γ)).

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

USE = [0, 1, 2]  # the cheap model's covariates: 1, m - 2.25, c - 1.6 (and 3, ln(Γ/1.2), when the nights' Γ differ)
GAMMA0 = cheap.GAMMA0
START_S = cheap.NIGHT_AFTER_S
END_S = cheap.NIGHT_END_S
SCALES = [k / 100.0 for k in range(50, 301)]  # the calibration file's range of the scale, 0.5-3
READINGS = [
    ("first jam", "the first stop, released by the first recorded avalanche (02:18)", 1080.0),
    ("clog for good", "the fatal clog (03:33)", cheap.FATAL_CLOG_S),
]
DRAWS = 100
KNOWN_SCALES = (1.3, 1.45, 1.6)


def line(beta, s, g=GAMMA0):
    """ln h(t) = a + b t along the night at scale s and the entering group's back force g (m and c are linear
    in t)."""
    b0, b1, b2 = beta[:3]
    a = b0 + b1 * (3.0 * s - cheap.M0) + b2 * (0.2 * s - cheap.C0)
    if len(beta) > 3:
        a += beta[3] * math.log(g / GAMMA0)
    b = s * (-2.0 * b1 + 3.8 * b2) / END_S
    return a, b


def cumulative(beta, s, t, g=GAMMA0):
    """H(t) = ∫ h from START_S to t."""
    a, b = line(beta, s, g)
    if abs(b) * (t - START_S) < 1e-9:
        return math.exp(a + b * START_S) * (t - START_S)
    return (math.exp(a + b * t) - math.exp(a + b * START_S)) / b


def density(beta, s, t, g=GAMMA0):
    """h(t) S(t): the likelihood of an event at t."""
    a, b = line(beta, s, g)
    return math.exp(a + b * t - cumulative(beta, s, t, g))


def time_of(beta, s, target, g=GAMMA0):
    """The time t in the night where H(t) = target (H increases: bisection)."""
    lo, hi = START_S, END_S
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if cumulative(beta, s, mid, g) < target:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def draw_time(beta, s, rng, within=False, g=GAMMA0):
    """An event time from S (None: not by the night's end); within: conditioned on happening by the end."""
    h_end = cumulative(beta, s, END_S, g)
    if within:
        if h_end < 1e-12:
            return None
        e = -math.log(1.0 - rng.random() * (1.0 - math.exp(-h_end)))
    else:
        e = rng.expovariate(1.0)
        if e >= h_end:
            return None
    return time_of(beta, s, e, g)


def fit(nights, event):
    """The hazard of `event` fitted to the nights (each night's 10-s pieces to its event or censoring)."""
    return cheap.fit_hazard([p for n in nights for p in cheap.night_pieces(n["scale"], *n[event], gamma=n["gamma"])],
                            USE)


def scale_interval(draws, target, threshold=3.84):
    """Best scale and the scales within Δ(-2 ln L) < threshold, the coefficients' uncertainty averaged over."""
    return cheap.profile_over(lambda s: sum(density(b, s, target) for b in draws) / len(draws), SCALES, threshold)


def quantile(beta, s, q, g=GAMMA0):
    """The time by which a share q of nights have had the event (None: not within the night)."""
    h = -math.log(1.0 - q)
    if cumulative(beta, s, END_S, g) < h:
        return None
    return time_of(beta, s, h, g)


def synthetic_refit(nights, event, beta, rng, min_events):
    """A synthetic study: the design's nights (their scales and Γ) drawn from the hazard `beta` of `event`, the hazard
    refitted to them; (coefficients, covariance), or None with fewer than min_events events or no fit."""
    fake = []
    for n in nights:
        t = draw_time(beta, n["scale"], rng, g=n["gamma"])
        fake.append({"scale": n["scale"], "gamma": n["gamma"], event: (t, t if t is not None else END_S)})
    if sum(1 for f in fake if f[event][0] is not None) < min_events:
        return None
    try:
        b_rep, c_rep, _ = fit(fake, event)
    except ZeroDivisionError:
        return None
    return b_rep, c_rep


def finite_fit(b_rep):
    """A refit with a finite maximum (not every synthetic event at one end of the night)."""
    return all(math.isfinite(x) for x in b_rep) and max(abs(x) for x in b_rep) <= 50


def coverage(nights, event, beta, cov, target_scales, reps, seed):
    """Per known scale, the synthetic studies' Δ(-2 ln L) at the known scale (an interval at threshold q contains it
    when Δ < q), and the count of studies without a fit."""
    rng = random.Random(seed)
    out = {}
    for true_s in target_scales:
        deltas, failed = [], 0
        for _ in range(reps):
            refit = synthetic_refit(nights, event, beta, rng, 3)
            if refit is None or not finite_fit(refit[0]):
                failed += 1
                continue
            b_rep, c_rep = refit
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


GAMMAS = [0.3 * 2.0 ** (k / 4.0) for k in range(17)]  # the calibration file's range of the entering Γ, 0.3-4.8
JOINT_KNOWN = ((1.3, 1.2), (1.45, 1.2), (1.45, 4.8))
COARSE_SCALES = [k / 50.0 for k in range(25, 151)]  # the coverage studies' grid: s by 0.02, Γ by half octaves
COARSE_GAMMAS = GAMMAS[::2]


def joint_likelihood(draws_by_event, targets, s, g):
    """The recorded times' joint likelihood at (s, Γ): the product over the readings of h(t) S(t), each averaged
    over its hazard's coefficient draws (the readings' events taken as independent given s and Γ)."""
    out = 1.0
    for event, target in targets.items():
        draws = draws_by_event[event]
        out *= sum(density(b, s, target, g) for b in draws) / len(draws)
    return out


def joint_profile(draws_by_event, targets, scales=None, gammas=None):
    """-2 ln L of the joint likelihood on the (s, Γ) grid: {(s, Γ): value}."""
    return {(s, g): -2.0 * math.log(max(joint_likelihood(draws_by_event, targets, s, g), 1e-300))
            for s in (scales or SCALES) for g in (gammas or GAMMAS)}


def joint_region(grid, threshold):
    """The best (s, Γ) and the ranges of s and Γ over the cells within Δ(-2 ln L) < threshold."""
    best = min(grid, key=grid.get)
    inside = [k for k, v in grid.items() if v - grid[best] < threshold]
    return best, (min(k[0] for k in inside), max(k[0] for k in inside)), (min(k[1] for k in inside),
                                                                           max(k[1] for k in inside))


def joint_coverage(nights, fits, targets, reps, seed):
    """Per known (s, Γ): Δ(-2 ln L) of the joint likelihood at the known point against the coarse grid's least, over
    synthetic studies (each event's nights drawn from its fitted hazard at the design's scales and Γ, both hazards
    refitted, a record drawn at the known point, each event within the night), and the studies without a fit."""
    rng = random.Random(seed)
    out = {}
    for known in JOINT_KNOWN:
        deltas, failed = [], 0
        for _ in range(reps):
            draws_by_event, record, ok = {}, {}, True
            for event in targets:
                beta = fits[event][0]
                refit = synthetic_refit(nights, event, beta, rng, len(USE))
                if refit is None:
                    ok = False
                    break
                b_rep, c_rep = refit
                t_rec = draw_time(beta, known[0], rng, within=True, g=known[1])
                if t_rec is None or not finite_fit(b_rep):
                    ok = False
                    break
                draws_by_event[event] = cheap.coefficient_draws(b_rep, c_rep, 20, rng.randrange(1 << 30))
                record[event] = t_rec
            if not ok:
                failed += 1
                continue
            grid = joint_profile(draws_by_event, record, COARSE_SCALES, COARSE_GAMMAS)
            at_known = -2.0 * math.log(max(joint_likelihood(draws_by_event, record, *known), 1e-300))
            deltas.append(at_known - min(grid.values()))
        out[known] = (deltas, failed)
    return out


def contains_cell(deltas, threshold):
    """A coverage table's cell: how many synthetic studies' Δ(-2 ln L) at the known point fall below the threshold,
    and that share with its binomial standard error."""
    n = len(deltas)
    hits = sum(1 for d in deltas if d < threshold)
    share = hits / n if n else float("nan")
    se = math.sqrt(share * (1 - share) / n) if n else float("nan")
    return f"{hits} of {n}: {100 * share:.1f} % ± {100 * se:.1f}"


def percentile(values, q):
    v = sorted(values)
    if not v:
        return float("nan")
    k = (len(v) - 1) * q
    i = int(math.floor(k))
    return v[i] if i + 1 >= len(v) else v[i] + (v[i + 1] - v[i]) * (k - i)


def entering_gamma(scenario, where):
    """The entering group's back force of a night: an event at the start setting the group "counter"'s
    back_force_gamma, else the model's (the profile's)."""
    gamma = float(scenario.get("model", {}).get("back_force_gamma", GAMMA0))
    for k, e in enumerate(scenario.get("timeline", {}).get("events") or []):
        if "back_force_gamma" not in (e.get("set") or {}):
            continue
        if e.get("group") not in (None, "counter"):
            what = f"of the group {e.get('group')!r}"
        elif float(e.get("time_s", 0.0)) > 0.0:
            what = f"at {e.get('time_s')} s"
        else:
            what = None
        if what:
            raise guard.ScriptError(f"{where}: scenario.timeline.events[{k}] sets back_force_gamma {what}; "
                                    "expected only the entering group's (\"counter\"), set at the start (time_s 0)")
        gamma = float(e["set"]["back_force_gamma"])
    if not gamma > 0.0:
        raise guard.ScriptError(f"{where}: the entering group's back_force_gamma {gamma:g}; expected a positive number")
    return gamma


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
                d["_path"] = os.path.join(folder, name)
                summaries[os.path.splitext(name)[0]] = d
    unfinished = {}
    for item in args.unfinished:
        parts = item.split(":")
        try:
            if len(parts) == 2:
                unfinished[parts[0]] = (float(parts[1]), GAMMA0)
            elif len(parts) == 3:
                unfinished[parts[0]] = (float(parts[1]), float(parts[2]))
            else:
                raise ValueError
            if not unfinished[parts[0]][1] > 0.0:
                raise ValueError
        except ValueError:
            raise guard.ScriptError(f"--unfinished {item}: expected RUN:SCALE or RUN:SCALE:GAMMA (a run of the paths CSV, "
                                    f"its inflow scale and its entering group's positive back force, default {GAMMA0:g})")
    nights = []
    for run, rows in paths.items():
        onset = cheap.first_jam([(t, v) for t, v, _, _ in rows], START_S)
        last = rows[-1][0]
        if run in summaries:
            d = summaries[run]
            scale = float(d["scenario"]["timeline"].get("rate_scale", 1.0))
            gamma = entering_gamma(d["scenario"], d["_path"])
            clog = d.get("clog_for_good_s")
            end = float(d["end_s"])
            if end < END_S - 1.0:
                raise guard.ScriptError(f"{run}: its summary ends at {end:g} s; expected a whole night (to {END_S:g} s)")
            finished = True
            avalanches = [float(a) for a in d.get("avalanche_s", [])]
            falls = [float(f) for f in d.get("fall_s", [])]
        elif run in unfinished:
            (scale, gamma), clog, end, finished, avalanches, falls = unfinished[run], None, last, False, None, None
        else:
            raise guard.ScriptError(f"{args.paths}: night {run} has no summary in {', '.join(args.summaries)} and is not "
                                    "named with --unfinished RUN:SCALE; expected every night of the CSV accounted for")
        nights.append({
            "run": run, "scale": scale, "gamma": gamma, "finished": finished,
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
    finish_svg(path, out, h, ["Curves: the hazard fitted to the validated nights, ln h = b0 + b1 (m − 2.25) + b2 (c − 1.6), "
                              "at each inflow scale; dots: the nights' own events, at their scale.",
                              "Right: the recorded time's −2 ln L over the scale, less its least, averaged over the "
                              "coefficients' uncertainty; 3.84 marks the uncalibrated 95 % interval (table: the calibrated ones)."])


def finish_svg(path, out, h, captions):
    """The figure's captions, one line each from 18 px apart up to the bottom edge, and the figure written whole."""
    for k, text in enumerate(captions):
        y = h - 12 - 18 * (len(captions) - 1 - k)
        out.append(f'<text x="20" y="{y}" fill="#444">{text.replace("<", "&lt;")}</text>')
    out.append("</svg>")
    with guard.whole_file(path) as f:
        f.write("\n".join(out))


def draw_joint(path, joint):
    """The joint Δ(−2 ln L) over (s, Γ): cells shaded by Δ, the region's cells outlined, the best marked."""
    w, h, x0, top, pw, ph = 700, 540, 80, 50, 580, 380
    grid = joint["grid"]
    low = min(grid.values())
    smin, smax = SCALES[0], SCALES[-1]
    lg0, lg1 = math.log(GAMMAS[0]), math.log(GAMMAS[-1])
    thr = joint["threshold"] or 5.99
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" font-size="12">',
           f'<rect width="{w}" height="{h}" fill="white"/>',
           f'<text x="{x0}" y="{top - 20}" font-weight="bold">The recorded night: Δ(−2 ln L) of the inflow scale and the '
           'entering group\'s push</text>',
           f'<clipPath id="plot"><rect x="{x0}" y="{top}" width="{pw}" height="{ph}"/></clipPath>', '<g clip-path="url(#plot)">']
    ds = (SCALES[1] - SCALES[0]) / (smax - smin) * pw
    dg = ph / (len(GAMMAS) - 1)
    for (sc, g), v in grid.items():
        d = v - low
        x = x0 + (sc - smin) / (smax - smin) * pw - ds / 2
        y = top + ph - (math.log(g) - lg0) / (lg1 - lg0) * ph - dg / 2
        shade = max(0.0, min(1.0, d / 30.0))
        grey = int(40 + 215 * shade)
        fill = f"rgb({grey},{grey},255)" if d < thr else f"rgb({grey},{grey},{grey})"
        out.append(f'<rect x="{x:.1f}" y="{y:.1f}" width="{ds + 0.6:.1f}" height="{dg + 0.6:.1f}" fill="{fill}" '
                   'shape-rendering="crispEdges"/>')
    out.append('</g>')
    (bs, bg), _, _ = joint.get("calibrated") or joint["region"]
    out.append(f'<circle cx="{x0 + (bs - smin) / (smax - smin) * pw:.1f}" '
               f'cy="{top + ph - (math.log(bg) - lg0) / (lg1 - lg0) * ph:.1f}" r="6" fill="#d95f02" stroke="black"/>')
    out.append(f'<rect x="{x0}" y="{top}" width="{pw}" height="{ph}" fill="none" stroke="#999"/>')
    for sc in (0.5, 1.0, 1.5, 2.0, 2.5, 3.0):
        out.append(f'<text x="{x0 + (sc - smin) / (smax - smin) * pw}" y="{top + ph + 16}" text-anchor="middle">{sc:g}</text>')
    out.append(f'<text x="{x0 + pw / 2}" y="{top + ph + 34}" text-anchor="middle">inflow scale s</text>')
    for g in GAMMAS[::4]:
        out.append(f'<text x="{x0 - 6}" y="{top + ph - (math.log(g) - lg0) / (lg1 - lg0) * ph + 4:.1f}" '
                   f'text-anchor="end">{g:g}</text>')
    out.append(f'<text x="18" y="{top + ph / 2}" transform="rotate(-90 18 {top + ph / 2})" text-anchor="middle">'
               'entering group\'s back force Γ</text>')
    finish_svg(path, out, h, [f"Blue: within Δ < {thr:.2f}"
                              + (" (calibrated by simulation)" if joint["threshold"] else " (two parameters, uncalibrated)")
                              + "; darker: more likely. Dot: the best (s, Γ).",
                              "Both readings of the record at once: the first stop before 02:18 as the first jam,",
                              "the fatal clog at 03:33 as the clog for good (hazards fitted to the validated nights)."])


OUTPUTS = {"hazard.md": "# The Madrid night's inflow scale with the validated crowd", "nights.csv": "run,scale,",
           "hazard.svg": None, "hazard.png": None, "joint.svg": None, "joint.png": None}


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
    global USE
    gammas_run = sorted({n["gamma"] for n in nights})
    if len(gammas_run) > 1:
        USE = [0, 1, 2, 3]  # the nights' entering Γ differ: its term can be fitted
    targets = {event: target for event, _, target in READINGS}

    # The closed form against the cheap model's numerical integral (its survival_curve), at the first fit.
    fits = {}
    for event, _, _ in READINGS:
        if sum(1 for n in nights if n[event][0] is not None) < len(USE):
            raise guard.ScriptError(f"{args.paths}: fewer than {len(USE)} nights with a {event}; expected nights at inflow "
                                    f"scales where some jam ({len(USE)} coefficients need at least as many events)")
        fits[event] = fit(nights, event)
    beta = fits["first jam"][0]
    for s, g in ((1.0, GAMMA0), (1.45, GAMMA0)) + (((1.45, 4.8),) if len(USE) > 3 else ()):
        numeric = cheap.survival_curve(beta, USE, gamma=g, scale=s, dt=1.0)[-1][1]
        closed = math.exp(-cumulative(beta, s, END_S, g))
        if abs(numeric - closed) > 1e-4 * max(closed, 1e-3):
            raise RuntimeError(f"internal error: survival {closed} against the numerical {numeric} at s = {s}, Γ = {g}")

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

    # The entering group's push beside the scale, where the nights' Γ differ: both readings at once over (s, Γ).
    joint = None
    if len(USE) > 3:
        draws_by_event = {event: cheap.coefficient_draws(fits[event][0], fits[event][1], DRAWS, 11) for event in targets}
        grid = joint_profile(draws_by_event, targets)
        joint = {"grid": grid, "region": joint_region(grid, 5.99), "threshold": None, "check": None}
        if args.coverage:
            reps = max(1, args.coverage // 2)
            calibration = joint_coverage(nights, fits, targets, reps, 20261209)
            joint["threshold"] = max(5.99, percentile([d for ds, _ in calibration.values() for d in ds], 0.95))
            joint["check"] = joint_coverage(nights, fits, targets, reps, 20261210)
            joint["calibrated"] = joint_region(grid, joint["threshold"])

    os.makedirs(args.out, exist_ok=True)
    with guard.whole_file(os.path.join(args.out, "nights.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["run", "scale", "gamma", "finished", "first_jam_s", "first_jam_exposure_end_s", "clog_for_good_s",
                    "clog_exposure_end_s", "avalanches", "falls"])
        for n in nights:
            w.writerow([n["run"], n["scale"], n["gamma"], int(n["finished"]), n["first jam"][0] or "", n["first jam"][1],
                        n["clog for good"][0] or "", n["clog for good"][1],
                        "" if n["avalanches"] is None else len(n["avalanches"]), "" if n["falls"] is None else len(n["falls"])])

    md = ["# The Madrid night's inflow scale with the validated crowd (its whole nights' own hazards)", "",
          f"{len(nights)} whole nights of `madrid-night.json` with the profile `validated` ("
          + (f"the entering group's back force {GAMMA0:g}, the profile's" if len(USE) == 3 else
             "the entering group's back force Γ " + ", ".join(f"{g:g} ({sum(1 for n in nights if n['gamma'] == g)})"
                                                             for g in gammas_run))
          + "), at the inflow scales "
          + ", ".join(f"{s:g} ({sum(1 for n in nights if n['scale'] == s)})" for s in sorted({n['scale'] for n in nights}))
          + ". Written by `night-hazard.py` (its header says the model and the checks).", "",
          "## The nights", "",
          "| night | scale | " + ("Γ entering | " if len(USE) > 3 else "") + "first jam | clog for good | avalanches | falls |",
          "| --- | --- | " + ("--- | " if len(USE) > 3 else "") + "--- | --- | --- | --- |"]
    for n in sorted(nights, key=lambda n: (n["scale"], n["run"])):
        cl = n["clog for good"]
        clog = fmt_time(cl[0]) if cl[0] is not None else (
            "none" if n["finished"] else f"not known (stopped at {fmt_time(n['end_s'])}; no earlier than {fmt_time(cl[1])})")
        md.append(f"| {n['run']} | {n['scale']:g} | " + (f"{n['gamma']:g} | " if len(USE) > 3 else "")
                  + f"{fmt_time(n['first jam'][0]) if n['first jam'][0] is not None else 'none'} | "
                  f"{clog} | {'—' if n['avalanches'] is None else len(n['avalanches'])} | "
                  f"{'—' if n['falls'] is None else len(n['falls'])} |")
    md += ["", "## The fitted hazards", "",
           "ln h = b0 + b1 (m − 2.25) + b2 (c − 1.6)" + (" + b3 ln(Γ/1.2)" if len(USE) > 3 else "")
           + ", h per s; maximum likelihood over each night's 10-s pieces from 02:05.", "",
           "| event | events / nights | b0 | b1 (per leaving person/s) | b2 (per entering person/s) |"
           + (" b3 (per ln(Γ/1.2) of the entering group) |" if len(USE) > 3 else ""),
           "| --- | --- | --- | --- | --- |" + (" --- |" if len(USE) > 3 else "")]
    for event, _, _ in READINGS:
        b, cv, _ = fits[event]
        k = sum(1 for n in nights if n[event][0] is not None)
        md.append(f"| {event} | {k} / {len(nights)} | " + " | ".join(f"{b[i]:.2f} ± {math.sqrt(cv[i][i]):.2f}" for i in range(len(USE))) + " |")
    for g in (gammas_run if len(USE) > 3 else [GAMMA0]):
        md += ["", "Predicted from the fits (10 % / median / 90 % of nights; — : fewer by the night's end)"
               + (f", the entering group's Γ {g:g}" if len(USE) > 3 else "") + ":", "",
               "| scale | first jam | clog for good |", "| --- | --- | --- |"]
        for s in (1.0, 1.2, 1.3, 1.4, 1.45, 1.5, 1.6, 1.8, 2.0):
            cells = []
            for event, _, _ in READINGS:
                b = fits[event][0]
                cells.append(" / ".join(fmt_time(quantile(b, s, q, g)) for q in (0.1, 0.5, 0.9)))
            md.append(f"| {s:g} | " + " | ".join(cells) + " |")
    md += ["", "## The recorded night's scale", "",
           f"Likelihood h(t) S(t) of the recorded time, averaged over {DRAWS} draws of the coefficients; s on a grid of 0.01 "
           "over 0.5–3 (the calibration file's range)"
           + (f"; the entering group's Γ at the profile's {GAMMA0:g} (both together over s and Γ: the next section)"
              if len(USE) > 3 else "") + ".", "",
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
                md.append(f"| {event} | {s:g} | " + " | ".join(contains_cell(deltas, thr) for thr in (3.84, q))
                          + f" | {failed} |")
        md += ["", "The recorded night's scale with the calibrated thresholds:", "",
               "| reading | threshold | best s | s within it |", "| --- | --- | --- | --- |"]
        for event, label, _ in READINGS:
            best, lo, hi, _ = calibrated[event]
            md.append(f"| {label}, as the {event} | {thresholds[event]:.2f} | {best:.2f} | {lo:.2f}–{hi:.2f} |")
    if joint:
        (bs, bg), (s_lo, s_hi), (g_lo, g_hi) = joint["region"]
        md += ["", "## The recorded night's scale and push together", "",
               "Both readings at once (the first stop before 02:18 as the first jam, the fatal clog at 03:33 as the clog "
               "for good), their likelihoods multiplied (the two events taken as independent given s and Γ), each "
               f"averaged over {DRAWS} draws of its hazard's coefficients; s by 0.01 over 0.5–3, the entering group's Γ "
               "by quarter octaves over 0.3–4.8 (the calibration file's ranges). The region: the grid's cells within "
               "Δ(−2 ln L) < 5.99 (two parameters), its extent in s and in Γ.", "",
               "| | best s | best Γ | s in the region | Γ in the region | at the best: first jam 10 % / median / 90 % "
               "| clog for good 10 % / median / 90 % |", "| --- | --- | --- | --- | --- | --- | --- |"]
        rows = [("Δ < 5.99", joint["region"])]
        if joint.get("calibrated"):
            rows.append((f"Δ < {joint['threshold']:.2f} (calibrated)", joint["calibrated"]))
        for name, ((bs, bg), (s_lo, s_hi), (g_lo, g_hi)) in rows:
            md.append(f"| {name} | {bs:.2f} | {bg:.2f} | {s_lo:.2f}–{s_hi:.2f} | {g_lo:.2f}–{g_hi:.2f} | "
                      + " | ".join(" / ".join(fmt_time(quantile(fits[e][0], bs, q, bg)) for q in (0.1, 0.5, 0.9))
                                   for e in targets) + " |")
        md += ["", "The least −2 ln L over s at each Γ (the scale's interval there: Δ < 3.84 from that Γ's own least):", "",
               "| Γ entering | best s | s within | Δ(−2 ln L) from the overall least |", "| --- | --- | --- | --- |"]
        low = min(joint["grid"].values())
        for g in GAMMAS[::2]:
            col = {sc: v for (sc, gg), v in joint["grid"].items() if gg == g}
            best_s = min(col, key=col.get)
            inside = [sc for sc, v in col.items() if v - col[best_s] < 3.84]
            md.append(f"| {g:.2f} | {best_s:.2f} | {min(inside):.2f}–{max(inside):.2f} | {col[best_s] - low:.2f} |")
        if joint["check"]:
            md += ["", "Coverage of the region (simulated; the coarse grid s by 0.02, Γ by half octaves, 20 coefficient "
                   f"draws; {max(1, args.coverage // 2)} synthetic studies per known point, each event's nights drawn "
                   "from its fitted hazard at the design's scales and Γ, both hazards refitted, a record of both events "
                   "drawn at the known point within the night; the threshold calibrated on a first set, checked on an "
                   "independent second):", "",
                   "| known (s, Γ) | Δ < 5.99 contains it | Δ < calibrated threshold contains it | no fit |",
                   "| --- | --- | --- | --- |"]
            for known, (deltas, failed) in joint["check"].items():
                md.append(f"| ({known[0]:g}, {known[1]:g}) | "
                          + " | ".join(contains_cell(deltas, thr) for thr in (5.99, joint["threshold"])) + f" | {failed} |")
        draw_joint(os.path.join(args.out, "joint.svg"), joint)
        svg_to_png(os.path.join(args.out, "joint.svg"), os.path.join(args.out, "joint.png"), 700, 540)
    with guard.whole_file(os.path.join(args.out, "hazard.md")) as f:
        f.write("\n".join(md) + "\n")
    svg = os.path.join(args.out, "hazard.svg")
    draw_figure(svg, nights, fits, intervals)
    svg_to_png(svg, os.path.join(args.out, "hazard.png"), 1100, 520)
    print("\n".join(md))


if __name__ == "__main__":
    guard.run_main(main)
