#!/usr/bin/env python3
"""The Madrid night's cheap forward model (issue 41, point 2), its check
against whole nights, and what it can fit of the recorded night.

The model. Read from the whole nights (studies/night-cheap-model/night-path.py), the hallway
stays at 1.5-2.5 persons/m^2 until its first jam and fills within a minute
when it jams: the night does not walk the periodic phase diagram's density
axis. What changes along the night is the arrivals: leaving m(t) and
entering c(t) persons/s (the scenario's schedule). So the cheap model is the
open hallway fed at constant rates (studies/night-cheap-model/
night-path-point.json, sweeps night-path-points*.json: 600-s runs on a grid
of rates), read as a hazard of the first jam,

    h(m, c; Γ, λ, ε) = exp(b0 + b1 (m - 2.25) + b2 (c - 1.6) + b3 ln(Γ/1.2) + b4 ln(λ/27) + b6 ln(ε/0.4))

fitted by maximum likelihood to the runs' first jams (an exponential
survival model: each run contributes its exposure from 60 s, after the
start, to its first jam or its end). Along the night the first jam's time
then has the survival S(t) = exp(-∫ h(s m(u), s c(u)) du) from 300 s (after
the night's start transient), s the inflow schedule's scale.

Besides: the same grid with the adaptive step (the whole nights' step; b5,
its effect, with a likelihood-ratio test), longer runs (the hazard against a
run's age, piecewise in windows of the run), and the cheap model corrected by
the whole nights (h_night = e^δ h, δ by maximum likelihood from their first
jams, checked across the inflow scales), on which the recorded night's inflow
scale is fitted.

The first jam (one definition for whole nights and cheap runs, fixed
before any cheap run was read): the first sample, at least `after` s into
the run, from which the mean speed of the people inside the hallway stays
below 0.1 m/s for 30 s (the timeline's "last moving" threshold).

Usage:
  night-cheap-model.py --paths paths.csv --sweep DIR [--sweep DIR ...] -o OUT

Writes OUT/cheap-model.md (the tables), OUT/cheap-runs.csv (each cheap run's
first jam and exposure), OUT/cheap-model.svg and .png (with chromium).

Before any work (scripts/script_guard.py): the CSVs must be night-path.py's
paths, each --sweep a sweep folder (results.csv), the scales and times
positive; OUT must be new, empty or a previous cheap model's folder (else
--force, which writes into it and deletes nothing), never an input; every file
is written whole. A bad argument is one line, exit status 2.
"""
import argparse
import collections
import csv
import importlib.util
import math
import os
import random
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))  # studies/NAME/ is two levels down
sys.path.insert(0, os.path.join(ROOT, "scripts"))
from svg_png import svg_to_png  # noqa: E402
import script_guard as guard  # noqa: E402

spec = importlib.util.spec_from_file_location("night_path", os.path.join(HERE, "night-path.py"))
night_path = importlib.util.module_from_spec(spec)
spec.loader.exec_module(night_path)

SAMPLE_S = 10.0
STAY_S = 30.0
STILL_M_PER_S = 0.1
NIGHT_AFTER_S = 300.0
CHEAP_AFTER_S = 60.0
CHEAP_RUN_S = 600.0
AGE_WINDOWS_S = [60.0, 600.0, 1200.0, 1800.0, float("inf")]
NIGHT_END_S = 5700.0
GAMMA0, LAMBDA0, EPS0 = 1.2, 27.0, 0.4
M0, C0 = 2.25, 1.6
RECORDED = [(1080, "02:18"), (1140, "02:19"), (2460, "02:41"), (3540, "02:59"), (5340, "03:29"), (5580, "fatal clog 03:33")]
FATAL_CLOG_S = 5580.0
# Kolmogorov-Smirnov one-sample critical values at 5 % (two-sided), n = 1..8.
KS_CRITICAL_5 = {1: 0.975, 2: 0.842, 3: 0.708, 4: 0.624, 5: 0.565, 6: 0.521, 7: 0.486, 8: 0.457}


def clock(t):
    t = int(round(t))
    return f"{2 + t // 3600:02d}:{t % 3600 // 60:02d}:{t % 60:02d}"


def first_jam(rows, after_s):
    """rows: (time_s, mean speed) sampled every SAMPLE_S; the onset or None."""
    need = int(round(STAY_S / SAMPLE_S)) + 1
    for i in range(len(rows) - need + 1):
        if rows[i][0] < after_s:
            continue
        if all(rows[j][1] < STILL_M_PER_S for j in range(i, i + need)):
            return rows[i][0]
    return None


def night_rates(t, scale=1.0):
    return scale * (3.0 - 2.0 * t / 5700.0), scale * (0.2 + 3.8 * t / 5700.0)


def covariates(m, c, gamma, lam, adaptive=False, eps=EPS0):
    """The surrogate's covariates (index 5 says the run took the adaptive step, as the whole nights did)."""
    return [1.0, m - M0, c - C0, math.log(gamma / GAMMA0), math.log(lam / LAMBDA0), 1.0 if adaptive else 0.0,
            math.log(eps / EPS0)]


# --- small linear algebra (no numpy on the machines this runs on) ---
def solve(a, b):
    n = len(b)
    m = [row[:] + [b[i]] for i, row in enumerate(a)]
    for k in range(n):
        p = max(range(k, n), key=lambda i: abs(m[i][k]))
        m[k], m[p] = m[p], m[k]
        if abs(m[k][k]) < 1e-300:
            raise ZeroDivisionError("singular")
        for i in range(k + 1, n):
            f = m[i][k] / m[k][k]
            for j in range(k, n + 1):
                m[i][j] -= f * m[k][j]
    x = [0.0] * n
    for i in reversed(range(n)):
        x[i] = (m[i][n] - sum(m[i][j] * x[j] for j in range(i + 1, n))) / m[i][i]
    return x


def inverse(a):
    n = len(a)
    cols = [solve(a, [1.0 if i == j else 0.0 for i in range(n)]) for j in range(n)]
    return [[cols[j][i] for j in range(n)] for i in range(n)]


def cholesky(a):
    n = len(a)
    l = [[0.0] * n for _ in range(n)]
    for i in range(n):
        for j in range(i + 1):
            s = a[i][j] - sum(l[i][k] * l[j][k] for k in range(j))
            l[i][j] = math.sqrt(max(s, 0.0)) if i == j else s / l[j][j]
    return l


def coefficient_draws(beta, cov, n, seed):
    """n draws of the coefficients from N(beta, cov) (the fits' own uncertainty)."""
    rng = random.Random(seed)
    chol = cholesky(cov)
    draws = []
    for _ in range(n):
        z = [rng.gauss(0, 1) for _ in beta]
        draws.append([beta[i] + sum(chol[i][j] * z[j] for j in range(i + 1)) for i in range(len(beta))])
    return draws


def ks_distance(places):
    """One-sample Kolmogorov-Smirnov distance of sorted places in [0, 1] from the uniform."""
    n = len(places)
    return max(max((i + 1) / n - u, u - i / n) for i, u in enumerate(places)) if places else float("nan")


def profile_over(likelihood, scales, threshold=3.84):
    """The profile of -2 ln L over `scales` (likelihood: scale -> L): the best scale, the first and last scales
    within Δ(-2 ln L) < threshold, and every (scale, -2 ln L) row."""
    rows = [(sc, -2.0 * math.log(max(likelihood(sc), 1e-300))) for sc in scales]
    top = min(v for _, v in rows)
    inside = [sc for sc, v in rows if v - top < threshold]
    return min(rows, key=lambda r: r[1])[0], inside[0], inside[-1], rows


