#!/usr/bin/env python3
"""How long a pedestrian takes to follow a change of the person ahead: the
empirical anchor for a reaction time T_r of the drive (docs/decisions.md,
"Issue 39", "not yet tried: a reaction time"), measured from the Jülich
corridor trajectories (../shared/data/juelich-uni, juelich-bfr).

Method, per file (corridors along x; units and frame rate from the header,
as ../shared/data/README.md describes them; a file without a unit is read in
metres):
  1. Positions are smoothed by a centred moving average over SMOOTH_S (0.52 s,
     13 frames at 25 fps: one step, so the speed's oscillation at the step
     frequency of ~2 Hz, the head's bobbing along the flow, falls in the
     average's first zero) and differentiated by central differences.  Each
     person's direction is the sign of their mean x-velocity (in the uni
     corridor everyone walks -x, so this is the flow's); "speed" below is
     the velocity along one's own direction.
  2. Measurement area: the corridor between the walls of walkable_area.wkt
     (beside the file), its x range cut to the trajectories' extent and then
     END_CUT_M (1.5 m) off each end, away from where people enter and leave.
  3. Leader of person i at a frame: the nearest person ahead along i's
     direction, walking the same direction, with |dy| < BAND_M (0.4 m, a
     shoulder width) and ahead distance < AHEAD_M (2 m), both in the area.
     A pair (i, j) is a segment of frames in which j is i's leader, gaps of
     up to GAP_S (0.2 s) bridged, lasting MIN_PAIR_S (4 s) or more, of
     which the frames where j's speed MAX_LAG_S earlier is known are used.
  4. Per segment, the Pearson correlation r(L) of the follower's speed u_i(t)
     with the leader's u_j(t - L), L = 0 ... MAX_LAG_S in frame steps, each
     series minus its segment mean; r(L) averaged over segments weighted by
     their length; the lag of its maximum (parabola through the top three
     points).  Interval: bootstrap over followers (a person's segments
     resampled together), 2000 resamples, 68 % and 95 % percentile intervals.
     Per segment: the lag of its own maximum, for segments whose maximum
     r exceeds 0.3 (median, quartiles).
  5. First-order lag: u_j filtered by exp(-s/T)/T (exact weights of each
     frame's interval, so the filter's mean delay is T), correlated with u_i
     as in 4; T_r maximises the weighted mean correlation over T = 0.05 ...
     2 s; the same bootstrap.  A pure delay L and a first-order lag T_r with
     the same mean delay are T_r = L; the lag that maximises the correlation
     with an exponentially lagged signal is less than T_r (the filter's
     mode is at 0), so T_r >= L* is expected.
  6. Context: density in the measurement area per frame (people / m^2),
     the density, headway and speed at the pairs' frames; r(L) also for
     L < 0 (leader following follower) as a check that the correlation is
     causal and not common to both; the lag and T_r again with other
     smoothing windows (0.04 s: none), with linear instead of mean
     detrending, and with looser pairs (|dy| < 0.6 m, ahead < 3 m, >= 3 s).
     With fewer than FEW_FOLLOWERS (20) followers the report says that
     there is no estimate and prints the numbers only as computed.

Biases and limits, none corrected:
  * Smoothing: the moving average is symmetric and applied to both speeds,
    so it does not move a symmetric correlation peak, but it widens it and
    pulls a skewed one (a lagged response) toward its mean; and
    PeTrack's head positions carry the sway of the gait (lateral at the
    stride frequency, ~1 Hz, along the flow at the step frequency, ~2 Hz):
    with too little smoothing the step's oscillation can alias a
    correlation peak at multiples of ~0.5 s (people walking in step), with
    too much it makes the peak broad.  The sensitivity table shows how much
    the result depends on it.
  * Tracking noise is white position noise; after differentiation it is
    uncorrelated between people, so it lowers r but does not shift its peak.
  * The lag measured is the whole follower's loop: perception, the decision
    and the body's acceleration (in the model: T_r, the relaxation time tau
    and the repulsion's stiffness together).  It is not T_r itself: the model's
    T_r is to be set so that the same statistic on simulated trajectories
    matches it.
  * Common causes (the whole flow slowing at a jam further ahead) correlate
    speeds without a leader-follower lag; the r(L < 0) check shows how much.
  * At low density (the uni file, ~0.3 /m^2) people walk at their own free
    speed and hardly react to anyone: few pairs qualify, and with looser
    pairs r(L) is flat and symmetric in L (no following); without
    smoothing its speeds correlate periodically at ~0.5 s, symmetric in L
    (the step's oscillation), which a one-sided search would read as a
    lag.  It is reported as measured.
  * Check of the code: two people walking one path 0.6 s apart (synthetic
    tracks, leader's speed a random walk) give L* = 0.60 s, T_r = 0.70 s.

Simulated runs (the same measurement on the model, to choose its drive_reaction_time_s): SQLite files
in JuPedSim format, i.e. crowdrecon run files, their exports (`crowdrecon export`) or other JuPedSim
trajectory files, given as files (each its own section, or one with --pool) or as a sweep folder with
kept runs (--sweep DIR: one section per variant, its seeds pooled; a follower is (run, person), so the
bootstrap resamples people across seeds).  What differs from the PeTrack path, and why:
  * Reading: positions, ids and fps from trajectory_data and metadata; the corridor's y range from the
    bounding box of the walkable area (geometry); the periodic box from the run table (periodic_box)
    or an export's metadata (crowdrecon_periodic).  An export's pieces (a trajectory cut at each seam,
    each piece its own id) are joined again into one track per person through crowdrecon_track.
  * Periodic box: each step is taken as its minimum image, so a track is continuous across the seam and
    smoothing and speeds never see the seam's jump.  Positions are wrapped into the box again for the
    area, the density and the leaders.
  * Measurement area (--periodic-area): by default ("cut") the box minus END_CUT_M at each end, the
    data's rule applied to the box: nobody enters or leaves a periodic box, so the ends need no cut for
    their own sake, but the cut keeps what shapes the statistic as in the data: the area's length (7.0 m
    here, 6.55 m in bi_corr_400_b_03), hence how long a pair stays in it (segments end when either
    leaves; the mean is taken per segment), and the leader is never looked for across the seam.  The
    alternative ("whole", shown as a sensitivity row) is the whole box, leaders also across the seam
    (minimum image): pairs then last up to the whole run, and per-segment means remove less of the slow
    common variation.  Unlike the data's people, a simulated leader's speed is known before it enters
    the area, so no segment loses its first frames to the leader's history.
  * --from-s S drops the frames before S: people start at rest and the crowd takes ~25-40 s to settle
    (lanes, speeds); 30 s is dropped for the corridor's 120 s runs.
  * Everything else is identical: smoothing, windows in seconds, the leader rule, the first-order lag
    grid, the bootstrap, the sensitivity table.  A summary table of all sections (data and runs) comes
    first when there are simulated runs; without them the report is as before.

usage: studies/reaction-time/reaction-time-from-data.py [TRAJECTORIES.txt ...] [RUN.sqlite ...] [--pool]
         [--sweep DIR [--variants A,B]] [--from-s 30] [--periodic-area cut|whole]
         [-o REPORT.md] [--bootstrap 2000]
  (default: ../shared/data/juelich-uni/traj_UNI_CORR_500_01.txt and ../shared/data/juelich-bfr/bi_corr_400_b_03.txt;
  prints a plain-text report; -o writes the same as markdown).  Standard library only; one process, ~15 s
  for the two files, ~2 min per sweep variant of 10 runs of 120 s (39 people).
  The default files need the data folder ../shared/data beside the repository (said by name when it is
  missing). -o is checked before any work and written whole (scripts/script_guard.py): never an input,
  an existing file that is not a previous report only with --force. A bad argument or input (a file that
  is not a trajectory file, a folder that is not a sweep, --bootstrap 0, --variants without --sweep) is
  one line, exit status 2.
"""
import argparse
import collections
import json
import math
import os
import random
import re
import sqlite3
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))  # studies/NAME/ is two levels down
sys.path.insert(0, os.path.join(ROOT, 'scripts'))
from petrack import read_petrack  # noqa: E402  (scripts/: the PeTrack reader the studies share)
import script_guard as guard  # noqa: E402

