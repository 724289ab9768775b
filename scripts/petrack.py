"""Reading PeTrack trajectory text files (the Jülich data archive's format, as in
../shared/data/README.md): columns `id frame x y z`, '#' comment lines, the frame rate and
the unit in the header.  One reader for the scripts that compare the model with those files
(bottleneck-study.py, reaction-time-from-data.py, gait-jitter-from-data.py through the first).
Standard library only.
"""
import collections
import re


def read_petrack(path, unit=None):
    """id -> [(frame, x, y)] in metres, the frame rate (1/s) and notes on how the header was read."""
    header = []
    tracks = collections.defaultdict(list)
    with open(path) as f:
        for line in f:
            if line.startswith('#') or not line.strip():
                if not tracks:
                    header.append(line)
                continue
            pid, frame, x, y = line.split()[:4]
            tracks[int(pid)].append((int(frame), float(x), float(y)))
    notes = []
    text = ''.join(header)
    m = re.search(r'framerate:\s*([0-9.]+)', text)
    fps = float(m.group(1)) if m else 25.0
    if not m:
        notes.append('no frame rate in the header: 25 fps assumed')
    if unit is None:
        m = re.search(r'\bx/(mm|cm|m)\b', text)
        if m:
            unit = m.group(1)
        else:
            unit = 'm'
            notes.append('the header states no unit: metres assumed (../shared/data/README.md)')
    scale = {'m': 1.0, 'cm': 0.01, 'mm': 0.001}[unit]
    for pid, t in tracks.items():
        t.sort()
        tracks[pid] = [(fr, x * scale, y * scale) for fr, x, y in t]
    return tracks, fps, unit, notes