def profile_scale(likelihood):
    """The inflow scale over 0.50-1.50 (steps of 0.01) for one recorded time: its best value and the values within
    Δ(-2 ln L) < 3.84. likelihood: scale -> L."""
    return profile_over(likelihood, [k / 100.0 for k in range(50, 151)])[:3]


def fit_hazard(runs, use):
    """Exponential survival regression on the covariates `use` (indices)."""
    beta = [0.0] * len(use)
    total_d = sum(r["jammed"] for r in runs)
    total_t = sum(r["exposure_s"] for r in runs)
    beta[0] = math.log(max(total_d, 0.5) / total_t)
    for _ in range(100):
        g = [0.0] * len(use)
        h = [[0.0] * len(use) for _ in use]
        ll = 0.0
        for r in runs:
            x = [r["x"][k] for k in use]
            eta = sum(b * xi for b, xi in zip(beta, x))
            mu = math.exp(eta) * r["exposure_s"]
            ll += r["jammed"] * eta - mu
            for a in range(len(use)):
                g[a] += (r["jammed"] - mu) * x[a]
                for b in range(len(use)):
                    h[a][b] += mu * x[a] * x[b]
        step = solve(h, g)
        beta = [b + s for b, s in zip(beta, step)]
        if max(abs(s) for s in step) < 1e-10:
            break
    cov = inverse(h)
    return beta, cov, ll


def hazard(beta, use, m, c, gamma=GAMMA0, lam=LAMBDA0, adaptive=False, eps=EPS0):
    x = covariates(m, c, gamma, lam, adaptive, eps)
    return math.exp(sum(b * x[k] for b, k in zip(beta, use)))


def survival_curve(beta, use, gamma=GAMMA0, lam=LAMBDA0, scale=1.0, dt=5.0, adaptive=False, eps=EPS0):
    """[(t, S(t), h(t))] from NIGHT_AFTER_S to the night's end."""
    out = [(NIGHT_AFTER_S, 1.0, hazard(beta, use, *night_rates(NIGHT_AFTER_S, scale), gamma, lam, adaptive, eps))]
    cum = 0.0
    t = NIGHT_AFTER_S
    while t < NIGHT_END_S - 1e-9:
        h0 = out[-1][2]
        h1 = hazard(beta, use, *night_rates(t + dt, scale), gamma, lam, adaptive, eps)
        cum += 0.5 * (h0 + h1) * dt
        t += dt
        out.append((t, math.exp(-cum), h1))
    return out


def jammed_by(curve, t):
    """The predicted share of nights jammed by t: 1 - S(t), S stepwise from the curve."""
    s_at = 1.0
    for tt, s, _ in curve:
        if tt > t:
            break
        s_at = s
    return 1.0 - s_at


def quantile_time(curve, q):
    """The time by which a share q of nights have jammed (None: later than the night)."""
    for t, s, _ in curve:
        if 1.0 - s >= q:
            return t
    return None


def read_sweep(folder):
    runs = []
    table = os.path.join(folder, "results.csv")
    for row in csv.DictReader(open(table)):
        run_file = os.path.join(folder, "runs", row["run_id"] + ".sqlite")
        if row["status"] != "complete" or not os.path.exists(run_file):
            continue
        scenario = night_path.read_scenario(run_file)
        m = scenario["timeline"]["inflows"][0]["rate_per_s"]
        c = scenario["timeline"]["inflows"][1]["rate_per_s"]
        gamma = scenario["model"].get("back_force_gamma", GAMMA0)
        lam = scenario["model"].get("torsion_stiffness_lambda", LAMBDA0)
        step = scenario["model"].get("time_step_mode", "fixed")
        eps = scenario["model"].get("restitution", EPS0)
        rows = night_path.read_run(run_file, SAMPLE_S)
        onset = first_jam([(r["time_s"], r["mean_speed_m_per_s"]) for r in rows], CHEAP_AFTER_S)
        end = rows[-1]["time_s"]
        exposure = (onset if onset is not None else end - STAY_S) - CHEAP_AFTER_S
        pre = [r for r in rows if r["time_s"] >= CHEAP_AFTER_S and (onset is None or r["time_s"] < onset)]
        runs.append({
            "run": row["run_id"], "variant": row["variant"], "seed": int(row["seed"]),
            "leaving_per_s": m, "entering_per_s": c, "gamma": gamma, "lambda": lam, "restitution": eps, "step": step,
            "jammed": 0 if onset is None else 1, "onset_s": onset, "exposure_s": exposure, "end_s": end,
            "pre_jam_density_per_m2": sum(r["density_per_m2"] for r in pre) / len(pre) if pre else float("nan"),
            "x": covariates(m, c, gamma, lam, step == "adaptive", eps),
        })
    return runs


def age_pieces(run):
    """A run's exposure cut at AGE_WINDOWS_S (piecewise exponential): [(window index, jammed, exposure s)]."""
    stop = run["onset_s"] if run["onset_s"] is not None else run["end_s"] - STAY_S
    out = []
    for k in range(len(AGE_WINDOWS_S) - 1):
        a, b = AGE_WINDOWS_S[k], AGE_WINDOWS_S[k + 1]
        if stop <= a:
            break
        jammed = 1 if run["onset_s"] is not None and a <= run["onset_s"] < b else 0
        out.append((k, jammed, min(stop, b) - a))
    return out


def age_section(long_runs):
    """Does the first jam's hazard grow with the time the hallway has been fed? Long runs, cut into windows."""
    def window(k):
        b = AGE_WINDOWS_S[k + 1]
        return f"{AGE_WINDOWS_S[k]:.0f}–{'end' if b == float('inf') else f'{b:.0f}'} s"
    points = sorted({(r["leaving_per_s"], r["entering_per_s"]) for r in long_runs})
    n_windows = len(AGE_WINDOWS_S) - 1
    out = ["", f"## The hazard against the run's age ({len(long_runs)} runs of {max(r['end_s'] for r in long_runs):.0f} s, "
           f"{long_runs[0]['step']} step; jams / exposure per window)", "",
           "| leaving / entering persons/s | runs | first jams at (s) | " + " | ".join(window(k) for k in range(n_windows)) + " |",
           "| --- | --- | --- | " + " | ".join("---" for _ in range(n_windows)) + " |"]
    total = [[0, 0.0] for _ in range(n_windows)]
    pieces = []
    for m, c in points:
        rs = [r for r in long_runs if (r["leaving_per_s"], r["entering_per_s"]) == (m, c)]
        cell = [[0, 0.0] for _ in range(n_windows)]
        for r in rs:
            for k, d, e in age_pieces(r):
                cell[k][0] += d
                cell[k][1] += e
                total[k][0] += d
                total[k][1] += e
                pieces.append({"jammed": d, "exposure_s": e, "x": r["x"] + [1.0 if k > 0 else 0.0]})  # index 7: after the first window
        onsets = ", ".join(f"{r['onset_s']:.0f}" for r in rs if r["onset_s"] is not None) or "none"
        out.append(f"| {m:g} / {c:g} | {len(rs)} | {onsets} | " + " | ".join(f"{d} / {e:.0f} s" for d, e in cell) + " |")
    out.append("| all | " + f"{len(long_runs)} | | " + " | ".join(f"{d} / {e:.0f} s ({600 * d / e:.2f} per 10 min)" if e > 0 else "–" for d, e in total) + " |")
    use = [0, 1, 2, 7]
    if sum(p["jammed"] for p in pieces) >= 3 and any(p["x"][7] for p in pieces if p["jammed"]) and any(not p["x"][7] for p in pieces if p["jammed"]):
        beta, cov, ll = fit_hazard(pieces, use)
        _, _, ll0 = fit_hazard(pieces, [0, 1, 2])
        lr = 2.0 * (ll - ll0)
        se = math.sqrt(cov[3][3])
        out += ["", f"- The hazard after the first {AGE_WINDOWS_S[1]:.0f} s against before it (the rates as covariates): × {math.exp(beta[3]):.2f} "
                f"(95 %: {math.exp(beta[3] - 1.96 * se):.2f}–{math.exp(beta[3] + 1.96 * se):.2f}); likelihood ratio {lr:.2f}, "
                f"p = {math.erfc(math.sqrt(max(lr, 0.0) / 2.0)):.3g} (χ², one degree of freedom)."]
    else:
        out += ["", "- Too few first jams on either side of 600 s for a hazard ratio."]
    return out