DATA = os.path.join(ROOT, '..', 'shared', 'data')
DEFAULT_FILES = [os.path.join(DATA, 'juelich-uni', 'traj_UNI_CORR_500_01.txt'),
                 os.path.join(DATA, 'juelich-bfr', 'bi_corr_400_b_03.txt')]

SMOOTH_S = 0.52            # moving-average window (13 frames at 25 fps)
END_CUT_M = 1.5            # cut off each end of the corridor
BAND_M = 0.4               # |dy| to the leader
AHEAD_M = 2.0              # ahead distance to the leader
GAP_S = 0.2                # gaps in a pair's frames bridged
MIN_PAIR_S = 4.0           # a pair must last this long
MAX_LAG_S = 2.0            # lags 0 ... MAX_LAG_S
R_PAIR_MIN = 0.3           # per-pair maxima counted above this r
T_GRID = [0.05 * k for k in range(1, 41)]   # first-order lag T, s
RELAXED = (0.6, 3.0, 3.0)  # band, ahead, minimum duration of the sensitivity's relaxed pairs
FEW_FOLLOWERS = 20        # fewer followers than this: no estimate


# ---------------------------------------------------------------- reading

def read_corridor(path):
    """(x0, x1, y0, y1) between the two wall obstacles of a corridor's walkable_area.wkt, or None."""
    if not os.path.exists(path):
        return None
    with open(path) as f:
        text = f.read()
    rings = []
    for ring in re.findall(r'\(([^()]+)\)', text):
        pts = [tuple(float(v) for v in p.split()) for p in ring.split(',')]
        rings.append(pts)
    holes = rings[1:]
    if len(holes) != 2:
        return None
    boxes = sorted((min(p[1] for p in h), max(p[1] for p in h), min(p[0] for p in h), max(p[0] for p in h))
                   for h in holes)
    lower, upper = boxes
    return (max(lower[2], upper[2]), min(lower[3], upper[3]), lower[1], upper[0])


