#!/usr/bin/env python3
"""Writes the large geometry inputs of tests/cli/bad_input_geometry.cmake, so
that no large file is committed.

  make_geometry_input.py png WIDTH HEIGHT OUT          dark picture with a light
                                                        1-pixel frame (a body
                                                        region filling it)
  make_geometry_input.py png-header WIDTH HEIGHT OUT   a PNG whose header gives
                                                        WIDTH x HEIGHT (no pixels)
  make_geometry_input.py pgm-header WIDTH HEIGHT OUT   the same as a netpbm (PGM) file
  make_geometry_input.py square SIDE [POINTS] OUT      point-list square of SIDE
                                                        units (JSON), POINTS per edge
  make_geometry_input.py bowtie SIDE POINTS OUT        the same with two corners swapped
  make_geometry_input.py circles COUNT OUT              DXF: COUNT circles of radius 1e5 m
                                                        (7000 points each at 1 cm)
  make_geometry_input.py minsert COLUMNS ROWS OUT      DXF: a room and a MINSERT
                                                        of COLUMNS x ROWS pillars
"""
import json
import struct
import sys
import zlib


def chunk(kind, data):
    body = kind + data
    return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)


def png(width, height, rows):
    header = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)  # 8-bit grey
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", rows) + chunk(b"IEND", b""))


def dark_png(width, height):
    # Row filter byte 0, then pixels: light first and last rows and columns.
    light = b"\x00" + b"\xff" * width
    dark = b"\x00\xff" + b"\x00" * (width - 2) + b"\xff"
    compressor = zlib.compressobj(9)
    parts = [compressor.compress(light)]
    block = dark * 64
    full, rest = divmod(height - 2, 64)
    for _ in range(full):
        parts.append(compressor.compress(block))
    parts.append(compressor.compress(dark * rest))
    parts.append(compressor.compress(light))
    parts.append(compressor.flush())
    return png(width, height, b"".join(parts))


def square(side, per_edge, bowtie=False):
    corners = [(0, 0), (side, side), (side, 0), (0, side)] if bowtie else [(0, 0), (side, 0), (side, side), (0, side)]
    points = []
    for k in range(4):
        (x0, y0), (x1, y1) = corners[k], corners[(k + 1) % 4]
        for i in range(per_edge):
            t = i / per_edge
            points.append([x0 + (x1 - x0) * t, y0 + (y1 - y0) * t])
    return json.dumps({"points": points})


def minsert(columns, rows):
    def pairs(*items):
        return "".join(f"{code}\n{value}\n" for code, value in items)

    room = pairs((0, "LWPOLYLINE"), (8, "0"), (90, 4), (70, 1),
                 (10, 0), (20, 0), (10, 100), (20, 0), (10, 100), (20, 100), (10, 0), (20, 100))
    pillar = pairs((0, "LWPOLYLINE"), (8, "0"), (90, 4), (70, 1),
                   (10, 0), (20, 0), (10, 0.1), (20, 0), (10, 0.1), (20, 0.1), (10, 0), (20, 0.1))
    return (pairs((0, "SECTION"), (2, "BLOCKS"), (0, "BLOCK"), (8, "0"), (2, "PILLAR"), (70, 0),
                  (10, 0), (20, 0), (3, "PILLAR")) + pillar + pairs((0, "ENDBLK"), (8, "0"), (0, "ENDSEC"))
            + pairs((0, "SECTION"), (2, "ENTITIES")) + room
            + pairs((0, "INSERT"), (8, "0"), (2, "PILLAR"), (10, 1), (20, 1), (70, columns), (71, rows),
                    (44, 0.5), (45, 0.5))
            + pairs((0, "ENDSEC"), (0, "EOF")))


def circles(count):
    def pairs(*items):
        return "".join(f"{code}\n{value}\n" for code, value in items)

    body = "".join(pairs((0, "CIRCLE"), (8, "0"), (10, 3e5 * k), (20, 0), (40, 1e5)) for k in range(count))
    return pairs((0, "SECTION"), (2, "ENTITIES")) + body + pairs((0, "ENDSEC"), (0, "EOF"))


def main():
    kind = sys.argv[1]
    args = sys.argv[2:]
    if kind == "png":
        data, out = dark_png(int(args[0]), int(args[1])), args[2]
    elif kind == "png-header":
        data, out = png(int(args[0]), int(args[1]), zlib.compress(b"")), args[2]
    elif kind == "pgm-header":
        data, out = f"P5\n{args[0]} {args[1]}\n255\n".encode() + b"\0" * 16, args[2]
    elif kind == "square":
        data, out = square(float(args[0]), int(args[1]) if len(args) > 2 else 1).encode(), args[-1]
    elif kind == "bowtie":
        data, out = square(float(args[0]), int(args[1]), bowtie=True).encode(), args[2]
    elif kind == "circles":
        data, out = circles(int(args[0])).encode(), args[1]
    elif kind == "minsert":
        data, out = minsert(int(args[0]), int(args[1])).encode(), args[2]
    else:
        sys.exit(f"unknown kind {kind}")
    with open(out, "wb") as f:
        f.write(data)


if __name__ == "__main__":
    main()
