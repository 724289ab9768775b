#!/usr/bin/env python3
"""The open hallway's local stops, per run and measurement area: the peak
density and the longest stretch of frames in which the area held at least
3.6 persons/m2 and its walkers' mean speed along their direction was below
0.1 m/s (the local reading's clog: docs/analysis.md, "Local avalanches").
A check beside `crowdrecon timeline --area-avalanches`, read from the run
files' tables directly (standard library; the group's direction taken as
+x for group 0 and -x for group 1, which the open hallway's targets are to
within 1e-3).

    area-stops.py RUN.sqlite...

Each argument must be a run file with the tables read (person, frame_time,
trajectory_data, person_state); anything else is one line, exit status 2
(scripts/script_guard.py).
"""
import collections
import os
import sqlite3
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))  # studies/NAME/results/
sys.path.insert(0, os.path.join(ROOT, 'scripts'))
import script_guard as guard  # noqa: E402

AREAS = {'court_end': (1.5, 4.5), 'centre': (5.0, 7.0), 'exit_end': (7.5, 10.5)}  # x ranges, y 0..3
CONTACT, STOP = 3.6, 0.1


def arguments():
    p = guard.ArgumentParser(description=__doc__.strip().splitlines()[0])
    p.add_argument('runs', nargs='+', metavar='RUN.sqlite', help='run files of the open hallway')
    args = p.parse_args()
    for f in args.runs:
        guard.check_run_file(f, ('person', 'frame_time', 'trajectory_data', 'person_state'))
    return args.runs


def main():
    for f in arguments():
        report(f)


def report(f):
    db = sqlite3.connect(f'file:{f}?mode=ro', uri=True)
    group = dict(db.execute('SELECT id, grp FROM person'))
    times = dict(db.execute('SELECT frame, time_s FROM frame_time'))
    acc = collections.defaultdict(lambda: collections.defaultdict(lambda: [0, 0.0, 0]))  # inside, sum along, walking
    for frame, i, x, vx, state in db.execute(
            'SELECT t.frame, t.id, t.pos_x, s.vel_x, s.state FROM trajectory_data t '
            'JOIN person_state s ON s.frame = t.frame AND s.id = t.id'):
        for a, (x0, x1) in AREAS.items():
            if x0 <= x <= x1:
                c = acc[a][frame]
                c[0] += 1
                if state == 0:
                    c[1] += vx * (1 if group[i] == 0 else -1)
                    c[2] += 1
    parts = []
    for a, (x0, x1) in AREAS.items():
        area = (x1 - x0) * 3.0
        longest, longest_from, start = 0.0, None, None
        for frame in sorted(times):
            inside, along, walking = acc[a].get(frame, [0, 0.0, 0])
            t = times[frame]
            if walking and along / walking < STOP and inside / area >= CONTACT:
                start = t if start is None else start
                if t - start > longest:
                    longest, longest_from = t - start, start
            else:
                start = None
        peak = max((c[0] / area for c in acc[a].values()), default=0.0)
        parts.append(f'{a}: peak {peak:.1f} /m2, longest dense stop {longest:.1f} s'
                     + (f' from {longest_from:.0f} s' if longest_from is not None else ''))
    print(f, '|', '; '.join(parts))


if __name__ == '__main__':
    guard.run_main(main)
