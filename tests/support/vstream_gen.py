#!/usr/bin/env python3
"""vstream_gen.py SCENARIO - writes egofuse-framed V frames to stdout,
built from the byte table of docs/vstream.md (not from egofuse's code), for
tests/test_io_vsrc.c. Pixel values (frame i, pixel x, y of the whole frame):
  r = (4x + i) & 255, g = (8y) & 255, b = (x + y + 50i) & 255
  float depth = (i + 1) + x / 100 + y / 1000 metres
  uint16 depth = 1000 (i + 1) + 10 x + y, scale 0.001
Scenarios: basic, u16, yuyv, badsize, garbage, badfmt, truncated, version."""
import struct
import sys


def header(w, h, fourcc, layout, dfmt, colour_bytes, depth_bytes, t_ns=0, seq=0,
           flags=0, scale=0.0, version=1, magic=b"EGFV"):
    hdr = magic + struct.pack("<HHII", version, 64, w, h) + fourcc
    hdr += struct.pack("<BBHQQIIf", layout, dfmt, flags, t_ns, seq, colour_bytes,
                       depth_bytes, scale)
    hdr += bytes(12)
    assert len(hdr) == 64
    return hdr


def rgb(i, x, y):
    return ((4 * x + i) & 255, (8 * y) & 255, (x + y + 50 * i) & 255)


def frame_rgb(i, w, h, layout=2, depth=None, t_ns=0):
    px = bytearray()
    for y in range(h):
        for x in range(w):
            px += bytes(rgb(i, x, y))
    dfmt, dbytes, scale = 0, b"", 0.0
    if depth == "f32":
        dfmt = 1
        dbytes = b"".join(struct.pack("<f", (i + 1) + x / 100 + y / 1000)
                          for y in range(h) for x in range(w))
    elif depth == "u16":
        dfmt, scale = 2, 0.001
        dbytes = b"".join(struct.pack("<H", 1000 * (i + 1) + 10 * x + y)
                          for y in range(h) for x in range(w))
    return header(w, h, b"RGB3", layout, dfmt, len(px), len(dbytes), t_ns=t_ns, seq=i,
                  scale=scale) + bytes(px) + dbytes


def frame_yuyv(w, h):
    # y = 16 + x, u = 128, v = 128 (grey ramp); 2 bytes per pixel
    px = bytearray()
    for y in range(h):
        for x in range(0, w, 2):
            px += bytes((16 + x, 128, 16 + x + 1, 128))
    return header(w, h, b"YUYV", 1, 0, len(px), 0) + bytes(px)


def main():
    sc = sys.argv[1]
    out = sys.stdout.buffer
    if sc == "basic":      # 3 frames 64x32 sbs with float depth, t = 1 s + i ms
        for i in range(3):
            out.write(frame_rgb(i, 64, 32, 2, "f32", t_ns=1000000000 + i * 1000000))
    elif sc == "u16":      # 1 frame 32x64 top-bottom with uint16 depth
        out.write(frame_rgb(0, 32, 64, 3, "u16"))
    elif sc == "yuyv":     # 1 frame 32x16 mono YUYV
        out.write(frame_yuyv(32, 16))
    elif sc == "badsize":  # 64x32, then 32x32 (refused), then 64x32
        out.write(frame_rgb(0, 64, 32))
        out.write(frame_rgb(1, 32, 32))
        out.write(frame_rgb(2, 64, 32))
    elif sc == "garbage":  # frame, 100 bytes of junk, frame
        out.write(frame_rgb(0, 64, 32))
        out.write(bytes((7 * k + 3) & 255 for k in range(100)))
        out.write(frame_rgb(1, 64, 32))
    elif sc == "badfmt":   # a frame of unknown format ZZZZ, then a good one
        out.write(header(64, 32, b"ZZZZ", 2, 0, 64 * 32 * 3, 0) + bytes(64 * 32 * 3))
        out.write(frame_rgb(1, 64, 32))
    elif sc == "truncated":  # a good frame, then 30 bytes of a header
        out.write(frame_rgb(0, 64, 32))
        out.write(frame_rgb(1, 64, 32)[:30])
    elif sc == "version":  # a version 2 header
        out.write(header(64, 32, b"RGB3", 2, 0, 64 * 32 * 3, 0, version=2) + bytes(64 * 32 * 3))
    else:
        sys.exit("unknown scenario " + sc)


if __name__ == "__main__":
    main()
