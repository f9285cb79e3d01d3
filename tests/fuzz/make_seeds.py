#!/usr/bin/env python3
"""make_seeds.py [SHARED] - writes the seed corpora of the fuzz targets
into tests/fuzz/corpus/NAME/ (docs/fuzzing.md). The files are committed;
run this again after a format changes. Sources: the formats' examples in
docs/ (scene, tracking, calibration), samples/cockpit.conf, the NatNet and
V stream generators of the tests (tests/natnet_gen.py,
tests/support/vstream_gen.py, written from the published formats), a UDP
pose packet built here from docs/tracking.md's table, and the small glTF
models of SHARED/gltf (default ../shared). Each seed of the targets with
a control byte (io_vstream, io_natnet, kin_packet) starts with it (see
the target's header)."""
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import zlib

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OUT = os.path.join(ROOT, "tests", "fuzz", "corpus")
SHARED = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "..", "shared")


CALIB_STEREO = """%YAML:1.0
---
M1: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 500., 0., 320., 0., 501., 240., 0., 0., 1. ]
D1: !!opencv-matrix
   rows: 1
   cols: 8
   dt: d
   data: [ 0.1, 0.01, 0., 0., 0.001, 0.2, 0.02, 0.002 ]
M2: [ 510., 0., 330., 0., 511., 250., 0., 0., 1. ]
D2: [ 0.2, 0.02, 0., 0., 0.002 ]
"""


def put(name, file, data):
    d = os.path.join(OUT, name)
    os.makedirs(d, exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(d, file), "wb") as f:
        f.write(data)


SCENE = """egofuse-scene 1
# a recorded sequence, 2 seconds at 60 fps
model         = models/arms.glb
animation     = wave
head_node     = head
frames        = 120
fps           = 60
camera_left   = cam/left_%04d.png
camera_right  = cam/right_%04d.png
virtual_left  = virt/left_%d.png
virtual_right = virt/right_%d.png
virtual_depth_left  = virt/depth_left_%04d.exr
virtual_depth_right = virt/depth_right_%04d.exr
ambient   = 0.35 0.35 0.35
light     = 0 0.6 0.8   1 1 1
light     = -1 0 0      0.3 0.3 0.4
kd        = 0.75
ks        = 0.15
shininess = 16
kf        = 0.6
tone      = 1 1 1
tracking  = track.txt
"""
MIN_SCENE = """egofuse-scene 1
model = a.gltf
frames = 1
fps = 30
camera_left = l%d.png
camera_right = r%d.png
virtual_left = vl%d.png
virtual_right = vr%d.png
"""

HEAD = "H 0 1.25 -0.08 0 0 0 1"
FULL = ("t 0.000 " + HEAD + " SL -0.19 1 0 SR 0.19 1 0 HL -0.2 1 -0.4 0 0 0 1 "
        "HR 0.2 1 -0.4 0 0 0 1 GL .1 .2 .2 .3 .3 GR .1 .2 .2 .3 .3\n")
TRACK = ("egofuse-track 1\n# comments (also after data) and blank lines are ignored\n" + FULL +
         "t 0.011 HR 0.2 1 -0.4 0 0 0 1\n\nt 0.022 " + HEAD + " # after data\n")
TRACK_CRLF = "egofuse-track 1\r\nt 1 SL -0.19 1 0\r\nt 2 GR 0 0 0 0 1\r\n"

CALIB = """egofuse-calib 1
arm_scale 1.1 1.1           # left right
hand_scale 1.1 1.1
shoulder_scale 1.105
arm_length 0.616 0.616      # metres, measured (0 = unknown)
shoulder_width 0.42
hand_length 0.204 0.204
glove_left 0.1 0.1 0.1 0.1 0.1 0.9 0.9 0.9 0.9 0.9
"""
CALIB_MIN = """egofuse-calib 1
arm_scale 1 1
hand_scale 1 1
shoulder_scale 1
arm_length 0 0
shoulder_width 0.4
"""


def packet(valid, seq, t, floats):
    """docs/tracking.md: "EGTK", u16 version 1, u16 valid bits, u32 sequence,
    f64 t, 37 f32, u32 CRC-32 of bytes 0..167."""
    body = b"EGTK" + struct.pack("<HHId", 1, valid, seq, t) + struct.pack("<37f", *floats)
    assert len(body) == 168
    return body + struct.pack("<I", zlib.crc32(body) & 0xffffffff)


