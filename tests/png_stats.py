#!/usr/bin/env python3
"""Numbers about 8-bit PNGs for the shell tests (no imaging library needed).

png_stats.py size A.png            -> "W H"
png_stats.py diff A.png B.png [X Y W H]
                                   -> "MEAN MAX": the mean and largest absolute
                                      difference of the RGB codes (same size),
                                      over the rectangle if given
png_stats.py mean A.png            -> "R G B": the mean codes
png_stats.py ink A.png X Y W H R G B
                                   -> the pixels of the rectangle that are not
                                      the colour R G B
"""
import struct
import sys
import zlib


def read(path):
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"{path}: not a PNG")
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, colour, _, _, interlace = header
    channels = {2: 3, 6: 4}.get(colour)
    if depth != 8 or not channels or interlace:
        sys.exit(f"{path}: only 8-bit RGB or RGBA, not interlaced")
    raw, stride = zlib.decompress(idat), width * channels
    rows, previous = [], bytearray(stride)
    for y in range(height):
        kind, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b = previous[i]
            c = previous[i - channels] if i >= channels else 0
            if kind == 1:
                line[i] = (line[i] + a) & 255
            elif kind == 2:
                line[i] = (line[i] + b) & 255
            elif kind == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        previous = line
    return width, height, channels, rows


def main():
    command, args = sys.argv[1], sys.argv[2:]
    if command == "size":
        w, h, _, _ = read(args[0])
        print(w, h)
    elif command == "diff":
        wa, ha, ca, ra = read(args[0])
        wb, hb, cb, rb = read(args[1])
        if (wa, ha) != (wb, hb):
            sys.exit(f"sizes differ: {wa}x{ha} and {wb}x{hb}")
        x0, y0, rw, rh = map(int, args[2:6]) if len(args) >= 6 else (0, 0, wa, ha)
        total, largest = 0, 0
        for y in range(y0, y0 + rh):
            for x in range(x0, x0 + rw):
                for k in range(3):
                    d = abs(ra[y][x * ca + k] - rb[y][x * cb + k])
                    total += d
                    largest = max(largest, d)
        print(f"{total / (rw * rh * 3):.4f} {largest}")
    elif command == "mean":
        w, h, c, rows = read(args[0])
        print(" ".join(f"{sum(r[x * c + k] for r in rows for x in range(w)) / (w * h):.2f}" for k in range(3)))
    elif command == "ink":
        w, h, c, rows = read(args[0])
        x0, y0, rw, rh, *colour = map(int, args[1:])
        print(sum(1 for y in range(y0, y0 + rh) for x in range(x0, x0 + rw)
                  if list(rows[y][x * c:x * c + 3]) != colour))
    else:
        sys.exit(__doc__)


main()
