"""Reading PeTrack trajectory text files (the Jülich data archive's format, as in
../shared/data/README.md): columns `id frame x y z`, '#' comment lines, the frame rate and
the unit in the header.  One reader for the scripts that compare the model with those files
(bottleneck-study.py, reaction-time-from-data.py, gait-jitter-from-data.py through the first).
Standard library only.  A file that is not of this form is refused with a ScriptError
(scripts/script_guard.py) naming the file and the line.
"""
import collections
import math
import os
import re

from script_guard import ScriptError


def read_petrack(path, unit=None):
    """id -> [(frame, x, y)] in metres, the frame rate (1/s) and notes on how the header was read."""
    header = []
    tracks = collections.defaultdict(list)
    expected = 'a PeTrack trajectory file (lines "id frame x y z", \'#\' comments; ../shared/data/README.md)'
    if os.path.isdir(path) or not os.path.exists(path):
        raise ScriptError(f'{path}: {"a folder" if os.path.isdir(path) else "no such file"}; expected {expected}')
    with open(path, errors='replace') as f:
        for number, line in enumerate(f, 1):
            if line.startswith('#') or not line.strip():
                if not tracks:
                    header.append(line)
                continue
            try:
                pid, frame, x, y = line.split()[:4]
                point = (int(frame), float(x), float(y))
                if not all(map(math.isfinite, point[1:])):
                    raise ValueError
                tracks[int(pid)].append(point)
            except ValueError:
                raise ScriptError(f'{path}: line {number}: {line.strip()[:60]!r} is not "id frame x y ..."; '
                                  f'expected {expected}') from None
    if not tracks:
        raise ScriptError(f'{path}: holds no trajectory lines; expected {expected}')
    notes = []
    text = ''.join(header)
    m = re.search(r'framerate:\s*([0-9.]+)', text)
    try:
        fps = float(m.group(1)) if m else 25.0
    except ValueError:
        fps = 0.0
    if not fps > 0:
        raise ScriptError(f'{path}: framerate {m.group(1)} in the header; expected a frame rate above 0')
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
