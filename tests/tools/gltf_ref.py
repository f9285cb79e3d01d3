#!/usr/bin/python3
"""gltf_ref.py - an independent reference for the masks of test_gltf_samples.

Written from the glTF 2.0 specification, sharing no code with egofuse:
its own .gltf/.glb and accessor reading (strides, normalized integers,
sparse), the scene graph (default scene or the one asked for), animation
sampling (STEP, LINEAR with slerp, CUBICSPLINE), morph targets (weights of
the animation, else the node, else the mesh), skinning with every
JOINTS_n/WEIGHTS_n set as stored, EXT_mesh_gpu_instancing, the triangle
primitive modes, a look-at camera with an OpenGL perspective, and exact
pixel-centre coverage in double precision (both faces).

Usage: EGOFUSE_GLTF_DUMP=DIR build/tests/test_gltf_samples
       /usr/bin/python3 tests/tools/gltf_ref.py DIR
For each DIR/NNN.pgm (egofuse's mask) and NNN.txt (its camera and pose)
it draws the same mask and reports the pixels that differ, apart from
those whose centre lies within EPS pixels of a triangle edge: the fill
rule decides there, and egofuse snaps vertices to 1/256 px (docs/raster.md),
which moves an edge by up to 1/512 px at a vertex; EPS is 0.004 px
(GLTF_REF_EPS overrides). Exit 1 if any other pixel differs.
"""
import base64
import json
import math
import os
import struct
import sys

import numpy as np

EPS = float(os.environ.get("GLTF_REF_EPS", "0.004"))

CT = {5120: ('b', 1), 5121: ('B', 1), 5122: ('h', 2), 5123: ('H', 2),
      5125: ('I', 4), 5126: ('f', 4)}
NCOMP = {'SCALAR': 1, 'VEC2': 2, 'VEC3': 3, 'VEC4': 4, 'MAT2': 4, 'MAT3': 9, 'MAT4': 16}


class Gltf:
    def __init__(self, path):
        raw = open(path, 'rb').read()
        self.dir = os.path.dirname(path)
        self.bin = None
        if raw[:4] == b'glTF':
            off = 12
            while off < len(raw):
                n, kind = struct.unpack_from('<II', raw, off)
                chunk = raw[off + 8:off + 8 + n]
                if kind == 0x4E4F534A:
                    self.j = json.loads(chunk.decode('utf-8'))
                elif kind == 0x004E4942:
                    self.bin = chunk
                off += 8 + n
        else:
            self.j = json.loads(raw.decode('utf-8'))
        self.buffers = []
        for b in self.j.get('buffers', []):
            uri = b.get('uri')
            if uri is None:
                self.buffers.append(self.bin)
            elif uri.startswith('data:'):
                self.buffers.append(base64.b64decode(uri.split(',', 1)[1]))
            else:
                self.buffers.append(open(os.path.join(self.dir, uri), 'rb').read())

    def _read(self, view, offset, ctype, comps, count, stride=None):
        bv = self.j['bufferViews'][view]
        buf = self.buffers[bv['buffer']]
        fmt, size = CT[ctype]
        elem = size * comps
        stride = stride or bv.get('byteStride') or elem
        base = bv.get('byteOffset', 0) + offset
        out = np.zeros((count, comps))
        for i in range(count):
            out[i] = struct.unpack_from('<' + fmt * comps, buf, base + i * stride)
        return out

    def accessor(self, i):
        a = self.j['accessors'][i]
        comps = NCOMP[a['type']]
        ct = a['componentType']
        if 'bufferView' in a:
            v = self._read(a['bufferView'], a.get('byteOffset', 0), ct, comps, a['count'])
        else:
            v = np.zeros((a['count'], comps))
        sp = a.get('sparse')
        if sp:
            idx = self._read(sp['indices']['bufferView'], sp['indices'].get('byteOffset', 0),
                             sp['indices']['componentType'], 1, sp['count'], CT[sp['indices']['componentType']][1])
            val = self._read(sp['values']['bufferView'], sp['values'].get('byteOffset', 0),
                             ct, comps, sp['count'], CT[ct][1] * comps)
            for k in range(sp['count']):
                v[int(idx[k, 0])] = val[k]
        if a.get('normalized'):
            if ct == 5120:
                v = np.maximum(v / 127.0, -1.0)
            elif ct == 5121:
                v = v / 255.0
            elif ct == 5122:
                v = np.maximum(v / 32767.0, -1.0)
            elif ct == 5123:
                v = v / 65535.0
        return v