def read_sqlite(path, from_s=0.0):
    """A crowdrecon run file, its export or another JuPedSim trajectory file (SQLite): id -> [(frame, x, y)],
    one track per person (an export's pieces joined again through crowdrecon_track), the frame rate,
    the periodic box along x as (x_min, x_max) or None, the walkable area's bounding box (x0, x1, y0, y1)
    and notes.  Frames before from_s are dropped.  In a periodic box the positions are unwrapped: each step
    is the minimum image of the stored one, so a track is continuous across the seams."""
    guard.require_tables(path, ['trajectory_data'], 'a JuPedSim trajectory file (a crowdrecon run file, its export, '
                         'or another JuPedSim SQLite file)')
    con = sqlite3.connect(f'file:{os.path.abspath(path)}?mode=ro', uri=True)
    tables = {r[0] for r in con.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
    notes = []
    meta = dict(con.execute('SELECT key, value FROM metadata')) if 'metadata' in tables else {}
    fps = float(meta.get('fps', 0) or 0)
    if fps <= 0:
        fps = 25.0
        notes.append('no frame rate in the metadata: 25 fps assumed')
    box_json = meta.get('crowdrecon_periodic')
    kind = 'crowdrecon export' if 'crowdrecon_export' in meta else 'JuPedSim trajectory file'
    if 'run' in tables:
        run = dict(con.execute('SELECT key, value FROM run'))
        if run.get('format') == 'crowdrecon-run':
            kind = 'crowdrecon run file'
            box_json = run.get('periodic_box', box_json)
    period = None
    if box_json:
        box = json.loads(box_json)
        if box.get('y'):
            raise guard.ScriptError(f'{path}: periodic along y; expected a corridor periodic along x (or not periodic)')
        if box.get('x'):
            period = (float(box['min_m'][0]), float(box['max_m'][0]))
    # first frame kept
    if 'frame_time' in tables:
        times = dict(con.execute('SELECT frame, time_s FROM frame_time'))
    else:
        times = None
    person_of = {}
    if 'crowdrecon_track' in tables:
        person_of = {tid: (person, part) for tid, person, part in
                     con.execute('SELECT id, person, part FROM crowdrecon_track')}
    pieces = collections.defaultdict(list)     # person -> [(part, [(frame, x, y)])]
    current = {}
    for fr, tid, x, y in con.execute('SELECT frame, id, pos_x, pos_y FROM trajectory_data ORDER BY id, frame'):
        t = times.get(fr, fr / fps) if times is not None else fr / fps
        if t < from_s - 1e-9:
            continue
        if tid not in current:
            person, part = person_of.get(tid, (tid, 0))
            current[tid] = []
            pieces[person].append((part, current[tid]))
        current[tid].append((fr, x, y))
    tracks = {}
    for person, parts in pieces.items():
        parts.sort(key=lambda q: q[0])
        track = [p for _part, pts in parts for p in pts]
        track.sort()
        if period is not None:
            length = period[1] - period[0]
            out = [track[0]]
            for (fr0, xr0, _y0), (fr, x, y) in zip(track, track[1:]):
                dx = x - xr0
                dx -= length * round(dx / length)
                out.append((fr, out[-1][1] + dx, y))
            track = out
        tracks[person] = track
    area = None
    if 'geometry' in tables:
        row = con.execute('SELECT wkt FROM geometry LIMIT 1').fetchone()
        if row:
            nums = [float(v) for v in re.findall(r'-?[0-9.]+(?:[eE][-+]?[0-9]+)?', row[0])]
            xs, ys = nums[0::2], nums[1::2]
            if xs:
                area = (min(xs), max(xs), min(ys), max(ys))
    con.close()
    return tracks, fps, period, area, kind, notes


def simulated_corridor(tracks, period, area, periodic_area):
    """The measurement area (x0, x1, y0, y1) of a simulated corridor and whether leaders wrap around."""
    if area is None:
        xs = [p[1] for t in tracks.values() for p in t]
        ys = [p[2] for t in tracks.values() for p in t]
        area = (min(xs), max(xs), min(ys), max(ys))
    if period is not None:
        if periodic_area == 'whole':
            return (period[0], period[1], area[2], area[3]), True
        return (period[0] + END_CUT_M, period[1] - END_CUT_M, area[2], area[3]), False
    xs = [p[1] for t in tracks.values() for p in t]
    return (max(area[0], min(xs)) + END_CUT_M, min(area[1], max(xs)) - END_CUT_M, area[2], area[3]), False


# ---------------------------------------------------------------- kinematics

def moving_average(values, w):
    """Centred moving average of odd width w; entry k is centred on values[k + w // 2]."""
    out = []
    s = sum(values[:w])
    out.append(s / w)
    for k in range(w, len(values)):
        s += values[k] - values[k - w]
        out.append(s / w)
    return out


class Person:
    __slots__ = ('pid', 'start', 'x', 'y', 'vx', 'd', 'u')

    def __init__(self, pid, track, w, fps):
        h = w // 2
        frames = [p[0] for p in track]
        if frames[-1] - frames[0] + 1 != len(frames):
            raise guard.ScriptError(f'person {pid}: frames not contiguous; expected a track in every frame from its first to its last')
        sx = moving_average([p[1] for p in track], w)
        sy = moving_average([p[2] for p in track], w)
        # velocity valid at smoothed index 1 .. len-2, i.e. frame frames[0] + h + 1 ...
        self.pid = pid
        self.start = frames[0] + h + 1
        self.x = sx[1:-1]
        self.y = sy[1:-1]
        self.vx = [(sx[k + 1] - sx[k - 1]) * fps / 2 for k in range(1, len(sx) - 1)]
        self.d = 1 if sum(self.vx) > 0 else -1
        self.u = [self.d * v for v in self.vx]

    def end(self):
        return self.start + len(self.u) - 1


# ---------------------------------------------------------------- statistics

def pearson(a, b):
    n = len(a)
    ma = sum(a) / n
    mb = sum(b) / n
    sab = saa = sbb = 0.0
    for p, q in zip(a, b):
        p -= ma
        q -= mb
        sab += p * q
        saa += p * p
        sbb += q * q
    if saa <= 0 or sbb <= 0:
        return 0.0
    return sab / math.sqrt(saa * sbb)


def linear_detrend(a):
    n = len(a)
    mid = (n - 1) / 2
    mean = sum(a) / n
    den = sum((k - mid) ** 2 for k in range(n))
    slope = sum((k - mid) * (v - mean) for k, v in enumerate(a)) / den
    return [v - mean - slope * (k - mid) for k, v in enumerate(a)]


def argmax_refined(values, xs):
    """x of the maximum, refined by a parabola through the top three points (not at an end)."""
    k = max(range(len(values)), key=values.__getitem__)
    if 0 < k < len(values) - 1:
        a, b, c = values[k - 1], values[k], values[k + 1]
        den = a - 2 * b + c
        if den < 0:
            off = 0.5 * (a - c) / den
            return xs[k] + off * (xs[1] - xs[0])
    return xs[k]


def quantile(sorted_values, q):
    if not sorted_values:
        return float('nan')
    pos = q * (len(sorted_values) - 1)
    lo = int(math.floor(pos))
    hi = min(lo + 1, len(sorted_values) - 1)
    return sorted_values[lo] + (pos - lo) * (sorted_values[hi] - sorted_values[lo])


def exp_filter(u, T, dt):
    """u filtered by exp(-s/T)/T, each past sample weighted by the integral over its frame interval
    (midpoint rule), so the mean delay is T; the first value starts the filter."""
    a = math.exp(-dt / T)
    c0 = 1.0 - math.exp(-dt / (2 * T))
    c1 = math.exp(-dt / (2 * T)) * (1.0 - a)
    out = []
    z = u[0] * (1.0 - c0)       # as if u had been u[0] forever
    for k, v in enumerate(u):
        if k > 0:
            z = a * z + c1 * u[k - 1]
        out.append(c0 * v + z)
    return out


# ---------------------------------------------------------------- the analysis

def analyse(tracks, fps, corridor, smooth_s, detrend='mean', need_two_sided=True,
            band=BAND_M, ahead_max=AHEAD_M, min_pair_s=MIN_PAIR_S, period=None, wrap_leaders=False):
    """period: (x_min, length) of a box periodic along x (tracks unwrapped, i.e. continuous across the
    seam): positions are wrapped into the box for the area, the density and the leaders; wrap_leaders:
    the leader is also looked for across the seam (minimum image), for an area that is the whole box."""
    dt = 1.0 / fps
    w = max(1, int(round(smooth_s * fps)))
    if w % 2 == 0:
        w += 1
    people = {pid: Person(pid, t, w, fps) for pid, t in tracks.items() if len(t) > w + 2}
    x0, x1, y0, y1 = corridor
    area_m2 = (x1 - x0) * (y1 - y0)

    if period is None:
        def wrap(x):
            return x
    else:
        def wrap(x, b=period[0], length=period[1]):
            return b + (x - b) % length

    def inside(x, y):
        x = wrap(x)
        return x0 <= x <= x1 and y0 <= y <= y1

    # density from the raw positions
    counts = collections.Counter()
    frames_all = set()
    for t in tracks.values():
        for fr, x, y in t:
            frames_all.add(fr)
            if inside(x, y):
                counts[fr] += 1
    density = {fr: counts[fr] / area_m2 for fr in frames_all}

    # leaders, frame by frame
    by_frame = collections.defaultdict(list)
    for p in people.values():
        for k in range(len(p.u)):
            if inside(p.x[k], p.y[k]):
                by_frame[p.start + k].append((p.d * wrap(p.x[k]), p.y[k], p.pid, p.d))
    leader_frames = collections.defaultdict(list)   # (i, j) -> frames
    headway = {}                                      # (i, frame) -> ahead distance
    for fr, rows in by_frame.items():
        for d in (1, -1):
            group = sorted(r for r in rows if r[3] == d)
            n_group = len(group)
            for a in range(n_group):
                s_i, y_i, pid_i, _ = group[a]
                for b in range(a + 1, n_group + a if wrap_leaders else n_group):
                    s_j, y_j, pid_j, _ = group[b % n_group]
                    ahead = s_j - s_i + (period[1] if b >= n_group else 0.0)
                    if ahead >= ahead_max:
                        break
                    if ahead > 0 and abs(y_j - y_i) < band:
                        leader_frames[(pid_i, pid_j)].append(fr)
                        headway[(pid_i, fr)] = ahead
                        break

    gap = int(round(GAP_S * fps))
    min_len = int(round(min_pair_s * fps))
    max_lag = int(round(MAX_LAG_S * fps))
    lags = list(range(0, max_lag + 1))
    segments = []      # dicts
    for (i, j), frs in leader_frames.items():
        frs.sort()
        runs = [[frs[0], frs[0]]]
        for fr in frs[1:]:
            if fr - runs[-1][1] <= gap + 1:
                runs[-1][1] = fr
            else:
                runs.append([fr, fr])
        for first, last in runs:
            if last - first + 1 < min_len:
                continue
            segments.append({'i': i, 'j': j, 'first': first, 'last': last})

    def series(p, a, b):
        return p.u[a - p.start:b - p.start + 1]

    filtered = {}    # (leader, T index) -> the leader's whole speed series filtered (computed once)
    used = []
    two_sided_sum = [0.0] * (2 * max_lag + 1)
    two_sided_n = 0
    for seg in segments:
        fi, le = people[seg['i']], people[seg['j']]
        first = max(seg['first'], le.start + max_lag)
        last = seg['last']
        n = last - first + 1
        if n < min_len:
            continue
        uf = series(fi, first, last)
        if detrend == 'linear':
            uf_d = linear_detrend(uf)
        r = []
        for L in lags:
            ul = series(le, first - L, last - L)
            if detrend == 'linear':
                r.append(pearson(uf_d, linear_detrend(ul)))
            else:
                r.append(pearson(uf, ul))
        # first-order lag: leader's speed filtered from its first frame on
        rT = []
        for kT, T in enumerate(T_GRID):
            filt = filtered.get((le.pid, kT))
            if filt is None:
                filt = filtered[(le.pid, kT)] = exp_filter(le.u, T, dt)
            ul = filt[first - le.start:last - le.start + 1]
            rT.append(pearson(linear_detrend(uf), linear_detrend(ul)) if detrend == 'linear' else pearson(uf, ul))
        seg.update(n=n, first_used=first, r=r, rT=rT,
                   hw=[headway[(seg['i'], fr)] for fr in range(first, last + 1) if (seg['i'], fr) in headway],
                   dens=[density.get(fr, 0.0) for fr in range(first, last + 1)],
                   speed=sum(uf) / n)
        used.append(seg)
        if need_two_sided:
            # r(L) for L in -max_lag..max_lag on the frames where the leader is known 2 s before and after
            last2 = min(last, le.end() - max_lag)
            if last2 - first + 1 >= int(round(2.0 * fps)):
                uf2 = series(fi, first, last2)
                nn = last2 - first + 1
                for k, L in enumerate(range(-max_lag, max_lag + 1)):
                    two_sided_sum[k] += nn * pearson(uf2, series(le, first - L, last2 - L))
                two_sided_n += nn

    lag_s = [L * dt for L in lags]
    total = sum(s['n'] for s in used)
    res = {'people': len(people), 'window_frames': w, 'area_m2': area_m2, 'density': density, 'segments': used,
           'lag_s': lag_s, 'pairs': len({(s['i'], s['j']) for s in used}),
           'followers': len({s['i'] for s in used}), 'frames': total,
           'directions': collections.Counter(p.d for p in people.values())}
    if not used:
        return res
    R = [sum(s['n'] * s['r'][k] for s in used) / total for k in range(len(lags))]
    RT = [sum(s['n'] * s['rT'][k] for s in used) / total for k in range(len(T_GRID))]
    res.update(R=R, RT=RT, lag_best=argmax_refined(R, lag_s), T_best=argmax_refined(RT, T_GRID))
    if two_sided_n:
        res['R2'] = [v / two_sided_n for v in two_sided_sum]
        res['lag2_s'] = [L * dt for L in range(-max_lag, max_lag + 1)]
        res['two_sided_frames'] = two_sided_n
    return res


def merge(results):
    """Pool the analyses of several runs (seeds) as one: segments weighted by length as within a run, a
    person of run k is follower (k, id), so the bootstrap resamples followers across runs."""
    if len(results) == 1:
        return results[0]
    first = results[0]
    out = {'people': sum(r['people'] for r in results), 'window_frames': first['window_frames'],
           'area_m2': first['area_m2'], 'lag_s': first['lag_s'],
           'density': {(k, fr): v for k, r in enumerate(results) for fr, v in r['density'].items()},
           'segments': [dict(s, i=(k, s['i']), j=(k, s['j'])) for k, r in enumerate(results) for s in r['segments']],
           'directions': sum((r['directions'] for r in results), collections.Counter())}
    used = out['segments']
    out.update(pairs=len({(s['i'], s['j']) for s in used}), followers=len({s['i'] for s in used}),
               frames=sum(s['n'] for s in used))
    if not used:
        return out
    total = out['frames']
    R = [sum(s['n'] * s['r'][k] for s in used) / total for k in range(len(first['lag_s']))]
    RT = [sum(s['n'] * s['rT'][k] for s in used) / total for k in range(len(T_GRID))]
    out.update(R=R, RT=RT, lag_best=argmax_refined(R, out['lag_s']), T_best=argmax_refined(RT, T_GRID))
    two = [r for r in results if 'R2' in r]
    if two:
        n2 = sum(r['two_sided_frames'] for r in two)
        out['R2'] = [sum(r['two_sided_frames'] * r['R2'][k] for r in two) / n2 for k in range(len(two[0]['R2']))]
        out['lag2_s'] = two[0]['lag2_s']
        out['two_sided_frames'] = n2
    return out


def bootstrap(res, n_boot, seed=1):
    """Percentiles of the lag of the maximum and of T_r over resamples of followers."""
    per = collections.defaultdict(lambda: [0, None, None])
    for s in res['segments']:
        acc = per[s['i']]
        acc[0] += s['n']
        wr = [s['n'] * v for v in s['r']]
        wt = [s['n'] * v for v in s['rT']]
        acc[1] = wr if acc[1] is None else [a + b for a, b in zip(acc[1], wr)]
        acc[2] = wt if acc[2] is None else [a + b for a, b in zip(acc[2], wt)]
    keys = sorted(per)
    rng = random.Random(seed)
    lags, Ts = [], []
    for _ in range(n_boot):
        n = 0
        R = [0.0] * len(res['lag_s'])
        RT = [0.0] * len(T_GRID)
        for _k in keys:
            acc = per[keys[rng.randrange(len(keys))]]
            n += acc[0]
            R = [a + b for a, b in zip(R, acc[1])]
            RT = [a + b for a, b in zip(RT, acc[2])]
        lags.append(argmax_refined(R, res['lag_s']))
        Ts.append(argmax_refined(RT, T_GRID))
    lags.sort()
    Ts.sort()

    def iv(v):
        return {68: (quantile(v, 0.16), quantile(v, 0.84)), 95: (quantile(v, 0.025), quantile(v, 0.975))}
    return iv(lags), iv(Ts)


# ---------------------------------------------------------------- report

class Report:
    def __init__(self):
        self.blocks = []

    def heading(self, text, level=2):
        self.blocks.append(('h', level, text))

    def para(self, text):
        self.blocks.append(('p', text))

    def table(self, header, rows):
        self.blocks.append(('t', header, rows))

    def code(self, text):
        self.blocks.append(('c', text))

    def text(self):
        out = []
        for b in self.blocks:
            if b[0] == 'h':
                out += ['', b[2], ('=' if b[1] == 1 else '-') * len(b[2])]
            elif b[0] == 'p':
                out += [b[1].replace('`', '').replace('**', ''), '']
            elif b[0] == 't':
                rows = [b[1]] + b[2]
                widths = [max(len(str(r[c])) for r in rows) for c in range(len(b[1]))]
                for k, r in enumerate(rows):
                    out.append('  '.join(str(v).ljust(widths[c]) for c, v in enumerate(r)).rstrip())
                    if k == 0:
                        out.append('  '.join('-' * wd for wd in widths))
                out.append('')
            else:
                out += [b[1], '']
        return '\n'.join(out).strip() + '\n'

    def markdown(self):
        out = []
        for b in self.blocks:
            if b[0] == 'h':
                out += ['#' * b[1] + ' ' + b[2], '']
            elif b[0] == 'p':
                out += [b[1], '']
            elif b[0] == 't':
                out.append('| ' + ' | '.join(b[1]) + ' |')
                out.append('|' + '|'.join('---' for _ in b[1]) + '|')
                for r in b[2]:
                    out.append('| ' + ' | '.join(str(v).replace('|', '\\|') for v in r) + ' |')
                out.append('')
            else:
                out += ['```', b[1], '```', '']
        return '\n'.join(out).strip() + '\n'


def q3(values):
    v = sorted(values)
    return quantile(v, 0.25), quantile(v, 0.5), quantile(v, 0.75)


def report_file(rep, path, n_boot, unit):
    tracks, fps, unit_used, notes = read_petrack(path, unit)
    wkt = os.path.join(os.path.dirname(path), 'walkable_area.wkt')
    walls = read_corridor(wkt)
    xs = [p[1] for t in tracks.values() for p in t]
    ys = [p[2] for t in tracks.values() for p in t]
    if walls is None:
        notes.append('no corridor in walkable_area.wkt: the trajectories\' extent is used')
        walls = (min(xs), max(xs), min(ys), max(ys))
    x0 = max(walls[0], min(xs)) + END_CUT_M
    x1 = min(walls[1], max(xs)) - END_CUT_M
    corridor = (x0, x1, walls[2], walls[3])

    res = analyse(tracks, fps, corridor, SMOOTH_S)
    name = os.path.relpath(path, os.path.join(HERE, '..'))
    rep.heading(os.path.basename(path))
    dirs = ', '.join(f'{n} walking {"+x" if d > 0 else "-x"}' for d, n in sorted(res['directions'].items()))
    rep.para(f'`{name}`: {len(tracks)} people ({dirs}), {fps:g} fps, unit {unit_used}'
             + (' (' + '; '.join(notes) + ')' if notes else '') + '. '
             f'Measurement area x ∈ [{x0:.2f}, {x1:.2f}] m, y ∈ [{walls[2]:.2f}, {walls[3]:.2f}] m '
             f'({res["area_m2"]:.1f} m²); smoothing {res["window_frames"]} frames '
             f'({res["window_frames"] / fps:.2f} s).')

    def reanalyse(sm, det, kw):
        return analyse(tracks, fps, corridor, sm, det, True, **kw)
    return report_result(rep, res, fps, n_boot, reanalyse, os.path.basename(path))


def report_result(rep, res, fps, n_boot, reanalyse, label, extra=()):
    """The tables of one measurement (a file, or a variant's runs pooled); reanalyse(smoothing, detrending,
    pair criteria) gives the sensitivity's analyses; extra: more sensitivity rows (label, analysis).
    Returns the summary row's values."""
    section = label
    dens = sorted(v for v in res['density'].values() if v > 0)
    seg = res['segments']
    if not seg:
        rep.para('No leader-follower pair lasts long enough: nothing measured.')
        return {'label': label, 'res': res}
    pair_dens = sorted(d for s in seg for d in s['dens'])
    hw = sorted(h for s in seg for h in s['hw'])
    speeds = sorted(s['speed'] for s in seg)
    rep.table(['quantity', 'value'], [
        ['density in the area (frames with anyone in it), median [10 %, 90 %], max',
         f'{quantile(dens, 0.5):.2f} [{quantile(dens, 0.1):.2f}, {quantile(dens, 0.9):.2f}], {dens[-1]:.2f} /m²'],
        ['density at the pairs\' frames, median [10 %, 90 %]',
         f'{quantile(pair_dens, 0.5):.2f} [{quantile(pair_dens, 0.1):.2f}, {quantile(pair_dens, 0.9):.2f}] /m²'],
        ['pairs (segments) / followers', f'{res["pairs"]} ({len(seg)}) / {res["followers"]}'],
        ['frames used', f'{res["frames"]} ({res["frames"] / fps:.0f} s); segment length median '
                        f'{quantile(sorted(s["n"] for s in seg), 0.5) / fps:.1f} s'],
        ['headway to the leader, quartiles', '{:.2f}, {:.2f}, {:.2f} m'.format(*q3(hw))],
        ['follower speed (segment mean), quartiles', '{:.2f}, {:.2f}, {:.2f} m/s'.format(*q3(speeds))],
    ])
    if res['followers'] < FEW_FOLLOWERS:
        rep.para(f'**Too few pairs for an estimate** ({res["followers"]} followers, fewer than {FEW_FOLLOWERS}): '
                 'the figures below are printed as computed, not as a measurement.')
    iv_lag, iv_T = bootstrap(res, n_boot)
    lag_s = res['lag_s']
    R = res['R']
    k0 = max(range(len(R)), key=R.__getitem__)
    kT = max(range(len(T_GRID)), key=res['RT'].__getitem__)
    rep.table(['estimate', 'value', '68 % interval', '95 % interval'], [
        ['lag L* of the maximum of mean r(L)', f'{res["lag_best"]:.2f} s (r = {R[k0]:.3f}; r(0) = {R[0]:.3f})'
         + (' (end of the range)' if k0 == len(R) - 1 else ''),
         '{:.2f} – {:.2f} s'.format(*iv_lag[68]), '{:.2f} – {:.2f} s'.format(*iv_lag[95])],
        ['first-order lag T_r (max of mean r)', f'{res["T_best"]:.2f} s (r = {res["RT"][kT]:.3f})'
         + (' (end of the grid)' if kT in (0, len(T_GRID) - 1) else ''),
         '{:.2f} – {:.2f} s'.format(*iv_T[68]), '{:.2f} – {:.2f} s'.format(*iv_T[95])],
    ])
    strong = [s for s in seg if max(s['r']) > R_PAIR_MIN]
    per_lag = [lag_s[max(range(len(s['r'])), key=s['r'].__getitem__)] for s in strong]
    per_T = [T_GRID[max(range(len(T_GRID)), key=s['rT'].__getitem__)] for s in strong]
    at_end = sum(1 for v in per_lag if v in (lag_s[0], lag_s[-1]))
    if strong:
        rep.para(f'Per segment, {len(strong)} of {len(seg)} segments have max r > {R_PAIR_MIN}: '
                 'lag of their maximum {:.2f} s median, quartiles {:.2f} – {:.2f} s'.format(
                     *(lambda a: (a[1], a[0], a[2]))(q3(per_lag)))
                 + f' ({at_end} at an end of 0 – {MAX_LAG_S:g} s); their best T_r '
                 '{:.2f} s median, quartiles {:.2f} – {:.2f} s.'.format(*(lambda a: (a[1], a[0], a[2]))(q3(per_T))))
    else:
        rep.para(f'No segment has max r > {R_PAIR_MIN}.')
    rows = []
    for k in range(0, len(lag_s), 5):
        rows.append([f'{lag_s[k]:.1f}', f'{R[k]:.3f}'])
    if 'R2' in res:
        R2, l2 = res['R2'], res['lag2_s']
        mid = len(R2) // 2
        rows = [[f'{lag_s[k]:.1f}', f'{R[k]:.3f}', f'{R2[mid + k]:.3f}', f'{R2[mid - k]:.3f}']
                for k in range(0, len(lag_s), 5)]
        k2 = max(range(len(R2)), key=R2.__getitem__)
        rep.para(f'Mean r(L) (the causality check: r(-L), the leader\'s speed L after the follower\'s, on the '
                 f'{res["two_sided_frames"]} frames where the leader is known {MAX_LAG_S:g} s before and after; '
                 f'its maximum over −{MAX_LAG_S:g} … {MAX_LAG_S:g} s is at {argmax_refined(R2, l2):+.2f} s, '
                 f'r = {R2[k2]:.3f}):')
        rep.table(['L (s)', 'r(L)', 'r(L), check frames', 'r(−L), check frames'], rows)
    else:
        rep.table(['L (s)', 'r(L)'], rows)
    def excess(r2):
        if 'R2' not in r2:
            return '–'
        mid = len(r2['R2']) // 2
        k = int(round(r2['lag_best'] * fps))
        return f'{round(r2["R2"][mid + k] - r2["R2"][mid - k], 3) + 0.0:+.3f}'

    variants = [  # smoothing (s), detrending, pair criteria (band, ahead, minimum duration)
        (0.04, 'mean', None), (0.28, 'mean', None), (SMOOTH_S, 'mean', None), (1.0, 'mean', None),
        (0.28, 'linear', None), (SMOOTH_S, 'linear', None), (SMOOTH_S, 'mean', RELAXED)]
    rows = []
    for sm, det, crit in variants:
        if (sm, det, crit) == (SMOOTH_S, 'mean', None):
            r2 = res
        else:
            kw = dict(zip(('band', 'ahead_max', 'min_pair_s'), crit)) if crit else {}
            r2 = reanalyse(sm, det, kw)
        label = (f'|dy| < {crit[0]:g} m, ahead < {crit[1]:g} m, ≥ {crit[2]:g} s' if crit else 'as above')
        if not r2['segments']:
            rows.append([f'{sm:.2f}', det, label, '0 / 0', '–', '–', '–'])
            continue
        rows.append([f'{r2["window_frames"] / fps:.2f}', det, label,
                     f'{len(r2["segments"])} / {r2["followers"]}',
                     f'{r2["lag_best"]:.2f} (r = {max(r2["R"]):.3f})',
                     f'{r2["T_best"]:.2f} (r = {max(r2["RT"]):.3f})', excess(r2)])
    for label2, r2 in extra:
        if not r2['segments']:
            rows.append([f'{SMOOTH_S:.2f}', 'mean', label2, '0 / 0', '–', '–', '–'])
            continue
        rows.append([f'{r2["window_frames"] / fps:.2f}', 'mean', label2,
                     f'{len(r2["segments"])} / {r2["followers"]}',
                     f'{r2["lag_best"]:.2f} (r = {max(r2["R"]):.3f})',
                     f'{r2["T_best"]:.2f} (r = {max(r2["RT"]):.3f})', excess(r2)])
    rep.para('Sensitivity (no bootstrap; smoothing 0.04 s is none; last column: the causal excess, r at +L* minus '
             'r at −L* on the check frames, about 0 when the correlation is common to both and not a following):')
    rep.table(['smoothing (s)', 'detrending', 'pairs', 'segments / followers', 'L* (s)', 'T_r (s)',
               'r(L*) − r(−L*)'], rows)
    return {'label': section, 'res': res, 'iv_lag': iv_lag, 'iv_T': iv_T, 'pair_dens': pair_dens,
            'speeds': speeds, 'hw': hw, 'excess': excess(res)}


def report_runs(rep, label, paths, n_boot, from_s, periodic_area):
    """One section for simulated runs (a sweep variant's seeds, or files), pooled; the summary row."""
    runs = [read_sqlite(p, from_s) for p in paths]
    fps = runs[0][1]
    if any(abs(r[1] - fps) > 1e-9 for r in runs):
        raise guard.ScriptError(f'{label}: the runs have different frame rates ({sorted({r[1] for r in runs})}); '
                                'expected runs of one frame rate to pool')
    setups = []
    for tracks, _fps, period, area, _kind, _notes in runs:
        corridor, wrap = simulated_corridor(tracks, period, area, periodic_area)
        per = None if period is None else (period[0], period[1] - period[0])
        setups.append((tracks, corridor, per, wrap))

    def measure(sm, det, kw, mode=periodic_area):
        out = []
        for (tracks, corridor, per, wrap), run in zip(setups, runs):
            if mode != periodic_area:
                corridor, wrap = simulated_corridor(tracks, run[2], run[3], mode)
            out.append(analyse(tracks, fps, corridor, sm, det, True, period=per, wrap_leaders=wrap, **kw))
        return merge(out)

    res = measure(SMOOTH_S, 'mean', {})
    kinds = sorted({r[4] for r in runs})
    notes = sorted({n for r in runs for n in r[5]})
    periods = sorted({r[2] for r in runs}, key=str)
    x0, x1, y0, y1 = setups[0][1]
    rep.heading(label)
    dirs = ', '.join(f'{n} walking {"+x" if d > 0 else "-x"}' for d, n in sorted(res['directions'].items()))
    names = [os.path.basename(p) for p in paths]
    shown = ', '.join(f'`{n}`' for n in names) if len(names) <= 3 else f'`{names[0]}` … `{names[-1]}`'
    if periods != [None]:
        box = ', '.join(f'x ∈ [{a:g}, {b:g}) m' for a, b in periods)
        where = (f'periodic box {box}; measurement area '
                 + ('the whole box, leaders also across the seam (minimum image)' if periodic_area == 'whole'
                    else f'the box minus {END_CUT_M} m at each end, as the data\'s area'))
    else:
        where = f'not periodic; measurement area the corridor minus {END_CUT_M} m at each end'
    rep.para(f'{len(paths)} run(s) pooled ({", ".join(kinds)}): {shown}; {res["people"]} people in all ({dirs}), '
             f'{fps:g} fps' + (' (' + '; '.join(notes) + ')' if notes else '')
             + (f'; frames from {from_s:g} s on' if from_s > 0 else '') + f'. {where}: '
             f'x ∈ [{x0:.2f}, {x1:.2f}] m, y ∈ [{y0:.2f}, {y1:.2f}] m ({res["area_m2"]:.1f} m²); smoothing '
             f'{res["window_frames"]} frames ({res["window_frames"] / fps:.2f} s).')
    extra = []
    if periods != [None]:
        other = 'cut' if periodic_area == 'whole' else 'whole'
        extra.append(('whole box, leaders across the seam' if other == 'whole'
                      else f'box minus {END_CUT_M} m at each end', measure(SMOOTH_S, 'mean', {}, other)))
    return report_result(rep, res, fps, n_boot, lambda sm, det, kw: measure(sm, det, kw), label, extra)


def sweep_variants(folder):
    """variant -> run files of a crowdrecon sweep folder (kept runs), in run order; complete runs only."""
    db = os.path.join(folder, 'results.sqlite')
    guard.check_sweep_dir(folder)
    con = sqlite3.connect(f'file:{os.path.abspath(db)}?mode=ro', uri=True)
    groups = collections.OrderedDict()
    for run_id, variant, status in con.execute('SELECT run_id, variant, status FROM runs ORDER BY run_index'):
        path = os.path.join(folder, 'runs', run_id + '.sqlite')
        if status != 'complete':
            continue
        if not os.path.exists(path):
            raise guard.ScriptError(f'{path}: missing; expected the sweep\'s kept runs (run the sweep with '
                                    '"keep_runs": true)')
        groups.setdefault(variant, []).append(path)
    con.close()
    return groups


def summary_table(summaries):
    rows = []
    for sm in summaries:
        res = sm['res']
        if not res['segments']:
            rows.append([sm['label'], 'no pairs', '', '', '', '0 / 0', '', '', ''])
            continue
        pd_, sp, hw = sm['pair_dens'], sm['speeds'], sm['hw']
        few = ' (too few)' if res['followers'] < FEW_FOLLOWERS else ''
        rows.append([sm['label'],
                     '{:.2f} ({:.2f} – {:.2f})'.format(res['lag_best'], *sm['iv_lag'][95]),
                     '{:.2f} ({:.2f} – {:.2f})'.format(res['T_best'], *sm['iv_T'][95]),
                     f'{max(res["R"]):.3f}', sm['excess'],
                     f'{len(res["segments"])} / {res["followers"]}{few}',
                     f'{quantile(pd_, 0.5):.2f} [{quantile(pd_, 0.1):.2f}, {quantile(pd_, 0.9):.2f}]',
                     '{1:.2f} [{0:.2f}, {2:.2f}]'.format(*q3(sp)), f'{quantile(hw, 0.5):.2f}'])
    return (['source', 'L* (s) (95 %)', 'T_r (s) (95 %)', 'r(L*)', 'r(L*) − r(−L*)', 'segments / followers',
             'density at pairs, median [10 %, 90 %] (/m²)', 'follower speed, median [quartiles] (m/s)',
             'headway median (m)'], rows)


REPORT_HEAD = '# Reaction time'


def main():
    ap = guard.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('files', nargs='*', type=guard.existing_file,
                    help='PeTrack .txt files and simulated runs (.sqlite: crowdrecon run '
                    'files, their exports, JuPedSim trajectory files); default: the two Jülich corridors')
    ap.add_argument('-o', '--output', help='write the report as markdown to this file')
    ap.add_argument('--bootstrap', type=guard.positive_int, default=2000, help='bootstrap resamples (default 2000)')
    ap.add_argument('--unit', choices=('m', 'cm', 'mm'), help='override the unit read from the header')
    ap.add_argument('--sweep', type=guard.sweep_dir, help='a crowdrecon sweep folder with kept runs: one section '
                    'per variant, its seeds pooled')
    ap.add_argument('--variants', type=guard.nonempty_list, help='with --sweep: only these variants (comma-separated)')
    ap.add_argument('--pool', action='store_true', help='the .sqlite files given as one section (seeds pooled)')
    ap.add_argument('--from-s', type=guard.nonnegative_float, default=0.0,
                    help='simulated runs: drop the frames before this time (s), the start from rest')
    ap.add_argument('--periodic-area', choices=('cut', 'whole'), default='cut',
                    help='periodic runs: measurement area the box minus END_CUT_M at each end, leaders within '
                         'it, as in the data (cut, default), or the whole box, leaders across the seam (whole)')
    guard.add_force(ap)
    args = ap.parse_args()
    if args.variants and not args.sweep:
        raise guard.ScriptError('--variants: given without --sweep; expected --sweep DIR --variants A,B')
    guard.refuse_repeated(args.files, 'file')
    petrack = [f for f in args.files if not f.endswith(('.sqlite', '.db'))]
    sims = [f for f in args.files if f.endswith(('.sqlite', '.db'))]
    if not args.files and not args.sweep:
        petrack = DEFAULT_FILES
        for f in petrack:
            if not os.path.isfile(f):
                raise guard.ScriptError(f'{os.path.normpath(f)}: no such file: the data folder ../shared/data beside '
                                        f'the repository ({os.path.normpath(DATA)}) is missing or incomplete; expected '
                                        'the Jülich corridor trajectories there (../shared/data/README.md), or files '
                                        'given as arguments')
    for f in sims:
        guard.require_tables(f, ['trajectory_data'], 'a JuPedSim trajectory file (a crowdrecon run file, its export, '
                             'or another JuPedSim SQLite file)')
    inputs = [('a trajectory file', f) for f in petrack + sims]
    inputs += [('a corridor beside a trajectory file', os.path.join(os.path.dirname(f), 'walkable_area.wkt'))
               for f in petrack]
    variants = {}
    if args.sweep:
        inputs += guard.sweep_inputs(args.sweep)
        variants = sweep_variants(args.sweep)
        for v in args.variants or []:
            if v not in variants:
                raise guard.ScriptError(f'--variants: {args.sweep} has no complete runs of variant {v!r}; expected '
                                        f'one of {", ".join(variants)}')
        inputs += [('a run of the sweep', f) for paths in variants.values() for f in paths]
    guard.check_outputs([guard.Output('-o', args.output, 'a report of reaction-time-from-data.py',
                                      guard.starts_with(REPORT_HEAD))], inputs, args.force)
    groups = []
    if sims:
        groups += [(os.path.basename(sims[0]) + f' … ({len(sims)} runs)' if len(sims) > 1 else
                    os.path.basename(sims[0]), sims)] if args.pool else [(os.path.basename(f), [f]) for f in sims]
    if args.sweep:
        wanted = args.variants if args.variants else list(variants)
        for v in wanted:
            groups.append((f'model: {v} ({len(variants[v])} runs)', variants[v]))
    root = os.path.join(HERE, '..')
    rep = Report()
    rep.heading('Reaction time from the Jülich corridor trajectories' if not groups else
                'Reaction time: Jülich corridor trajectories and simulated runs', 1)
    rep.para('Made by `studies/reaction-time/reaction-time-from-data.py` (method, biases: its header). Follower: a person; '
             f'leader: the nearest person ahead walking the same way, |dy| < {BAND_M} m, ahead < {AHEAD_M} m, '
             f'both in the measurement area ({END_CUT_M} m off each end of the corridor), for ≥ {MIN_PAIR_S:g} s. '
             f'r(L): correlation of the follower\'s speed with the leader\'s L earlier (each minus its segment '
             f'mean), averaged over segments weighted by length. T_r: time constant of the exponential filter '
             f'of the leader\'s speed that correlates best with the follower\'s. Intervals: bootstrap over '
             f'followers, {args.bootstrap} resamples.')
    rep.para('Regenerate: `python3 studies/reaction-time/reaction-time-from-data.py '
             + ' '.join(os.path.relpath(f, root) for f in (petrack + sims if args.files else petrack))
             + (' --pool' if args.pool else '')
             + (f' --sweep {os.path.relpath(args.sweep, root)}' if args.sweep else '')
             + (f' --variants {",".join(args.variants)}' if args.variants else '')
             + (f' --from-s {args.from_s:g}' if args.from_s else '')
             + (f' --periodic-area {args.periodic_area}' if args.periodic_area != 'cut' else '')
             + (f' -o {os.path.relpath(args.output, root)}' if args.output else '')
             + (f' --bootstrap {args.bootstrap}' if args.bootstrap != 2000 else '') + '` (one process, seeded).')
    summary_at = len(rep.blocks)
    summaries = []
    for path in petrack:
        summaries.append(report_file(rep, path, args.bootstrap, args.unit))
    for label, paths in groups:
        summaries.append(report_runs(rep, label, paths, args.bootstrap, args.from_s, args.periodic_area))
    if groups:
        head, rows = summary_table([sm for sm in summaries if sm])
        rep.blocks[summary_at:summary_at] = [
            ('h', 2, 'Summary'),
            ('p', 'Each source as measured below (the same measurement on the data and on the simulated runs; '
                  'a variant\'s seeds pooled, its followers resampled together). Last columns at the pairs\' '
                  'frames; the follower\'s speed is a segment\'s mean.'),
            ('t', head, rows)]
    sys.stdout.write(rep.text())
    if args.output:
        guard.write_whole(args.output, rep.markdown())


if __name__ == '__main__':
    guard.run_main(main)