def pose_floats():
    head = [0, 1.25, -0.08, 0, 0, 0, 1]
    sh = [-0.19, 1, 0, 0.19, 1, 0]
    hl = [-0.2, 1, -0.4, 0, 0, 0, 1]
    hr = [0.2, 1, -0.4, 0, 0, 0, 1]
    gl = [0.1, 0.2, 0.2, 0.3, 0.3]
    return head + sh + hl + hr + gl + gl


def main():
    shutil.rmtree(OUT, ignore_errors=True)
    put("io_scene", "example.txt", SCENE)
    put("io_scene", "minimal.txt", MIN_SCENE)
    put("kin_track", "example.txt", TRACK)
    put("kin_track", "crlf.txt", TRACK_CRLF)
    put("kin_calib", "example.txt", CALIB)
    put("kin_calib", "minimal.txt", CALIB_MIN)
    with open(os.path.join(ROOT, "samples", "cockpit.conf"), "rb") as f:
        put("io_conf", "cockpit.conf", f.read())
    put("io_conf", "small.conf", "scene = a/scene.txt\n[prop]\nmodel = \"b c.glb\"\n")
    for f in ("hmd_left.yml", "hmd_right.xml", "fisheye_KD.yml"):
        with open(os.path.join(ROOT, "samples", "calib", f), "rb") as fh:
            put("io_calib", f, fh.read())
    put("io_calib", "stereo.yml", CALIB_STEREO)
    p = packet(0x7f, 7, 1.5, pose_floats())
    put("kin_packet", "full.bin", p)
    put("kin_packet", "full_crc_fixed.bin", p + b"\x01")   # harness writes the CRC
    put("kin_packet", "head_only.bin", packet(1, 8, 2.0, pose_floats()[:7] + [0] * 30))
    with tempfile.TemporaryDirectory() as t:
        subprocess.run([sys.executable, os.path.join(ROOT, "tests", "natnet_gen.py"), t],
                       check=True, stdout=subprocess.DEVNULL)
        # version index: 1 = 3.1, 3 = 4.1; bit 4: model definitions
        for f, ctl in (("frame_3.1_1.bin", 1), ("frame_4.1_1.bin", 3), ("frame_4.1_drop.bin", 3),
                       ("modeldef_3.1.bin", 0x11), ("modeldef_4.1.bin", 0x13)):
            with open(os.path.join(t, f), "rb") as fh:
                pkt = fh.read()
            put("io_natnet", f, bytes([ctl]) + pkt[4:])   # payload after the header
    gen = os.path.join(ROOT, "tests", "support", "vstream_gen.py")
    for sc, ctl in (("u16", 0x02), ("yuyv", 0x04), ("garbage", 0x03), ("truncated", 0x01),
                    ("version", 0x05), ("badsize", 0x06)):
        r = subprocess.run([sys.executable, gen, sc], check=True, stdout=subprocess.PIPE)
        put("io_vstream", sc + ".bin", bytes([ctl]) + r.stdout[:16384])
    y4m = (b"YUV4MPEG2 W4 H2 F30:1 Ip A1:1 C420jpeg XYSCSS=420JPEG\n" +
           (b"FRAME\n" + bytes(range(8)) + bytes([128] * 4)) * 2)
    put("io_vstream", "y4m.bin", b"\x03" + y4m)
    # raw: bit 3, then width-1, height-1, format index (2 = rgba)
    put("io_vstream", "raw_rgba.bin", bytes([0x0a, 3, 1, 0, 2]) + bytes(range(4 * 2 * 4)) * 2)
    for rel in ("RiggedSimple/RiggedSimple.glb", "SimpleSkin/SimpleSkin.gltf",
                "AnimatedMorphCube/glTF-Binary/AnimatedMorphCube.glb",
                "SimpleSparseAccessor/glTF-Embedded/SimpleSparseAccessor.gltf"):
        src = os.path.join(SHARED, "gltf", rel)
        if os.path.exists(src):
            with open(src, "rb") as f:
                put("io_gltf", os.path.basename(rel), f.read())


if __name__ == "__main__":
    main()
