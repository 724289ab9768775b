#!/usr/bin/env python3
"""How much people standing in a dense crowd move on their own: the strength
of the gait-jitter extension (docs/decisions.md, "Issue 39: gait jitter"),
measured from the Wuppertal 2018 bottleneck trajectories.

For every person and every 8-s window (half-overlapping) in which the person's
net speed is below 0.1 m/s (standing in the waiting crowd), the head's
position across and along the flow (-y) is detrended and its power spectrum
computed (0.125 Hz resolution).  The average spectrum S_y(f) of each axis is
turned into the spectrum of a desired-velocity perturbation u that would move
a free person so (eq. 3: m dv/dt = m/tau (u - v), so S_y = S_u / (w^2 (1 + w^2
tau^2)), w = 2 pi f), and sigma_u is the root of the integral of S_u over the
band where it is flat.  Standard library only.

Two biases, of opposite sign: PeTrack's tracking error adds white position
noise (it dominates above ~1.5 Hz, where S_u rises again), so sigma_u is too
high by its share; a person among neighbours moves less than a free one
under the same u, so sigma_u is too low by the crowd's resistance.  Both are
stated with the result, neither is corrected.

usage: studies/wuppertal-bottleneck/gait-jitter-from-data.py [TRAJECTORIES.txt]  (default: ../shared/data/juelich-bottleneck/040_c_56_h-.txt)
The default needs the data folder ../shared/data beside the repository (its
README says where the files come from); without it, or with a file that is not
a PeTrack trajectory file or has no standing windows, the script says so in
one line (exit status 2; scripts/script_guard.py).
"""
import importlib.util
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), 'scripts'))
import script_guard as guard  # noqa: E402  (scripts/)

TAU_S = 2.0 / 3.0          # relaxation time of eq. 3 (paper)
FPS = 25.0
WINDOW = 200               # frames: 8 s
STANDING_M_PER_S = 0.1     # net speed over the window
BAND_HZ = (0.5, 1.5)       # where S_u is flat (printed below: the evidence for it)


def load(path):
    """The PeTrack file's tracks (id -> [(frame, x, y)]), read as the bottleneck study reads it."""
    spec = importlib.util.spec_from_file_location('bottleneck_study', os.path.join(os.path.dirname(__file__),
                                                                                   'bottleneck-study.py'))
    study = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(study)
    return study.read_petrack(path)[0]


def detrended(values):
    n = len(values)
    mean = sum(values) / n
    mid = (n - 1) / 2
    slope = sum((k - mid) * (v - mean) for k, v in enumerate(values)) / sum((k - mid) ** 2 for k in range(n))
    return [v - mean - slope * (k - mid) for k, v in enumerate(values)]


def periodogram(values):
    """One-sided spectral density (m^2/Hz) at k/(WINDOW/FPS) Hz, k = 1..WINDOW/2-1."""
    n = len(values)
    df = FPS / n
    out = []
    for k in range(1, n // 2):
        re = sum(v * math.cos(2 * math.pi * k * j / n) for j, v in enumerate(values))
        im = sum(v * math.sin(2 * math.pi * k * j / n) for j, v in enumerate(values))
        out.append(2.0 * (re * re + im * im) / (n * n) / df)
    return out


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    default = os.path.join(here, '..', '..', '..', 'shared', 'data', 'juelich-bottleneck', '040_c_56_h-.txt')
    p = guard.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument('trajectories', nargs='?', type=guard.existing_file,
                   help='a PeTrack trajectory file (default: ../shared/data/juelich-bottleneck/040_c_56_h-.txt)')
    args = p.parse_args()
    path = args.trajectories or default
    if args.trajectories is None and not os.path.isfile(path):
        data = os.path.normpath(os.path.join(here, '..', '..', 'shared', 'data'))
        raise guard.ScriptError(f'{os.path.normpath(path)}: no such file: the data folder ../shared/data beside the '
                                f'repository ({data}) is missing or incomplete; expected the Jülich bottleneck '
                                'trajectories there (../shared/data/README.md), or a PeTrack file as the argument')
    people = load(path)
    sums = {'across': None, 'along': None}
    windows = 0
    for track in people.values():
        xs = [p[1] for p in track]
        ys = [p[2] for p in track]
        for start in range(0, len(track) - WINDOW, WINDOW // 2):
            x, y = xs[start:start + WINDOW], ys[start:start + WINDOW]
            if math.hypot(x[-1] - x[0], y[-1] - y[0]) / (WINDOW / FPS) >= STANDING_M_PER_S:
                continue
            windows += 1
            for axis, series in (('across', x), ('along', y)):  # the flow is along -y
                p = periodogram(detrended(series))
                sums[axis] = p if sums[axis] is None else [a + b for a, b in zip(sums[axis], p)]
    if windows == 0:
        raise guard.ScriptError(f'{path}: no window of {WINDOW / FPS:.0f} s in which a person stands (net speed < '
                                f'{STANDING_M_PER_S} m/s); expected trajectories of a waiting crowd, such as the '
                                'Wuppertal bottleneck\'s')
    df = FPS / WINDOW
    print(f'{path}: {len(people)} people, {windows} windows of {WINDOW / FPS:.0f} s standing (net speed < {STANDING_M_PER_S} m/s)')
    print('f (Hz)   S_y across, along (m^2/Hz)   S_u across, along ((m/s)^2/Hz)')
    result = {}
    for axis in ('across', 'along'):
        result[axis] = [s / windows for s in sums[axis]]
    for k in range(1, 20):
        f = k * df
        w = 2 * math.pi * f
        gain = w * w * (1 + (w * TAU_S) ** 2)
        sy = [result[a][k - 1] for a in ('across', 'along')]
        print(f'{f:6.3f}   {sy[0]:.3e} {sy[1]:.3e}        {sy[0] * gain:.3e} {sy[1] * gain:.3e}')
    for axis in ('across', 'along'):
        su2 = 0.0
        sy2 = 0.0
        for k in range(1, WINDOW // 2):
            f = k * df
            if BAND_HZ[0] <= f <= BAND_HZ[1]:
                w = 2 * math.pi * f
                su2 += result[axis][k - 1] * w * w * (1 + (w * TAU_S) ** 2) * df
                sy2 += result[axis][k - 1] * df
        print(f'{axis}: band {BAND_HZ[0]}-{BAND_HZ[1]} Hz: position rms {math.sqrt(sy2):.4f} m, '
              f'sigma_u = {math.sqrt(su2):.3f} m/s')


if __name__ == '__main__':
    guard.run_main(main)
