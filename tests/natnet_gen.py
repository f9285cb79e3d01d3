#!/usr/bin/env python3
"""natnet_gen.py OUTDIR - NatNet packets for tests/test_io_natnet.c.

Written from the published NatNet protocol (NatNet SDK: the packet layout
its documentation and client samples decode), independently of egofuse's
parser (src/io/io_natnet.c): every packet is built here byte by byte with
struct.pack, little-endian, for NatNet 3.1 and 4.1:

  header        u16 message id, u16 payload bytes
  NAT_SERVERINFO (1)  char[256] app name, u8[4] app version, u8[4] NatNet
                version, u64 high-resolution clock frequency, u16 data port,
                u8 multicast, u8[4] multicast group (279 bytes)
  NAT_MODELDEF (5)    i32 dataset count; per dataset i32 type (0 marker set,
                1 rigid body, 2 skeleton, 3 force plate, 4 device, 5 camera,
                6 asset), [4.1+: i32 byte count], the description
  NAT_FRAMEOFDATA (7) i32 frame number; marker sets; legacy unlabeled
                markers; rigid bodies; skeletons; [4.1+: assets]; labeled
                markers; force plates; devices; suffix (u32 timecode, u32
                subframe, f64 timestamp, u64 mid-exposure, u64 data
                received, u64 transmit, [4.1+: u32 precision s, u32
                fraction], i16 params, i32 end-of-data 0). In 4.1+ every
                section count is followed by an i32 byte count of the
                section's contents.

The scenario (also written to OUTDIR/expected.txt, one line per body of
each frame file: "FILE id x y z qx qy qz qw valid", Motive's Y-up metres):
rigid bodies 11 Head, 12 ShoulderL, 13 ShoulderR, 14 HandL, 15 HandR,
20 Joystick; frames 101..106 at t = 10 + k/120 s, the mid-exposure stamp
5 ms before the transmit stamp (clock 1 MHz)."""
import math
import os
import struct
import sys

BODIES = [(11, "Head"), (12, "ShoulderL"), (13, "ShoulderR"), (14, "HandL"), (15, "HandR"),
          (20, "Joystick")]
CLOCK = 1000000


def i32(v): return struct.pack("<i", v)
def u32(v): return struct.pack("<I", v)
def i16(v): return struct.pack("<h", v)
def f32(*v): return struct.pack("<%df" % len(v), *v)
def cstr(s): return s.encode() + b"\0"


def packet(msg, payload):
    return struct.pack("<HH", msg, len(payload)) + payload


def v41(ver): return ver >= (4, 1)


def section(ver, count, body):
    """count, [4.1+ byte count], contents"""
    return i32(count) + (i32(len(body)) if v41(ver) else b"") + body


def pose(i, k):
    """Body i (index in BODIES) at frame k: Motive Y-up metres."""
    p = (0.1 * i - 0.25 + 0.001 * k, 1.0 + 0.05 * i, -0.3 - 0.002 * k)
    ang = 0.2 * i + 0.01 * k
    ax = (1.0, 2.0, 2.0 + i)
    n = math.sqrt(sum(a * a for a in ax))
    s = math.sin(ang / 2)
    q = (ax[0] / n * s, ax[1] / n * s, ax[2] / n * s, math.cos(ang / 2))
    return p, q


def server_info(ver, app=(3, 1, 0, 0), data_port=1511, multicast=False):
    name = b"Motive".ljust(256, b"\0")
    pl = name + bytes(app) + bytes([ver[0], ver[1], 0, 0])
    pl += struct.pack("<QHB", CLOCK, data_port, 1 if multicast else 0) + bytes([239, 255, 42, 99])
    assert len(pl) == 279
    return packet(1, pl)


def rb_desc(ver, name, rid, parent=-1, markers=2):
    d = cstr(name) + i32(rid) + i32(parent) + f32(0.0, 0.0, 0.0)
    if ver >= (4, 2):
        d += f32(0, 0, 0, 1)
    d += i32(markers)
    d += b"".join(f32(0.01 * m, 0.02, 0.03) for m in range(markers))
    d += b"".join(i32(m + 1) for m in range(markers))
    if ver[0] >= 4:
        d += b"".join(cstr("%s_M%d" % (name, m)) for m in range(markers))
    return d


def model_def(ver, bodies=BODIES, extra_unknown=False):
    sets = []
    sets.append((0, cstr("all") + i32(3) + cstr("m1") + cstr("m2") + cstr("m3")))
    for rid, name in bodies:
        sets.append((1, rb_desc(ver, name, rid)))
    sets.append((2, cstr("Skel") + i32(1) + i32(2) + rb_desc(ver, "Skel_Hip", 1, -1, 0)
                 + rb_desc(ver, "Skel_Ab", 2, 1, 0)))
    fp = i32(1) + cstr("FP-0001") + f32(0.5, 0.6) + f32(0, 0, 0) + f32(*([0.0] * 144))
    fp += f32(*([0.0] * 12)) + i32(1) + i32(0) + i32(2) + cstr("Fx") + cstr("Fy")
    sets.append((3, fp))
    sets.append((4, i32(2) + cstr("NIDAQ") + cstr("SN-7") + i32(1) + i32(0) + i32(1) + cstr("ai0")))
    sets.append((5, cstr("Cam 1") + f32(1, 2, 3) + f32(0, 0, 0, 1)))
    if v41(ver):
        asset = cstr("Prop") + i32(1) + i32(30) + i32(1) + rb_desc(ver, "Prop_RB", 31, -1, 1)
        asset += i32(1) + cstr("Prop_M") + i32(5) + f32(0, 0, 0) + f32(0.01) + i16(0)
        sets.append((6, asset))
        if extra_unknown:
            sets.append((42, b"future description"))
    pl = i32(len(sets))
    for t, d in sets:
        pl += i32(t) + (i32(len(d)) if v41(ver) else b"") + d
    return packet(5, pl)