def quat_mat(q):
    x, y, z, w = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def trs(t, r, s):
    m = np.eye(4)
    r = np.asarray(r, float)
    r = r / np.linalg.norm(r)
    m[:3, :3] = quat_mat(r) @ np.diag(s)
    m[:3, 3] = t
    return m


def slerp(a, b, u):
    a = np.asarray(a, float)
    b = np.asarray(b, float)
    d = float(np.dot(a, b))
    if d < 0:
        b, d = -b, -d
    if d > 0.9995:
        q = a + (b - a) * u
    else:
        th = math.acos(d)
        q = (math.sin((1 - u) * th) * a + math.sin(u * th) * b) / math.sin(th)
    return q / np.linalg.norm(q)


def sample(g, sampler, t, comps, rotation):
    times = g.accessor(sampler['input'])[:, 0]
    vals = g.accessor(sampler['output']).reshape(-1)
    interp = sampler.get('interpolation', 'LINEAR')
    n = len(times)
    cub = interp == 'CUBICSPLINE'

    def key(k, part=1):
        if cub:
            return vals[(3 * k + part) * comps:(3 * k + part + 1) * comps]
        return vals[k * comps:(k + 1) * comps]
    if n == 1 or t <= times[0]:
        v = key(0)
    elif t >= times[-1]:
        v = key(n - 1)
    else:
        k = int(np.searchsorted(times, t, side='right') - 1)
        td = times[k + 1] - times[k]
        u = (t - times[k]) / td
        if interp == 'STEP':
            v = key(k)
        elif cub:
            u2, u3 = u * u, u * u * u
            v = ((2 * u3 - 3 * u2 + 1) * key(k) + td * (u3 - 2 * u2 + u) * key(k, 2) +
                 (-2 * u3 + 3 * u2) * key(k + 1) + td * (u3 - u2) * key(k + 1, 0))
        elif rotation:
            v = slerp(key(k), key(k + 1), u)
        else:
            v = key(k) * (1 - u) + key(k + 1) * u
    v = np.array(v, float)
    if rotation:
        v = v / np.linalg.norm(v)
    return v


