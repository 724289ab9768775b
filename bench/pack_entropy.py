#!/usr/bin/env python3
"""What a person-frame of a run file with tables would cost packed (issue 66).

usage: bench/pack_entropy.py RUN.sqlite [RESOLUTIONS]

Reads a run written with tables (run.frames "tables") and predicts each
person's numbers as runfile/src/frame_pack.cpp does (the frame before; x, y
and the angle extrapolated from the two before); then compresses each
number's eight byte planes per frame with zlib -6 and prints the bytes a
person-frame costs in all and per number. Without RESOLUTIONS the residuals
are the XOR of the doubles' bits (lossless: what the packed storage keeps);
with RESOLUTIONS (nine comma-separated steps: x, y, angle, vx, vy, omega,
load, chest, lateral) the numbers are first rounded to those steps and the
residuals are integer differences (what rounding would give; not used).
Standard library only; slow (pure Python): for runs of up to about 10^5
person-frames.
"""
import sqlite3
import struct
import sys
import zlib
db=sqlite3.connect(sys.argv[1])
rows=db.execute("select t.frame,t.id,t.pos_x,t.pos_y,s.angle_rad,s.vel_x,s.vel_y,s.omega_rad_per_s,s.load_n, coalesce(l.chest_n,0), coalesce(l.lateral_n,0) from trajectory_data t join person_state s on s.frame=t.frame and s.id=t.id left join person_load l on l.frame=t.frame and l.id=t.id order by t.frame,t.id").fetchall()
names=['x','y','ang','vx','vy','om','load','chest','lat']
frames={}
for r in rows: frames.setdefault(r[0],[]).append(r)
def bits(v): return struct.unpack('<Q',struct.pack('<d',v))[0]
quant=[float(a) for a in sys.argv[2].split(',')] if len(sys.argv)>2 else None
prev={}; prev2={}; seq=0; tot=[0]*9; npf=0
for f in sorted(frames):
    fr=frames[f]; n=len(fr); npf+=n
    planes=[[bytearray(n) for b in range(8)] for c in range(9)]
    for k,r in enumerate(fr):
        pid=r[1]; v=list(r[2:11])
        if quant: v=[round(v[c]/quant[c]) for c in range(9)]
        p1=prev.get(pid); p2=prev2.get(pid)
        for c in range(9):
            if p1 is not None and p1[0]==seq-1:
                if c<3 and p2 is not None and p2[0]==seq-2: pred=p1[1][c]+(p1[1][c]-p2[1][c])
                else: pred=p1[1][c]
            else: pred=0
            if quant:
                d=v[c]-pred; z=(d<<1) if d>=0 else ((-d<<1)-1); res=z
            else: res=bits(v[c])^bits(pred)
            for b in range(8): planes[c][b][k]=(res>>(56-8*b))&255
        if p1 is not None: prev2[pid]=p1
        prev[pid]=(seq,v)
    seq+=1
    for c in range(9):
        tot[c]+=len(zlib.compress(b''.join(bytes(p) for p in planes[c]),6))
print('person-frames',npf, 'B/pf total %.1f'%(sum(tot)/npf))
for c in range(9): print(names[c],'%.2f'%(tot[c]/npf))