def rigid_body(rid, p, q, valid=True):
    return i32(rid) + f32(*p) + f32(*q) + f32(0.0004) + i16(1 if valid else 0)


def frame(ver, k, bodies, ts, params=0, rb_count=None):
    """bodies: list of (id, p, q, valid) as streamed."""
    pl = i32(100 + k)
    ms = cstr("all") + i32(3) + f32(*([0.5] * 9))
    pl += section(ver, 1, ms)
    pl += section(ver, 2, f32(*([0.25] * 6)))
    rbs = b"".join(rigid_body(*b) for b in bodies)
    pl += section(ver, len(bodies) if rb_count is None else rb_count, rbs)
    skel = i32(1) + i32(2) + rigid_body(1, (0, 1, 0), (0, 0, 0, 1)) + rigid_body(2, (0, 1.2, 0), (0, 0, 0, 1))
    pl += section(ver, 1, skel)
    if v41(ver):
        asset = i32(30) + i32(1) + rigid_body(31, (1, 1, 1), (0, 0, 0, 1))
        asset += i32(2) + (i32(5) + f32(1, 1, 1) + f32(0.01) + i16(0) + f32(0.0001)) * 2
        pl += section(ver, 1, asset)
    lm = b"".join(i32(m) + f32(0.1 * m, 0.2, 0.3) + f32(0.014) + i16(4) + f32(0.0002)
                  for m in range(3))
    pl += section(ver, 3, lm)
    fp = i32(1) + i32(2) + (i32(3) + f32(1.0, 2.0, 3.0)) * 2
    pl += section(ver, 1, fp)
    dev = i32(2) + i32(1) + i32(2) + f32(0.5, 0.25)
    pl += section(ver, 1, dev)
    mid = 1000000 * (k + 200)
    pl += u32(0x01020304) + u32(0) + struct.pack("<d", ts)
    pl += struct.pack("<QQQ", mid, mid + 2000, mid + 5000)
    if v41(ver):
        pl += u32(1700000000 + k) + u32(123456)
    pl += i16(params) + i32(0)
    return packet(7, pl)


def main():
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    exp = []

    def put(name, data):
        with open(os.path.join(out, name), "wb") as f:
            f.write(data)

    def bodies_at(k, fname, skip=(), invalid=(), zup_mm=False):
        res = []
        for i, (rid, _) in enumerate(BODIES):
            if rid in skip:
                continue
            p, q = pose(i, k)
            valid = rid not in invalid
            exp.append("%s %d %.9g %.9g %.9g %.9g %.9g %.9g %.9g %d" % ((fname, rid) + p + q + (int(valid),)))
            if zup_mm:
                # the same pose in Motive's Z-up frame (+90 deg about X:
                # (x, y, z) -> (x, -z, y)), millimetres
                p = (1000 * p[0], -1000 * p[2], 1000 * p[1])
                q = (q[0], -q[2], q[1], q[3])
            res.append((rid, p, q, valid))
        return res

    for ver in ((3, 1), (4, 1)):
        v = "%d.%d" % ver
        put("serverinfo_%s.bin" % v, server_info(ver))
        put("modeldef_%s.bin" % v, model_def(ver, extra_unknown=True))
        for k in range(1, 7):
            fn = "frame_%s_%d.bin" % (v, k)
            put(fn, frame(ver, k, bodies_at(k, fn), 10.0 + k / 120.0))
        fn = "frame_%s_drop.bin" % v   # frame 107: HandL not tracked, HandR missing
        put(fn, frame(ver, 7, bodies_at(7, fn, skip=(15,), invalid=(14,)), 10.0 + 7 / 120.0))
        fn = "frame_%s_old.bin" % v    # frame 103 again, later: out of order
        put(fn, frame(ver, 3, bodies_at(3, fn), 10.0 + 3 / 120.0))
        fn = "frame_%s_tsback.bin" % v  # frame 108 but its time stamp goes back
        put(fn, frame(ver, 8, bodies_at(8, fn), 10.0 + 2 / 120.0))
        fn = "frame_%s_zupmm.bin" % v
        put(fn, frame(ver, 1, bodies_at(1, fn, zup_mm=True), 10.0 + 1 / 120.0))
        fn = "frame_%s_restart.bin" % v  # Motive restarted: frame 1 at t = 0.5
        put(fn, frame(ver, -99, bodies_at(9, fn), 0.5))
        # bad packets
        good = frame(ver, 9, bodies_at(9, "unused"), 11.0)
        put("short_hdr_%s.bin" % v, good[:40])                       # header says more
        put("short_body_%s.bin" % v, struct.pack("<HH", 7, 36) + good[4:40])  # cut inside
        put("overflow_%s.bin" % v, frame(ver, 9, bodies_at(9, "unused"), 11.0, rb_count=100000))
    put("tiny.bin", b"\x07\x00")
    put("unknown_id.bin", packet(77, b"\0" * 8))
    put("serverinfo_7.0.bin", server_info((7, 0)))
    put("message.bin", packet(8, cstr("hello from Motive")))
    # a model without the hands: names the config asks for are missing
    put("modeldef_nohands_4.1.bin", model_def((4, 1), bodies=BODIES[:3] + BODIES[5:]))
    with open(os.path.join(out, "expected.txt"), "w") as f:
        f.write("\n".join(exp) + "\n")


if __name__ == "__main__":
    main()