def posed_triangles(g, scene, anim, t):
    """World-space triangles (N x 3 x 3) of the scene at time t."""
    j = g.j
    nodes = j.get('nodes', [])
    local_trs = []
    for n in nodes:
        if 'matrix' in n:
            local_trs.append(('m', np.array(n['matrix'], float).reshape(4, 4).T))
        else:
            local_trs.append(['trs', list(n.get('translation', [0, 0, 0])),
                              list(n.get('rotation', [0, 0, 0, 1])), list(n.get('scale', [1, 1, 1]))])
    morph_w = {}
    if anim >= 0:
        a = j['animations'][anim]
        for ch in a['channels']:
            tg = ch['target']
            if 'node' not in tg:
                continue
            nd, path = tg['node'], tg['path']
            smp = a['samplers'][ch['sampler']]
            if path == 'weights':
                cnt = j['accessors'][smp['output']]['count']
                keys = j['accessors'][smp['input']]['count']
                comps = cnt // keys // (3 if smp.get('interpolation') == 'CUBICSPLINE' else 1)
                morph_w[nd] = sample(g, smp, t, comps, False)
                continue
            if local_trs[nd][0] == 'm':
                continue
            if path == 'translation':
                local_trs[nd][1] = sample(g, smp, t, 3, False)
            elif path == 'rotation':
                local_trs[nd][2] = sample(g, smp, t, 4, True)
            elif path == 'scale':
                local_trs[nd][3] = sample(g, smp, t, 3, False)
    local = [x[1] if x[0] == 'm' else trs(x[1], x[2], x[3]) for x in local_trs]
    parent = [-1] * len(nodes)
    for i, n in enumerate(nodes):
        for c in n.get('children', []):
            parent[c] = i
    world = [None] * len(nodes)

    def w_of(i):
        if world[i] is None:
            world[i] = local[i] if parent[i] < 0 else w_of(parent[i]) @ local[i]
        return world[i]
    if 'scenes' in j:
        sc = scene if scene >= 0 else j.get('scene', 0)
        drawn, stack = set(), list(j['scenes'][sc]['nodes'])
        while stack:
            n = stack.pop()
            drawn.add(n)
            stack.extend(nodes[n].get('children', []))
    else:
        drawn = set(range(len(nodes)))
    tris = []
    for i in sorted(drawn):
        n = nodes[i]
        if 'mesh' not in n:
            continue
        mesh = j['meshes'][n['mesh']]
        for prim in mesh['primitives']:
            mode = prim.get('mode', 4)
            if mode not in (4, 5, 6):
                continue
            pos = g.accessor(prim['attributes']['POSITION'])
            targets = prim.get('targets', [])
            if targets:
                if i in morph_w:
                    wts = morph_w[i]
                else:
                    wts = n.get('weights', mesh.get('weights', [0.0] * len(targets)))
                for k, tg in enumerate(targets):
                    if 'POSITION' in tg and wts[k] != 0:
                        pos = pos + wts[k] * g.accessor(tg['POSITION'])
            ph = np.hstack([pos, np.ones((len(pos), 1))])
            if 'skin' in n:
                skin = j['skins'][n['skin']]
                ibm = (g.accessor(skin['inverseBindMatrices']).reshape(-1, 4, 4).transpose(0, 2, 1)
                       if 'inverseBindMatrices' in skin else np.tile(np.eye(4), (len(skin['joints']), 1, 1)))
                jm = np.array([w_of(jn) @ ibm[k] for k, jn in enumerate(skin['joints'])])
                out = np.zeros_like(ph)
                s = 0
                while 'JOINTS_%d' % s in prim['attributes']:
                    jj = g.accessor(prim['attributes']['JOINTS_%d' % s]).astype(int)
                    ww = g.accessor(prim['attributes']['WEIGHTS_%d' % s])
                    for c in range(4):
                        out += ww[:, c:c + 1] * np.einsum('vij,vj->vi', jm[jj[:, c]], ph)
                    s += 1
                wp = [out[:, :3]]
            else:
                inst = n.get('extensions', {}).get('EXT_mesh_gpu_instancing')
                mats = [w_of(i)]
                if inst:
                    at = inst['attributes']
                    cnt = j['accessors'][next(iter(at.values()))]['count']
                    T = g.accessor(at['TRANSLATION']) if 'TRANSLATION' in at else np.zeros((cnt, 3))
                    R = g.accessor(at['ROTATION']) if 'ROTATION' in at else np.tile([0, 0, 0, 1.0], (cnt, 1))
                    S = g.accessor(at['SCALE']) if 'SCALE' in at else np.ones((cnt, 3))
                    mats = [w_of(i) @ trs(T[k], R[k], S[k]) for k in range(cnt)]
                wp = [(ph @ m.T)[:, :3] for m in mats]
            if 'indices' in prim:
                idx = g.accessor(prim['indices'])[:, 0].astype(int)
            else:
                idx = np.arange(len(pos))
            if mode == 4:
                tri = idx.reshape(-1, 3)
            elif mode == 5:
                tri = np.array([[idx[k], idx[k + 1 + k % 2], idx[k + 2 - k % 2]] for k in range(len(idx) - 2)])
            else:
                tri = np.array([[idx[k + 1], idx[k + 2], idx[0]] for k in range(len(idx) - 2)])
            for p in wp:
                tris.append(p[tri])
    return np.concatenate(tris) if tris else np.zeros((0, 3, 3))


def camera(eye, target, fovy, w, h, near, far):
    eye, target = np.array(eye, float), np.array(target, float)
    f = target - eye
    f /= np.linalg.norm(f)
    s = np.cross(f, [0, 1, 0])
    s /= np.linalg.norm(s)
    u = np.cross(s, f)
    view = np.eye(4)
    view[0, :3], view[1, :3], view[2, :3] = s, u, -f
    view[:3, 3] = -view[:3, :3] @ eye
    ct = 1 / math.tan(math.radians(fovy) / 2)
    proj = np.zeros((4, 4))
    proj[0, 0], proj[1, 1] = ct / (w / h), ct
    proj[2, 2], proj[2, 3] = (far + near) / (near - far), 2 * far * near / (near - far)
    proj[3, 2] = -1
    return proj @ view


