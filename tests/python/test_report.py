#!/usr/bin/env python3
"""Recomputes a report's per-person figures from the run file alone (Python's
sqlite3, no crowdrecon code) and compares them with the report's people.csv
(issue 21: the report's numbers checked against an independent recomputation).

  test_report.py RUN.sqlite people.csv [--f0 400] [--danger 1112] [--smoothing 1] [--close-up report.html]

The chest load follows docs/reports.md: along an axis u, the contacts on the
side u points to push with P+ = sum max(0, -F.u), the others with
P- = sum max(0, F.u); the load is min(P+, P-); the person's load is the larger
of the chest (u = facing) and shoulder (u = perpendicular) loads, then a moving
mean over round(smoothing * fps) frames. With --close-up, the report's force
network close-up must be centred on the person with the largest smoothed load
at the frame of its worst moment (its captions name both), recomputed here."""
import argparse, csv, json, math, re, sqlite3, sys
from collections import defaultdict, deque


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("run")
    ap.add_argument("people_csv")
    ap.add_argument("--f0", type=float, default=400.0)
    ap.add_argument("--danger", type=float, default=1112.0)
    ap.add_argument("--smoothing", type=float, default=1.0)
    ap.add_argument("--short", type=float, nargs=2, default=(6227.0, 15.0))
    ap.add_argument("--long", type=float, nargs=2, default=(1112.0, 300.0))
    ap.add_argument("--close-up", help="report.html whose close-up is checked")
    a = ap.parse_args()
    close_up = None  # (worst frame, the person the close-up is around)
    if a.close_up:
        html = open(a.close_up).read()
        worst = re.search(r"runs: frame ([0-9]+) \(t = ", html)
        around = re.search(r"the worst region, x .*? m, around person ([0-9]+)", html)
        if not worst or not around:
            print(f"{a.close_up}: no worst frame or no close-up caption")
            return 1
        close_up = (int(worst.group(1)), int(around.group(1)))
    worst_loads = {}

    db = sqlite3.connect(a.run)
    run = dict(db.execute("SELECT key, value FROM run"))
    fps = float(run["output_fps"])
    box = json.loads(run["periodic_box"]) if "periodic_box" in run else None

    def minimum_image(dx, dy):
        if box:
            if box.get("x"):
                lx = box["max_m"][0] - box["min_m"][0]
                dx -= lx * round(dx / lx)
            if box.get("y"):
                ly = box["max_m"][1] - box["min_m"][1]
                dy -= ly * round(dy / ly)
        return dx, dy

    times = dict(db.execute("SELECT frame, time_s FROM frame_time"))
    pose = defaultdict(dict)  # frame -> id -> (x, y, angle)
    for frame, pid, x, y, ang in db.execute(
            "SELECT t.frame, t.id, t.pos_x, t.pos_y, s.angle_rad FROM trajectory_data t "
            "JOIN person_state s ON s.frame = t.frame AND s.id = t.id"):
        pose[frame][pid] = (x, y, ang)
    contacts = defaultdict(list)  # frame -> [(id, branch, force)]
    for frame, ca, cb, wall, px, py, nx, ny, fn, ft in db.execute(
            "SELECT frame, a, b, wall, point_x, point_y, normal_x, normal_y, normal_force_n, tangential_force_n FROM contact"):
        fx, fy = nx * fn - ny * ft, ny * fn + nx * ft  # n Fn + Perp(n) Ft, on a
        xa = pose[frame][ca]
        contacts[frame].append((ca, minimum_image(px - xa[0], py - xa[1]), (fx, fy)))
        if not wall:
            xb = pose[frame][cb]
            contacts[frame].append((cb, minimum_image(px - xb[0], py - xb[1]), (-fx, -fy)))

    def compression(u, items):
        plus = minus = 0.0
        for (lx, ly), (fx, fy) in items:
            side = lx * u[0] + ly * u[1]
            push = fx * u[0] + fy * u[1]
            tol = 1e-9 * max(math.hypot(lx, ly), 1e-12)
            if side > tol:
                plus += max(0.0, -push)
            elif side < -tol:
                minus += max(0.0, push)
            else:
                plus += 0.5 * max(0.0, -push)
                minus += 0.5 * max(0.0, push)
        return min(plus, minus)

    # The chest loads the run loop recorded (table person_load) against the
    # same equations on the recorded contacts.
    recorded = {}
    if db.execute("SELECT COUNT(*) FROM sqlite_master WHERE name = 'person_load'").fetchone()[0]:
        for frame, pid, chest, lateral in db.execute("SELECT frame, id, chest_n, lateral_n FROM person_load"):
            recorded[(frame, pid)] = (chest, lateral)
    load_failures = 0
    if recorded:
        for frame in sorted(pose):
            per = defaultdict(list)
            for pid, l, f in contacts.get(frame, []):
                per[pid].append((l, f))
            for pid, (x, y, ang) in pose[frame].items():
                items = per.get(pid, [])
                want = (0.0, 0.0)
                if len(items) >= 2:
                    d = (math.cos(ang), math.sin(ang))
                    want = (compression(d, items), compression((-d[1], d[0]), items))
                got = recorded.get((frame, pid), (0.0, 0.0))
                if any(abs(g - w) > 1e-6 * max(1.0, w) for g, w in zip(got, want)):
                    if load_failures < 5:
                        print(f"frame {frame} person {pid}: person_load {got}, recomputed from the contacts {want}")
                    load_failures += 1
        print(f"table person_load: {len(recorded)} rows, {load_failures} differences from the contacts")

    k = math.log(a.long[1] / a.short[1]) / math.log(a.short[0] / a.long[0])
    window = max(1, int(round(a.smoothing * fps)))
    buf = defaultdict(deque)
    stat = {}
    prev_t = None
    for frame in sorted(pose):
        t = times[frame]
        dt = 0.0 if prev_t is None else t - prev_t
        prev_t = t
        per = defaultdict(list)
        for pid, l, f in contacts.get(frame, []):
            per[pid].append((l, f))
        for pid in list(buf):
            if pid not in pose[frame]:
                del buf[pid]
        for pid, (x, y, ang) in sorted(pose[frame].items()):
            items = per.get(pid, [])
            load = 0.0
            if len(items) >= 2:
                d = (math.cos(ang), math.sin(ang))
                load = max(compression(d, items), compression((-d[1], d[0]), items))
            q = buf[pid]
            q.append(load)
            if len(q) > window:
                q.popleft()
            s = max(0.0, sum(q) / len(q))
            if close_up and frame == close_up[0]:
                worst_loads[pid] = s
            st = stat.setdefault(pid, dict(max=0.0, above=0.0, dose=0.0, danger=0.0))
            st["max"] = max(st["max"], s)
            if s > a.f0:
                st["above"] += dt
                st["dose"] += dt / (a.short[1] * (s / a.short[0]) ** (-k))
            if s > a.danger:
                st["danger"] += dt

    def zone(v):
        return "danger" if v > a.danger else "uncomfortable" if v > a.f0 else "safe"

    rows = list(csv.DictReader(open(a.people_csv)))
    failures = 0
    if len(rows) != len(stat):
        print(f"people.csv has {len(rows)} people, the run {len(stat)}")
        failures += 1
    counts = defaultdict(int)
    for r in rows:
        pid = int(r["id"])
        st = stat.get(pid)
        if st is None:
            print(f"person {pid} of people.csv is not in the run")
            failures += 1
            continue
        counts[zone(st["max"])] += 1
        checks = [("max_load_n", st["max"], float(r["max_load_n"])),
                  ("time_above_f0_s", st["above"], float(r["time_above_f0_s"])),
                  ("time_above_danger_s", st["danger"], float(r["time_above_danger_s"])),
                  ("dose", st["dose"], float(r["dose"]))]
        for name, want, got in checks:
            if abs(want - got) > 1e-5 * max(1.0, abs(want)):
                print(f"person {pid}: {name} {got} in people.csv, recomputed {want}")
                failures += 1
        if zone(st["max"]) != r["zone"]:
            print(f"person {pid}: zone {r['zone']} in people.csv, recomputed {zone(st['max'])}")
            failures += 1
    print(f"{len(rows)} people checked; recomputed zones: " + ", ".join(f"{z} {counts[z]}" for z in ("safe", "uncomfortable", "danger")) +
          f"; largest load {max(s['max'] for s in stat.values()):.1f} N; {failures} differences")
    if close_up:
        most = max(worst_loads, key=lambda pid: (worst_loads[pid], -pid))
        print(f"close-up at frame {close_up[0]} around person {close_up[1]}; recomputed the most loaded then: "
              f"person {most} ({worst_loads[most]:.1f} N)")
        if most != close_up[1]:
            failures += 1
    return 1 if failures or load_failures else 0


if __name__ == "__main__":
    sys.exit(main())