def cumulative_hazard(beta, use, scale, t_end, dt=5.0):
    """∫ h from NIGHT_AFTER_S to t_end along the schedule at `scale` (trapezoid)."""
    total, t = 0.0, NIGHT_AFTER_S
    while t < t_end - 1e-9:
        step = min(dt, t_end - t)
        total += 0.5 * (hazard(beta, use, *night_rates(t, scale)) + hazard(beta, use, *night_rates(t + step, scale))) * step
        t += step
    return total


def night_offset(beta, use, whole):
    """The factor e^δ on the cheap hazard that the whole nights say: δ's maximum likelihood and its standard error.
    whole: [(scale, first jam or None, end of the night's run)]."""
    jams = sum(1 for _, t, _ in whole if t is not None)
    exposure = sum(cumulative_hazard(beta, use, s, t if t is not None else end) for s, t, end in whole)
    return math.log(jams / exposure), 1.0 / math.sqrt(jams)


def shifted(beta, delta):
    return [beta[0] + delta] + beta[1:]


def corrected_section(beta, use, whole, other_scale, fitted_nights, what="the cheap model"):
    """A one-factor correction of the cheap model fitted to whole nights, checked across the inflow scales, and the
    recorded night's inflow scale on the corrected model."""
    def places(b, nights_at):
        return [jammed_by(survival_curve(b, use, scale=s), t if t is not None else end) for s, t, end in nights_at]

    def median_error(b, nights_at):
        s = nights_at[0][0]
        jammed = sorted(t for _, t, _ in nights_at if t is not None)
        if len(jammed) != len(nights_at):
            return "not all jammed"
        obs = (jammed[(len(jammed) - 1) // 2] + jammed[len(jammed) // 2]) / 2
        pred = quantile_time(survival_curve(b, use, scale=s), 0.5)
        if pred is None:
            return "the prediction's median after 03:35"
        n = len(jammed)
        u = sorted(places(b, nights_at))
        ks = ks_distance(u)
        return f"median {clock(pred)} against {clock(obs)} ({pred - obs:+.0f} s), places {', '.join(f'{x:.2f}' for x in u)}, KS {ks:.2f} (5 %: {KS_CRITICAL_5.get(n, float('nan')):.3f})"

    at_one = [w for w in whole if w[0] == 1.0]
    at_other = [w for w in whole if w[0] != 1.0]
    out = ["", f"## {what[0].upper() + what[1:]} corrected by whole nights (one factor on its hazard)", "",
           "The whole nights' first jams against the cheap hazard h along the schedule: h_night = e^δ h, δ by maximum "
           "likelihood (e^δ = jams / Σ ∫h, each night from 300 s to its first jam or its end), its standard error 1/√jams. "
           "Checked across the inflow scales: δ from the nights at one scale predicts the nights at the other.", "",
           "| δ fitted on | nights | e^δ (95 %) | predicts the nights at | prediction against them |", "| --- | --- | --- | --- | --- |"]
    for fit_on, test_on, label_fit, label_test in ((at_one, at_other, "s = 1", f"s = {other_scale:g}"),
                                                   (at_other, at_one, f"s = {other_scale:g}", "s = 1")):
        if not fit_on or not test_on:
            continue
        d, se = night_offset(beta, use, fit_on)
        out.append(f"| {label_fit} | {len(fit_on)} | {math.exp(d):.2f} ({math.exp(d - 1.96 * se):.2f}–{math.exp(d + 1.96 * se):.2f}) | "
                   f"{label_test} | {median_error(shifted(beta, d), test_on)} |")
    d, se = night_offset(beta, use, whole)
    out.append(f"| all | {len(whole)} | {math.exp(d):.2f} ({math.exp(d - 1.96 * se):.2f}–{math.exp(d + 1.96 * se):.2f}) | (in-sample) s = 1 | "
               f"{median_error(shifted(beta, d), at_one)} |")

    # The recorded night on the corrected model: the inflow's scale from one recorded time, δ's uncertainty integrated out.
    out += ["", "### The recorded night's inflow scale on the corrected model (paper's Γ, λ)", "",
            "One recorded time per reading; likelihood h(t) S(t) averaged over δ ~ N(δ̂, se²) (41 points); s on a grid of 0.01.", "",
            "| reading of the recorded night's first jam | best s | s within Δ(−2 ln L) < 3.84 | median first jam at the best s |",
            "| --- | --- | --- | --- |"]
    deltas = [d + se * z for z in [-3.0 + 0.15 * k for k in range(41)]]
    weights = [math.exp(-0.5 * ((x - d) / se) ** 2) for x in deltas]
    fitted = []
    for label, target in (("the stop released by the first recorded avalanche, 02:18", 1080.0),
                          ("the fatal clog, 03:33", FATAL_CLOG_S)):
        def likelihood(scale):
            base = survival_curve(beta, use, scale=scale, dt=10.0)
            _, s_i, h_i = min(base, key=lambda row: abs(row[0] - target))
            cum = -math.log(max(s_i, 1e-300))
            return sum(w * math.exp(x) * h_i * math.exp(-math.exp(x) * cum) for x, w in zip(deltas, weights)) / sum(weights)
        best, lo, hi = profile_scale(likelihood)
        med = quantile_time(survival_curve(shifted(beta, d), use, scale=best), 0.5)
        out.append(f"| {label} | {best:.2f} | {lo:.2f}–{hi:.2f} | {clock(med) if med is not None else 'after 03:35'} |")
        fitted.append(best)
    out += ["", "### The first jam predicted at those scales (paper's Γ, λ)", "",
            "| model | inflow scale | first jam: 10 % | 25 % | median | 75 % | 90 % |", "| --- | --- | --- | --- | --- | --- | --- |"]
    for scale in fitted:
        for label, b in (("uncorrected", beta), (f"corrected by the {len(whole)} whole nights", shifted(beta, d))):
            curve = survival_curve(b, use, scale=scale)
            out.append(f"| {label} | {scale:.2f} | " + " | ".join(
                clock(t) if t is not None else "after 03:35" for t in (quantile_time(curve, q) for q in (0.1, 0.25, 0.5, 0.75, 0.9))) + " |")
    if fitted_nights:
        out += fitted_check(beta, use, d, fitted_nights)
    return out


def fitted_check(beta, use, delta, nights_at):
    """Whole nights run at the fitted scale against the corrected and the uncorrected model's predictions."""
    scale = nights_at[0][0]
    corrected = survival_curve(shifted(beta, delta), use, scale=scale)
    plain = survival_curve(beta, use, scale=scale)
    out = ["", f"### The check: {len(nights_at)} whole nights at s = {scale:g}", "",
           "A night's place is 1 − S(t) at its first jam (uniform if the model is right); a night not jammed by the end of its "
           "run is censored there, with the predicted chance of lasting that long.", "",
           "| night | first jam | place in the corrected prediction | place in the uncorrected one |", "| --- | --- | --- | --- |"]
    for _, t, end, name in sorted(nights_at, key=lambda n: (n[1] is None, n[1] or 0.0)):
        if t is not None:
            out.append(f"| {name} | {clock(t)} | {jammed_by(corrected, t):.2f} | {jammed_by(plain, t):.2f} |")
        else:
            out.append(f"| {name} | none by {clock(end)} (censored) | lasts that long: {1 - jammed_by(corrected, end):.2f} | {1 - jammed_by(plain, end):.2f} |")
    jammed = sorted(n[1] for n in nights_at if n[1] is not None)
    n = len(nights_at)
    if len(jammed) > n / 2:
        # The empirical median (censored nights lie above every jammed one).
        ordered = jammed + [float("inf")] * (n - len(jammed))
        obs = (ordered[(n - 1) // 2] + ordered[n // 2]) / 2
        for label, curve in (("corrected", corrected), ("uncorrected", plain)):
            pred = quantile_time(curve, 0.5)
            if len(jammed) == n:
                ks = ks_distance(sorted(jammed_by(curve, t) for t in jammed))
                tail = f"; KS {ks:.2f} (5 %: {KS_CRITICAL_5.get(n, float('nan')):.3f})"
            else:
                tail = " (KS not computed: censored nights)"
            out.append(f"- {label}: median first jam {clock(pred) if pred is not None else 'after 03:35'} against the nights' "
                       f"{clock(obs) if obs != float('inf') else 'later'}"
                       + (f" (error {pred - obs:+.0f} s)" if pred is not None and obs != float("inf") else "") + tail + ".")
    return out


def night_pieces(scale, t, stop, gamma=GAMMA0):
    """A whole night's 10-s pieces from NIGHT_AFTER_S to `stop` (its event at t, or censored there when t is None),
    each with the rates of its middle (and the entering group's back force gamma): the exposures fit_hazard takes."""
    pieces = []
    u = NIGHT_AFTER_S
    while u < stop - 1e-9:
        dt = min(SAMPLE_S, stop - u)
        m, c = night_rates(u + dt / 2, scale)
        pieces.append({"jammed": 1 if t is not None and u + dt >= stop - 1e-9 else 0, "exposure_s": dt,
                       "x": covariates(m, c, gamma, LAMBDA0)})
        u += dt
    return pieces


def own_hazard_section(nights_at, cheap_fits):
    """The whole nights' own first-jam hazard, the cheap model's form fitted to them directly (10-s pieces of each night
    from 300 s to its first jam or its end, the rates of each piece's middle), beside the cheap fits."""
    pieces = [p for scale, t, end in nights_at for p in night_pieces(scale, t, t if t is not None else end)]
    use = [0, 1, 2]
    beta, cov, _ = fit_hazard(pieces, use)
    scales = sorted({n[0] for n in nights_at})
    out = ["", f"## The whole nights' own hazard ({len(nights_at)} nights at the inflow scales {', '.join(f'{x:g}' for x in scales)}, "
           f"{sum(1 for n in nights_at if n[1] is not None)} first jams)", "",
           "The cheap model's form fitted to the whole nights themselves (paper's Γ, λ, ε; adaptive step), beside the cheap fits: "
           "where the cheap model's coefficients leave the nights', it mispredicts them.", "",
           "| fitted to | ln h at (2.25, 1.6) | per person/s leaving | per person/s entering |", "| --- | --- | --- | --- |"]
    for label, b, cv in [(f"the {len(nights_at)} whole nights", beta, cov)] + cheap_fits:
        out.append(f"| {label} | " + " | ".join(f"{b[i]:.2f} ± {math.sqrt(cv[i][i]):.2f}" for i in range(3)) + " |")

    # The recorded night's inflow scale on the whole nights' own hazard, its uncertainty integrated out.
    draws = coefficient_draws(beta, cov, 100, 11)
    out += ["", f"### The recorded night's inflow scale on the whole nights' own hazard (paper's Γ, λ, ε)", "",
            "One recorded time per reading; likelihood h(t) S(t) averaged over 100 draws of the coefficients from their covariance; "
            "s on a grid of 0.01 over 0.5–1.5.", "",
            "| reading of the recorded night's first jam | best s | s within Δ(−2 ln L) < 3.84 | first jam at the best s: 10 % / median / 90 % |",
            "| --- | --- | --- | --- |"]
    for label, target in (("the stop released by the first recorded avalanche, 02:18", 1080.0), ("the fatal clog, 03:33", FATAL_CLOG_S)):
        def likelihood(scale):
            return sum(hazard(b, use, *night_rates(target, scale)) * math.exp(-cumulative_hazard(b, use, scale, target, dt=20.0))
                       for b in draws) / len(draws)
        best, lo, hi = profile_scale(likelihood)
        curve = survival_curve(beta, use, scale=best)
        qs = [quantile_time(curve, q) for q in (0.1, 0.5, 0.9)]
        out.append(f"| {label} | {best:.2f} | {lo:.2f}–{hi:.2f} | "
                   + " / ".join(clock(t) if t is not None else "after 03:35" for t in qs) + " |")
    return out


def read_paths(paths_csv):
    """run -> [(time_s, mean speed, density, counter-flow share)]"""
    series = collections.defaultdict(list)
    for r in csv.DictReader(open(paths_csv)):
        series[r["run"]].append((float(r["time_s"]), float(r["mean_speed_m_per_s"]), float(r["density_per_m2"]),
                                 float(r["counter_flow_share"])))
    return dict(sorted(series.items()))


def read_nights(paths):
    return {run: first_jam([(t, v) for t, v, _, _ in rows], NIGHT_AFTER_S) for run, rows in paths.items()}


PATHS_COLUMNS = ("run", "time_s", "mean_speed_m_per_s", "density_per_m2", "counter_flow_share")
PATHS_EXPECTED = "night-path.py's CSV of whole nights (studies/night-cheap-model/night-path.py -o paths.csv)"
OUTPUTS = {"cheap-model.md": "# The Madrid night's cheap forward model", "cheap-runs.csv": "run,variant,seed,",
           "cheap-model.svg": None, "cheap-model.png": None}


def check_sweep_runs(folder):
    """The runs read_sweep reads are run files of the open hallway fed at two constant rates (night-path-point.json)."""
    expected = "a sweep of studies/night-cheap-model/night-path-points*.json (two inflows at constant rates, keep_runs)"
    for row in csv.DictReader(open(os.path.join(folder, "results.csv"))):
        run_file = os.path.join(folder, "runs", row["run_id"] + ".sqlite")
        if row["status"] != "complete" or not os.path.exists(run_file):
            continue
        guard.check_run_file(run_file, night_path.TABLES)
        scenario = night_path.read_scenario(run_file)
        try:
            inflows = scenario["timeline"]["inflows"]
            float(inflows[0]["rate_per_s"]), float(inflows[1]["rate_per_s"])
            if not isinstance(scenario["model"], dict):
                raise TypeError
        except (KeyError, IndexError, TypeError, ValueError):
            raise guard.ScriptError(f"{folder}: run {row['run_id']}'s scenario lacks two inflows with rate_per_s or "
                                    f"a model; expected {expected}") from None


def check_arguments(args):
    """Inputs readable and of their kind, outputs never an input nor foreign (scripts/script_guard.py)."""
    csvs = [("--paths", args.paths)] + ([("--confirm", args.confirm)] if args.confirm else []) + \
        [("--fitted", f) for f in args.fitted]
    for option, path in csvs:
        try:
            guard.require_csv_columns(path, PATHS_COLUMNS, PATHS_EXPECTED)
        except guard.ScriptError as e:
            raise guard.ScriptError(f"{option} {e}") from None
    inputs = [(f"the {option} CSV", path) for option, path in csvs]
    for folder in args.sweep:
        guard.check_sweep_dir(folder, sqlite=False, csv_table=True)
        check_sweep_runs(folder)
        inputs += guard.sweep_inputs(folder) + [("a --sweep folder", folder)]
    checks = {name: guard.starts_with(head) if head else (guard.is_svg if name.endswith(".svg") else guard.is_png)
              for name, head in OUTPUTS.items()}
    guard.check_outputs(
        [guard.Output("-o", args.out, "a folder of night-cheap-model.py", folder=True, is_previous=guard.folder_with(checks))]
        + [guard.Output("", os.path.join(args.out, name), f"a {name} of night-cheap-model.py", check)
           for name, check in checks.items()], inputs, args.force)


def main():
    ap = guard.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--paths", required=True, help="night-path.py's CSV of the whole nights")
    ap.add_argument("--sweep", action="append", required=True, help="a night-path-points sweep's output folder (keep_runs)")
    ap.add_argument("-o", "--out", required=True)
    ap.add_argument("--confirm", help="night-path.py's CSV of whole nights run at another inflow scale (the confirmation)")
    ap.add_argument("--confirm-scale", type=guard.positive_float, default=0.85, help="the inflow scale of those nights (and of the prediction)")
    ap.add_argument("--confirm-end-s", type=guard.positive_float, default=5700.0, help="how far those nights were run (a night not jammed by then is censored)")
    ap.add_argument("--fitted", action="append", default=[], help="night-path.py's CSV of whole nights run at the fitted scale "
                    "(the check of the corrected model's prediction; repeatable; each night censored at its last sample)")
    ap.add_argument("--fitted-scale", type=guard.positive_float, default=1.12, help="the inflow scale of those nights")
    guard.add_force(ap)
    args = ap.parse_args()
    check_arguments(args)
    os.makedirs(args.out, exist_ok=True)

    paths = read_paths(args.paths)
    nights = read_nights(paths)
    runs = [r for folder in args.sweep for r in read_sweep(folder)]
    if not runs:
        raise guard.ScriptError(f"--sweep {', '.join(args.sweep)}: no complete cheap runs with their run files; "
                                "expected night-path-points sweeps run with keep_runs")
    with guard.whole_file(os.path.join(args.out, "cheap-runs.csv"), "w", newline="") as f:
        keys = [k for k in runs[0] if k != "x"]
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        for r in runs:
            w.writerow({k: r[k] for k in keys})

    # The surrogate is built on the 600-s runs; longer ones answer whether the hazard grows with the run's age.
    long_runs = [r for r in runs if r["end_s"] > CHEAP_RUN_S + 1.0]
    runs = [r for r in runs if r["end_s"] <= CHEAP_RUN_S + 1.0]
    fixed = [r for r in runs if r["step"] == "fixed"]
    adaptive = [r for r in runs if r["step"] == "adaptive"]
    def at_paper(r):
        return r["gamma"] == GAMMA0 and r["lambda"] == LAMBDA0 and r["restitution"] == EPS0
    paper = [r for r in fixed if at_paper(r)]
    use_rates = [0, 1, 2]
    b_paper, cov_paper, _ = fit_hazard(paper, use_rates)
    # The cheap model in the whole nights' own (adaptive) step, where enough of its runs jammed to fit it.
    adaptive_paper = [r for r in adaptive if at_paper(r)]
    fit_adaptive = fit_hazard(adaptive_paper, use_rates) if sum(r["jammed"] for r in adaptive_paper) >= 4 else None
    varied = len({(r["gamma"], r["lambda"]) for r in fixed}) > 1
    eps_varied = len({r["restitution"] for r in fixed}) > 1
    use_all = ([0, 1, 2, 3, 4] if varied else use_rates) + ([6] if eps_varied else [])
    b_all, cov_all, _ = fit_hazard(fixed, use_all)

    lines = ["# The Madrid night's cheap forward model: tables", "",
             "Written by `studies/night-cheap-model/night-cheap-model.py` (its docstring defines the model and the first jam).", ""]

    # The grid: jams and exposure per point, per parameter set and step.
    lines += ["## The cheap runs: first jams per grid point", "",
              "| step | Γ, λ, ε | leaving / entering persons/s | runs | jammed | first jams at (s) | exposure (s) | jams per 10 min (raw) | hallway before its jam (persons/m²) |",
              "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    cells = collections.defaultdict(list)
    for r in runs:
        cells[(r["gamma"], r["lambda"], r["restitution"], r["leaving_per_s"], r["entering_per_s"], r["step"])].append(r)
    for key in sorted(cells, key=lambda k: (k[5] != "fixed", k[:5])):
        rs = cells[key]
        d = sum(r["jammed"] for r in rs)
        t = sum(r["exposure_s"] for r in rs)
        onsets = ", ".join(f"{r['onset_s']:.0f}" for r in rs if r["onset_s"] is not None) or "none"
        dens = sum(r["pre_jam_density_per_m2"] for r in rs) / len(rs)
        lines.append(f"| {key[5]} | {key[0]:g}, {key[1]:g}, {key[2]:g} | {key[3]:g} / {key[4]:g} | {len(rs)} | {d} | {onsets} | {t:.0f} | {600 * d / t:.2f} | {dens:.2f} |")

    def coef_table(beta, cov, use, title):
        names = ["ln h at (2.25, 1.6)", "per person/s leaving", "per person/s entering", "per ln(Γ/1.2)", "per ln(λ/27)",
                 "adaptive step (against fixed)", "per ln(ε/0.4)"]
        out = ["", f"## {title}", "", "| coefficient | value | standard error |", "| --- | --- | --- |"]
        for i, k in enumerate(use):
            out.append(f"| {names[k]} | {beta[i]:.3f} | {math.sqrt(cov[i][i]):.3f} |")
        return out

    lines += coef_table(b_paper, cov_paper, use_rates, f"The hazard at the paper's Γ and λ, fixed step ({len(paper)} runs, {sum(r['jammed'] for r in paper)} first jams)")
    if varied:
        lines += coef_table(b_all, cov_all, use_all, f"The surrogate over {'Γ, λ and ε' if eps_varied else 'Γ and λ'}, fixed step ({len(fixed)} runs, {sum(r['jammed'] for r in fixed)} first jams)")

    def fmt(t):
        return "after 03:35" if t is None or t == float("inf") else clock(t)

    confirm_paths = read_paths(args.confirm) if args.confirm else {}

    def against_nights(beta, cov, use, step_adaptive, what):
        """The whole nights (at s = 1 and at the confirmation's scale) against the hazard `beta` along the schedule."""
        curve = survival_curve(beta, use, adaptive=step_adaptive)
        medians = []
        for b in coefficient_draws(beta, cov, 400, 41):
            q = quantile_time(survival_curve(b, use, dt=20.0, adaptive=step_adaptive), 0.5)
            medians.append(q if q is not None else float("inf"))
        medians.sort()
        lo, hi = medians[int(0.025 * len(medians))], medians[int(0.975 * len(medians)) - 1]
        observed = sorted(t for t in nights.values() if t is not None)
        obs_median = (observed[(len(observed) - 1) // 2] + observed[len(observed) // 2]) / 2 if observed else float("nan")
        # Probability integral transform of each night under the predicted distribution.
        pits = sorted(jammed_by(curve, t) for t in observed)
        ks = ks_distance(pits)
        pred = {q: quantile_time(curve, q) for q in (0.1, 0.25, 0.5, 0.75, 0.9)}
        out = ["", f"## The whole night predicted by {what}, against eight whole nights (paper's model)", "",
               "| | first jam: 10 % | 25 % | median | 75 % | 90 % |", "| --- | --- | --- | --- | --- | --- |",
               "| cheap model (rates' hazard along the night's schedule) | " + " | ".join(fmt(pred[q]) for q in (0.1, 0.25, 0.5, 0.75, 0.9)) + " |"]
        if observed:
            def emp(q):
                return observed[min(len(observed) - 1, max(0, math.ceil(q * len(observed)) - 1))]
            out.append(f"| {len(observed)} whole nights (empirical) | " + " | ".join(clock(emp(q)) for q in (0.1, 0.25, 0.5, 0.75, 0.9)) + " |")
        out += ["", f"- The cheap model's median first jam: {fmt(pred[0.5])} (95 % from the hazard's uncertainty: {fmt(lo)}–{fmt(hi)}); the whole nights': {clock(obs_median)}; "
                f"error of the median {pred[0.5] - obs_median:+.0f} s." if pred[0.5] is not None else "- The cheap model predicts no first jam before 03:35.",
                "- Each whole night's first jam: " + ", ".join(f"{run.split('-')[-1]} {fmt(t)}" for run, t in nights.items()) + ".",
                f"- Their places in the predicted distribution (1 − S(t), uniform if the cheap model is right): {', '.join(f'{u:.2f}' for u in pits)}; "
                f"Kolmogorov–Smirnov distance {ks:.2f} (5 % critical value for {len(pits)} values: {KS_CRITICAL_5.get(len(pits), float('nan')):.3f})."]

        # A prediction at another inflow scale, and the whole nights run there to confirm it.
        scaled = survival_curve(beta, use, scale=args.confirm_scale, adaptive=step_adaptive)
        out += ["", f"### Prediction at the inflow scale {args.confirm_scale:g} (paper's Γ, λ), and whole nights run there", "",
                "| | first jam: 10 % | 25 % | median | 75 % | 90 % |", "| --- | --- | --- | --- | --- | --- |",
                f"| cheap model at s = {args.confirm_scale:g} | " + " | ".join(fmt(quantile_time(scaled, q)) for q in (0.1, 0.25, 0.5, 0.75, 0.9)) + " |"]
        if confirm_paths:
            got = {run: first_jam([(t, v) for t, v, _, _ in rows], NIGHT_AFTER_S) for run, rows in confirm_paths.items()}
            out += ["", f"- Whole nights at s = {args.confirm_scale:g}: " + ", ".join(
                f"{run.split('-')[-1]} first jam {fmt(t)} (place in the prediction {jammed_by(scaled, t):.2f})" if t is not None else
                f"{run.split('-')[-1]} no jam by {clock(max(r[0] for r in confirm_paths[run]))} (censored; the prediction gives {1 - jammed_by(scaled, max(r[0] for r in confirm_paths[run])):.2f} for that)"
                for run, t in got.items()) + "."]
            jammed = sorted(t for t in got.values() if t is not None)
            if len(jammed) == len(got) and jammed:
                places = sorted(jammed_by(scaled, t) for t in jammed)
                n = len(places)
                ks_n = ks_distance(places)
                median_obs = (jammed[(n - 1) // 2] + jammed[n // 2]) / 2
                median_pred = quantile_time(scaled, 0.5)
                out.append(f"- Their median first jam {clock(median_obs)} against the predicted {fmt(median_pred)}"
                           + (f" (error {median_pred - median_obs:+.0f} s)" if median_pred is not None else "")
                           + f"; Kolmogorov–Smirnov distance {ks_n:.2f} (5 % critical value for {n} values: {KS_CRITICAL_5.get(n, float('nan')):.3f}).")
        return out, curve, (lo, hi)

    more, curve, band = against_nights(b_paper, cov_paper, use_rates, False, "the cheap model (fixed step)")
    lines += more
    if adaptive:
        # The step the runs take: the same points and seeds with the whole nights' (adaptive) step.
        paired = [r for r in runs if at_paper(r)]
        points = sorted({(r["leaving_per_s"], r["entering_per_s"]) for r in paired if r["step"] == "adaptive"})
        lines += ["", "## The step: the same points and seeds with the fixed and the adaptive step", "",
                  "| leaving / entering persons/s | fixed: jammed / runs | first jams (s) | adaptive: jammed / runs | first jams (s) |",
                  "| --- | --- | --- | --- | --- |"]
        for m, c in points:
            row = [f"{m:g} / {c:g}"]
            for step in ("fixed", "adaptive"):
                rs = [r for r in paired if r["step"] == step and (r["leaving_per_s"], r["entering_per_s"]) == (m, c)]
                row += [f"{sum(r['jammed'] for r in rs)} / {len(rs)}",
                        ", ".join(f"{r['onset_s']:.0f}" for r in rs if r["onset_s"] is not None) or "none"]
            lines.append("| " + " | ".join(row) + " |")
        use_step = [0, 1, 2, 5]
        b_step, cov_step, ll_step = fit_hazard(paired, use_step)
        _, _, ll_none = fit_hazard(paired, use_rates)
        lr = 2.0 * (ll_step - ll_none)
        p_lr = math.erfc(math.sqrt(max(lr, 0.0) / 2.0))  # chi-square with one degree of freedom
        lines += coef_table(b_step, cov_step, use_step, f"The hazard with the step as a covariate ({len(paired)} runs at the paper's Γ, λ, {sum(r['jammed'] for r in paired)} first jams)")
        lines += ["", f"- The adaptive step multiplies the first jam's hazard by {math.exp(b_step[3]):.2f} "
                  f"(95 %: {math.exp(b_step[3] - 1.96 * math.sqrt(cov_step[3][3])):.2f}–{math.exp(b_step[3] + 1.96 * math.sqrt(cov_step[3][3])):.2f}); "
                  f"likelihood ratio {lr:.2f}, p = {p_lr:.3g} (χ², one degree of freedom)."]
        more, curve_a, band_a = against_nights(b_step, cov_step, use_step, True, "the cheap model with the nights' step (adaptive; rates' slopes shared with the fixed-step runs)")
        lines += more
        if fit_adaptive:
            b_ad, cov_ad, _ = fit_adaptive
            lines += coef_table(b_ad, cov_ad, use_rates, f"The hazard from the adaptive-step runs alone ({len(adaptive_paper)} runs, {sum(r['jammed'] for r in adaptive_paper)} first jams)")
            more, _, _ = against_nights(b_ad, cov_ad, use_rates, False, "the adaptive-step runs alone")
            lines += more
    if long_runs:
        lines += age_section(long_runs)

    # The recorded night on the cheap model, under two readings of its first jam.
    if varied:
        lines += ["", "## The recorded night on the cheap model", "",
                  "One recorded time per reading, its likelihood h(t) S(t) under the cheap model; parameters Γ, λ (and ε where its runs are given) over the range the "
                  "surrogate was measured on (0.6–2.4, 13.5–54, 0.2–0.8; log-spaced grid of 5 × 5 (× 3)) and the inflow schedule's scale s "
                  "(a nuisance, 0.5–1.5 in steps of 0.1, profiled out; or fixed at the scenario's 1). The likelihood with the surrogate's best coefficients, "
                  "and averaged over 60 draws of them from their covariance (the surrogate's own uncertainty).", "",
                  "| reading of the recorded night's first jam | likelihood | best Γ, λ, ε, s | Γ within Δ(−2 ln L) < 3.84 | λ within 3.84 | ε within 3.84 | median first jam at the best |",
                  "| --- | --- | --- | --- | --- | --- | --- |"]
        gammas = [0.6 * 4 ** (k / 4) for k in range(5)]
        lambdas = [13.5 * 4 ** (k / 4) for k in range(5)]
        epses = [0.2, 0.4, 0.8] if eps_varied else [EPS0]
        scales = [0.5 + 0.1 * k for k in range(11)]
        # The surrogate's own uncertainty: the likelihood averaged over draws of its coefficients.
        draws = coefficient_draws(b_all, cov_all, 60, 7)
        for label, target in (("the stop released by the first recorded avalanche, 02:18", 1080.0),
                              ("the fatal clog, 03:33 (the avalanches before it as stops the cheap model does not resolve)", FATAL_CLOG_S)):
            def likelihood(beta, prm, scale):
                """h(target) S(target), integrated up to the target only."""
                gamma, lam, eps = prm
                cum, t, dt = 0.0, NIGHT_AFTER_S, 20.0
                h0 = hazard(beta, use_all, *night_rates(t, scale), gamma, lam, False, eps)
                while t < target - 1e-9:
                    step = min(dt, target - t)
                    h1 = hazard(beta, use_all, *night_rates(t + step, scale), gamma, lam, False, eps)
                    cum += 0.5 * (h0 + h1) * step
                    h0, t = h1, t + step
                return h0 * math.exp(-cum)

            def nll(prm, scale, marginal):
                if not marginal:
                    return -2.0 * math.log(max(likelihood(b_all, prm, scale), 1e-300))
                return -2.0 * math.log(max(sum(likelihood(b, prm, scale) for b in draws) / len(draws), 1e-300))

            def summary(marginal, scale_fixed):
                rows = []
                for prm in ((g, l, e) for g in gammas for l in lambdas for e in epses):
                    options = [1.0] if scale_fixed else scales
                    v, sc = min((nll(prm, x, marginal), x) for x in options)
                    rows.append((prm, sc, v))
                top = min(r[2] for r in rows)
                b = min(rows, key=lambda r: r[2])
                ok = [r for r in rows if r[2] - top < 3.84]
                within = []
                for k, values in enumerate((gammas, lambdas, epses)):
                    got = sorted({r[0][k] for r in ok})
                    within.append(f"{got[0]:.3g}–{got[-1]:.3g} ({len(got)} of {len(values)})")
                (g, l, e), sc = b[0], b[1]
                if marginal:  # the predictive median: the draws' survival averaged
                    curves = [survival_curve(d, use_all, g, l, sc, dt=20.0, eps=e) for d in draws]
                    mean_curve = [(curves[0][k][0], sum(c[k][1] for c in curves) / len(curves), 0.0) for k in range(len(curves[0]))]
                    med = quantile_time(mean_curve, 0.5)
                else:
                    med = quantile_time(survival_curve(b_all, use_all, g, l, sc, dt=20.0, eps=e), 0.5)
                return f"{g:.2g}, {l:.3g}, {e:g}, {sc:.1f} | " + " | ".join(within) + f" | {fmt(med)}"
            for marginal in (False, True):
                for fixed_scale in (False, True):
                    how = ("surrogate averaged over its uncertainty" if marginal else "surrogate's best coefficients") + \
                          ("; s = 1" if fixed_scale else "; s profiled")
                    lines.append(f"| {label} | {how} | {summary(marginal, fixed_scale)} |")

    # The cheap model corrected by the whole nights (one factor on its hazard), and the recorded night on it.
    whole = [(1.0, t, NIGHT_END_S) for t in nights.values()]
    whole += [(args.confirm_scale, first_jam([(t, v) for t, v, _, _ in rows], NIGHT_AFTER_S), min(args.confirm_end_s, max(r[0] for r in rows)))
              for rows in confirm_paths.values()]
    fitted_nights = []
    for path in args.fitted:
        for run, rows in read_paths(path).items():
            fitted_nights.append((args.fitted_scale, first_jam([(t, v) for t, v, _, _ in rows], NIGHT_AFTER_S), max(r[0] for r in rows),
                                  run.split("-")[-1]))
    lines += corrected_section(b_paper, use_rates, whole, args.confirm_scale, fitted_nights)
    lines += own_hazard_section(whole + [n[:3] for n in fitted_nights], [
        ("the cheap model, fixed step", b_paper, cov_paper),
        *([("the cheap model, adaptive step (as the nights)", *fit_adaptive[:2])] if fit_adaptive else [])])
    if fit_adaptive:
        # The cheap model in the whole nights' own step (found after the fitted nights' check, not committed before it).
        lines += corrected_section(fit_adaptive[0], use_rates, whole, args.confirm_scale, fitted_nights,
                                   "the cheap model in the nights' step (adaptive runs only)")

    guard.write_whole(os.path.join(args.out, "cheap-model.md"), "\n".join(lines) + "\n")
    delta, _ = night_offset(b_paper, use_rates, whole)
    draw(os.path.join(args.out, "cheap-model.svg"), cells, b_paper, use_rates, curve, nights, band, paths,
         survival_curve(fit_adaptive[0], use_rates) if fit_adaptive else None,
         survival_curve(shifted(b_paper, delta), use_rates))
    svg_to_png(os.path.join(args.out, "cheap-model.svg"), os.path.join(args.out, "cheap-model.png"), 1200, 900)
    print("\n".join(lines))


def draw(file, cells, beta, use, curve, nights, median_band, paths, curve_adaptive=None, curve_corrected=None):
    w, h = 1200, 900
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="DejaVu Sans, sans-serif" font-size="13">',
           f'<rect width="{w}" height="{h}" fill="white"/>']
    # Left: the rate plane, the hazard's contours (as coloured cells), the grid's raw jams, the night's schedule.
    x0, y0, pw, ph = 80, 70, 420, 370
    mlo, mhi, clo, chi = 1.0, 3.0, 0.2, 3.0

    def px(m):
        return x0 + (m - mlo) / (mhi - mlo) * pw

    def py(c):
        return y0 + ph - (c - clo) / (chi - clo) * ph
    n = 40
    for i in range(n):
        for j in range(n):
            m = mlo + (i + 0.5) * (mhi - mlo) / n
            c = clo + (j + 0.5) * (chi - clo) / n
            p10 = 1.0 - math.exp(-hazard(beta, use, m, c) * 600.0)
            shade = int(255 - 200 * p10)
            out.append(f'<rect x="{px(m - (mhi - mlo) / n / 2):.1f}" y="{py(c + (chi - clo) / n / 2):.1f}" width="{pw / n + 0.5:.1f}" height="{ph / n + 0.5:.1f}" fill="rgb(255,{shade},{shade})"/>')
    out.append(f'<rect x="{x0}" y="{y0}" width="{pw}" height="{ph}" fill="none" stroke="black"/>')
    for m in (1.0, 1.5, 2.0, 2.5, 3.0):
        out.append(f'<text x="{px(m):.0f}" y="{y0 + ph + 18}" text-anchor="middle">{m:g}</text>')
    for c in (0.5, 1.0, 1.5, 2.0, 2.5, 3.0):
        out.append(f'<text x="{x0 - 8}" y="{py(c) + 4:.0f}" text-anchor="end">{c:g}</text>')
    out.append(f'<text x="{x0 + pw / 2}" y="{y0 + ph + 38}" text-anchor="middle">leaving, persons/s (from the court)</text>')
    out.append(f'<text x="{x0 - 50}" y="{y0 + ph / 2}" text-anchor="middle" transform="rotate(-90 {x0 - 50} {y0 + ph / 2})">entering, persons/s (from the street)</text>')
    out.append(f'<text x="{x0}" y="{y0 - 34}" font-weight="bold">The cheap model: a first jam within 10 min at constant rates</text>')
    out.append(f'<text x="{x0}" y="{y0 - 16}" fill="#444" font-size="12">shade: the fitted chance (white 0, red 0.8); numbers: jammed / runs (paper\'s Γ, λ, fixed step)</text>')
    out.append(f'<clipPath id="plane"><rect x="{x0}" y="{y0}" width="{pw}" height="{ph}"/></clipPath>')
    for (g, l, e, m, c, step), rs in cells.items():
        if g != GAMMA0 or l != LAMBDA0 or e != EPS0 or step != "fixed":
            continue
        d = sum(r["jammed"] for r in rs)
        out.append(f'<circle cx="{px(m):.1f}" cy="{py(c):.1f}" r="3" fill="black"/>')
        out.append(f'<text x="{px(m) + 6:.1f}" y="{py(c) - 6:.1f}">{d}/{len(rs)}</text>')
    pts = [night_rates(t) for t in range(0, 5701, 100)]
    out.append('<polyline clip-path="url(#plane)" fill="none" stroke="#1f4e9c" stroke-width="2.5" points="' + " ".join(f"{px(m):.1f},{py(c):.1f}" for m, c in pts) + '"/>')
    for t in (0, 1200, 2400, 3600):
        m, c = night_rates(t)
        out.append(f'<circle cx="{px(m):.1f}" cy="{py(c):.1f}" r="3.5" fill="#1f4e9c"/><text x="{px(m) - 8:.1f}" y="{py(c) + 4:.1f}" text-anchor="end" fill="#1f4e9c">{clock(t)[:5]}</text>')
    for run, t in nights.items():
        if t is None:
            continue
        m, c = night_rates(t)
        out.append(f'<path d="M{px(m) - 5:.1f},{py(c) - 5:.1f} L{px(m) + 5:.1f},{py(c) + 5:.1f} M{px(m) - 5:.1f},{py(c) + 5:.1f} L{px(m) + 5:.1f},{py(c) - 5:.1f}" stroke="#b00" stroke-width="2"/>')
    out.append(f'<text x="{x0}" y="{y0 + ph + 58}" fill="#1f4e9c" font-size="12">blue: the night\'s schedule (clock times); red ×: the 8 whole nights\' first jams on it</text>')

    # Right: the share of nights not yet jammed, predicted against the whole nights.
    x1, pw2 = 660, 480
    t_lo, t_hi = 300.0, 5700.0

    def tx(t):
        return x1 + (t - t_lo) / (t_hi - t_lo) * pw2

    def sy(s):
        return y0 + ph - s * ph
    out.append(f'<rect x="{x1}" y="{y0}" width="{pw2}" height="{ph}" fill="none" stroke="black"/>')
    out.append(f'<text x="{x1}" y="{y0 - 46}" font-weight="bold">Share of nights not yet jammed (inflow scale 1)</text>')
    also = ", orange dashes: adaptive step" if curve_adaptive else ""
    out.append(f'<text x="{x1}" y="{y0 - 28}" fill="#444" font-size="12">red: cheap model, fixed step (band: median\'s 95 %){also};</text>')
    out.append(f'<text x="{x1}" y="{y0 - 12}" fill="#444" font-size="12">{"green: corrected by the whole nights (× e^δ); " if curve_corrected else ""}black: the 8 whole nights</text>')
    for t, label in RECORDED:
        out.append(f'<line x1="{tx(t):.1f}" y1="{y0}" x2="{tx(t):.1f}" y2="{y0 + ph}" stroke="#999" stroke-dasharray="4,3"/>')
    out.append(f'<text x="{tx(FATAL_CLOG_S) - 4:.1f}" y="{y0 + 14}" text-anchor="end" fill="#777">fatal clog</text>')
    for t in range(600, 5701, 1200):
        out.append(f'<text x="{tx(t):.0f}" y="{y0 + ph + 18}" text-anchor="middle">{clock(t)[:5]}</text>')
    for s in (0, 0.25, 0.5, 0.75, 1.0):
        out.append(f'<text x="{x1 - 8}" y="{sy(s) + 4:.0f}" text-anchor="end">{s:g}</text>')
    lo, hi = median_band
    if hi != float("inf"):
        out.append(f'<rect x="{tx(lo):.1f}" y="{sy(0.52):.1f}" width="{max(tx(hi) - tx(lo), 1):.1f}" height="{sy(0.48) - sy(0.52):.1f}" fill="#f2b8b8"/>')
    out.append('<polyline fill="none" stroke="#b00" stroke-width="2.5" points="' + " ".join(f"{tx(t):.1f},{sy(s):.1f}" for t, s, _ in curve) + '"/>')
    if curve_corrected:
        out.append('<polyline fill="none" stroke="#1a7f37" stroke-width="2.5" points="' + " ".join(f"{tx(t):.1f},{sy(s):.1f}" for t, s, _ in curve_corrected) + '"/>')
    if curve_adaptive:
        out.append('<polyline fill="none" stroke="#e07b00" stroke-width="2.5" stroke-dasharray="7,4" points="' + " ".join(f"{tx(t):.1f},{sy(s):.1f}" for t, s, _ in curve_adaptive) + '"/>')
    observed = sorted(t for t in nights.values() if t is not None)
    pts, s = [(tx(t_lo), sy(1.0))], 1.0
    for t in observed:
        pts.append((tx(t), sy(s)))
        s -= 1.0 / len(nights)
        pts.append((tx(t), sy(s)))
    pts.append((tx(t_hi), sy(s)))
    out.append('<polyline fill="none" stroke="black" stroke-width="2" points="' + " ".join(f"{a:.1f},{b:.1f}" for a, b in pts) + '"/>')
    out.append(f'<text x="{x1 + pw2 / 2}" y="{y0 + ph + 38}" text-anchor="middle">time of night</text>')

    # Below: the hallway's own path in the whole nights (Figure 5's arrow, measured): density and counter-flow share.
    y2, ph2 = 560, 260
    panels = [(x0, pw, 2, 16.0, "persons/m²", "The whole nights' hallway: density (12 m × 3 m)"),
              (x1, pw2, 3, 0.5, "share", "... and its counter-flow share (the smaller group's)")]
    colours = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f"]
    for xp, wp, col, top, unit, title in panels:
        def ptx(t, xp=xp, wp=wp):
            return xp + t / NIGHT_END_S * wp

        def pty(v, top=top):
            return y2 + ph2 - min(v, top) / top * ph2
        out.append(f'<rect x="{xp}" y="{y2}" width="{wp}" height="{ph2}" fill="none" stroke="black"/>')
        out.append(f'<text x="{xp}" y="{y2 - 12}" font-weight="bold">{title}</text>')
        for t in range(0, 5701, 1200):
            out.append(f'<text x="{ptx(t):.0f}" y="{y2 + ph2 + 18}" text-anchor="middle">{clock(t)[:5]}</text>')
        for v in (0, top / 2, top):
            out.append(f'<text x="{xp - 8}" y="{pty(v) + 4:.0f}" text-anchor="end">{v:g}</text>')
        out.append(f'<text x="{xp - 50}" y="{y2 + ph2 / 2}" text-anchor="middle" transform="rotate(-90 {xp - 50} {y2 + ph2 / 2})">{unit}</text>')
        for t, _ in RECORDED:
            out.append(f'<line x1="{ptx(t):.1f}" y1="{y2}" x2="{ptx(t):.1f}" y2="{y2 + ph2}" stroke="#bbb" stroke-dasharray="4,3"/>')
        for k, (run, rows) in enumerate(paths.items()):
            pts = " ".join(f"{ptx(r[0]):.1f},{pty(r[col]):.1f}" for r in rows)
            out.append(f'<polyline fill="none" stroke="{colours[k % len(colours)]}" stroke-width="1.2" points="{pts}"/>')
    out.append(f'<text x="{x0}" y="{y2 + ph2 + 40}" fill="#444">one line per whole night (seeds 1-8, paper\'s model); grey dashes: the recorded avalanches and the fatal clog</text>')
    out.append("</svg>")
    guard.write_whole(file, "\n".join(out) + "\n")


if __name__ == "__main__":
    guard.run_main(main)