def rasterize(tris, vp, w, h):
    """Coverage of pixel centres (both faces) and a mask of the centres
    within EPS pixels of an edge of a triangle covering or nearly covering
    them."""
    cover = np.zeros((h, w), bool)
    edge = np.zeros((h, w), bool)
    xs = np.arange(w) + 0.5
    ys = np.arange(h) + 0.5
    X, Y = np.meshgrid(xs, ys)
    for t in tris:
        c = np.hstack([t, np.ones((3, 1))]) @ vp.T
        if np.any(c[:, 3] <= 0):
            raise SystemExit('a triangle crosses the camera plane: choose another camera')
        ndc = c[:, :3] / c[:, 3:4]
        if np.all(ndc[:, 2] < -1) or np.all(ndc[:, 2] > 1):
            continue
        if np.any(np.abs(ndc[:, 2]) > 1):
            raise SystemExit('a triangle crosses the near or far plane')
        px = (ndc[:, 0] * 0.5 + 0.5) * w
        py = (1 - (ndc[:, 1] * 0.5 + 0.5)) * h
        area = (px[1] - px[0]) * (py[2] - py[0]) - (py[1] - py[0]) * (px[2] - px[0])
        if area == 0:
            continue
        x0, x1 = max(int(math.floor(px.min())) - 1, 0), min(int(math.ceil(px.max())) + 1, w)
        y0, y1 = max(int(math.floor(py.min())) - 1, 0), min(int(math.ceil(py.max())) + 1, h)
        if x0 >= x1 or y0 >= y1:
            continue
        Xs, Ys = X[y0:y1, x0:x1], Y[y0:y1, x0:x1]
        inside = np.ones(Xs.shape, bool)
        near_edge = np.zeros(Xs.shape, bool)
        sgn = 1 if area > 0 else -1
        dist = []
        for k in range(3):
            ax, ay = px[k], py[k]
            bx, by = px[(k + 1) % 3], py[(k + 1) % 3]
            e = ((bx - ax) * (Ys - ay) - (by - ay) * (Xs - ax)) * sgn
            ln = math.hypot(bx - ax, by - ay)
            d = e / ln if ln > 0 else e
            dist.append(d)
            inside &= d > 0
        dmin = np.minimum(np.minimum(dist[0], dist[1]), dist[2])
        near_edge = np.abs(dmin) <= EPS
        cover[y0:y1, x0:x1] |= inside
        edge[y0:y1, x0:x1] |= near_edge
    return cover, edge


def read_pgm(path):
    data = open(path, 'rb').read()
    parts = data.split(b'\n', 3)
    w, h = map(int, parts[1].split())
    return np.frombuffer(parts[3], np.uint8).reshape(h, w)


def main():
    d = sys.argv[1]
    bad = 0
    n = 0
    for name in sorted(os.listdir(d)):
        if not name.endswith('.txt'):
            continue
        cfg = {}
        for line in open(os.path.join(d, name)):
            k, v = line.rstrip('\n').split(' ', 1)
            cfg[k] = v
        w, h = map(int, cfg['size'].split())
        g = Gltf(cfg['model'])
        tris = posed_triangles(g, int(cfg['scene']), int(cfg['anim']), float(cfg['time']))
        vp = camera(list(map(float, cfg['eye'].split())), list(map(float, cfg['target'].split())),
                    float(cfg['fovy']), w, h, float(cfg['near']), float(cfg['far']))
        cover, edge = rasterize(tris, vp, w, h)
        ego = read_pgm(os.path.join(d, name[:-4] + '.pgm')) != 0
        diff = ego != cover
        real = diff & ~edge
        n += 1
        label = '%s %s scene %s anim %s t %.4g' % (name[:-4], os.path.basename(cfg['model']),
                                                   cfg['scene'], cfg['anim'], float(cfg['time']))
        print('%-70s %5d px, %d differ (%d on an edge), %d elsewhere' %
              (label, int(cover.sum()), int(diff.sum()), int((diff & edge).sum()), int(real.sum())))
        if real.any():
            bad += 1
    print('%d masks, %d with pixels that differ off the edges' % (n, bad))
    sys.exit(1 if bad else 0)


if __name__ == '__main__':
    main()
