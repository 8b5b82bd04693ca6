#!/usr/bin/env python3
"""mk_showcase.py [OUTDIR]: writes showcase.gltf, the same scene as showcase.glb, and
showcase_sky.hdr (default: this folder).

A small room built the way shipped assets are built, for the README picture and the asset
benchmark (tests/bench/showcase.sh, tests/bench/assets.sh):
- walls and ceiling are single sheets with doubleSided: true, and two walls are wound
  outwards (an exporter's mixed winding: doubleSided makes it harmless), their normals into
  the room (the side a one-layer lightmap keeps);
- a window opening in the left wall (x = -2), lit by showcase_sky.hdr, an equirectangular
  Radiance HDR made here: a blue gradient sky, a brown ground below the horizon and a small
  sun (3 degrees across) shining in through the window, about 50 degrees up;
- a curtain of a few folds hanging across the window's edge: a thin sheet, doubleSided, lit
  on its window side by the sun and on its room side by the room;
- a potted plant of leaf cards whose baseColorTexture has an alpha channel (a leaf shape,
  alpha 0 around it), alphaMode MASK with alphaCutoff 0.5, doubleSided: as glTF defines it,
  a renderer without cutouts shows the whole cards;
- a screen on the back wall with an emissiveTexture (colour bars over a dark gradient),
  emissiveFactor 1 1 1 and KHR_materials_emissive_strength 6;
- a table and the pot, plain closed boxes; a camera in the room's front corner.
Units: metres, +Y up. Everything is embedded (base64 buffer and PNG images)."""
import base64, json, math, os, struct, sys, zlib

out_dir = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))


def png(rows, alpha=False):
    """8-bit RGB or RGBA PNG from rows of pixel tuples"""
    raw = b''.join(b'\0' + bytes(v for px in r for v in px) for r in rows)
    chunk = lambda t, d: struct.pack('>I', len(d)) + t + d + struct.pack('>I', zlib.crc32(t + d) & 0xffffffff)
    return (b'\x89PNG\r\n\x1a\n' +
            chunk(b'IHDR', struct.pack('>IIBBBBB', len(rows[0]), len(rows), 8, 6 if alpha else 2, 0, 0, 0)) +
            chunk(b'IDAT', zlib.compress(raw, 9)) + chunk(b'IEND', b''))


# ---- textures ---------------------------------------------------------------------------
def leaf_texture(w=64, h=32):
    """a leaf along the card's length (u), pointed at both ends, a lighter midrib; alpha 0 off the leaf"""
    rows = []
    for j in range(h):
        row = []
        for i in range(w):
            u, v = (i + 0.5) / w, (j + 0.5) / h
            half = 0.46 * math.sin(math.pi * u) ** 0.8   # the leaf's half-width at u
            d = abs(v - 0.5)
            inside = d < half
            vein = d < 0.03 and 0.04 < u < 0.96
            g = 0.55 + 0.3 * (1 - d / max(half, 1e-3)) if inside else 0.0
            if inside and vein:
                row.append((150, 200, 110, 255))
            elif inside:
                row.append((int(40 + 30 * g), int(110 + 90 * g), int(30 + 20 * g), 255))
            else:
                row.append((60, 120, 40, 0))  # the colour under alpha 0 is the leaf's, so filtering shows no fringe
        rows.append(row)
    return png(rows, alpha=True)


def screen_texture(w=64, h=36):
    """colour bars over the top two thirds, a dark blue-to-orange gradient below (sRGB)"""
    bars = [(235, 235, 235), (235, 235, 20), (20, 235, 235), (20, 235, 20), (235, 20, 235), (235, 20, 20), (20, 20, 235)]
    rows = []
    for j in range(h):
        row = []
        for i in range(w):
            if j < 2 * h // 3:
                row.append(bars[i * len(bars) // w])
            else:
                t = i / (w - 1)
                row.append((int(30 + 200 * t), int(30 + 90 * t), int(120 - 100 * t)))
        rows.append(row)
    return png(rows)


# ---- the sky: an equirectangular Radiance HDR ----------------------------------------------
SUN = (-0.55, 0.80, 0.30)  # towards the sun: through the window (x = -2), about 50 degrees up
SUN_RADIUS = math.radians(1.5)
SUN_RADIANCE = (900.0, 820.0, 700.0)


def sky_radiance(d):
    """radiance (W/m^2/sr) of the direction d: the convention of RAD_LIGHT_ENVIRONMENT"""
    n = math.sqrt(sum(c * c for c in SUN))
    cosang = sum(a * b / n for a, b in zip(d, SUN))
    if cosang > math.cos(SUN_RADIUS):
        return SUN_RADIANCE
    y = d[1]
    if y < 0:
        return (0.18, 0.15, 0.11)  # ground
    t = y ** 0.5
    return (0.9 - 0.6 * t, 1.0 - 0.45 * t, 1.15 - 0.1 * t)


def rgbe(c):
    m = max(c)
    if m < 1e-32:
        return (0, 0, 0, 0)
    e = math.frexp(m)[1]
    s = 256.0 / 2.0 ** e
    return (int(c[0] * s), int(c[1] * s), int(c[2] * s), e + 128)


def write_hdr(path, w=256, h=128):
    """run-length encoded scanlines (literal runs only), the layout every .hdr reader takes"""
    out = bytearray(b'#?RADIANCE\n# tests/data/mk_showcase.py: sky, ground and sun\nFORMAT=32-bit_rle_rgbe\n\n')
    out += b'-Y %d +X %d\n' % (h, w)
    for j in range(h):
        theta = math.pi * (j + 0.5) / h
        px = []
        for i in range(w):
            phi = 2 * math.pi * (i + 0.5) / w
            d = (math.sin(theta) * math.cos(phi), math.cos(theta), math.sin(theta) * math.sin(phi))
            px.append(rgbe(sky_radiance(d)))
        out += bytes((2, 2, w >> 8, w & 255))
        for ch in range(4):
            vals = [p[ch] for p in px]
            for k in range(0, w, 128):
                run = vals[k:k + 128]
                out += bytes([len(run)]) + bytes(run)
    open(path, 'wb').write(bytes(out))


# ---- geometry --------------------------------------------------------------------------------
materials, meshes, nodes = [], [], []
buf = bytearray()
views, accessors = [], []


def material(name, albedo, double=False, **extra):
    m = {'name': name, 'pbrMetallicRoughness': {'baseColorFactor': list(albedo) + [1.0], 'metallicFactor': 0.0,
                                                'roughnessFactor': 1.0}}
    if double:
        m['doubleSided'] = True
    m.update(extra)
    materials.append(m)
    return len(materials) - 1


def add_view(data):
    while len(buf) % 4:
        buf.append(0)
    views.append({'buffer': 0, 'byteOffset': len(buf), 'byteLength': len(data)})
    buf.extend(data)
    return len(views) - 1


def face_normal(a, b, c):
    u = [b[k] - a[k] for k in range(3)]
    v = [c[k] - a[k] for k in range(3)]
    n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
    ln = math.sqrt(sum(x * x for x in n))
    return tuple(x / ln for x in n)


def add_mesh(name, mat, quads=(), tris=(), normal=None):
    """quads: (p0, p1, p2, p3) counter-clockwise seen from the front, uvs 0..1 over each;
    tris: ((p, uv), (p, uv), (p, uv)); normal: the shading normal of every vertex (as an
    exporter writes it: the side meant to be seen), else each face's own"""
    P, UV, N, I = [], [], [], []
    for q in quads:
        b = len(P)
        P += list(q)
        UV += [(0, 1), (1, 1), (1, 0), (0, 0)]  # glTF: v = 0 is the image's top row
        N += [normal or face_normal(q[0], q[1], q[2])] * 4
        I += [b, b + 1, b + 2, b, b + 2, b + 3]
    for t in tris:
        b = len(P)
        for p, uv in t:
            P.append(p)
            UV.append(uv)
        N += [normal or face_normal(t[0][0], t[1][0], t[2][0])] * 3
        I += [b, b + 1, b + 2]
    lo = [min(p[a] for p in P) for a in range(3)]
    hi = [max(p[a] for p in P) for a in range(3)]
    pv = add_view(b''.join(struct.pack('<3f', *p) for p in P))
    uv = add_view(b''.join(struct.pack('<2f', *t) for t in UV))
    nv = add_view(b''.join(struct.pack('<3f', *n) for n in N))
    iv = add_view(b''.join(struct.pack('<I', i) for i in I))
    accessors.extend([{'bufferView': pv, 'componentType': 5126, 'count': len(P), 'type': 'VEC3', 'min': lo, 'max': hi},
                      {'bufferView': uv, 'componentType': 5126, 'count': len(P), 'type': 'VEC2'},
                      {'bufferView': nv, 'componentType': 5126, 'count': len(P), 'type': 'VEC3'},
                      {'bufferView': iv, 'componentType': 5125, 'count': len(I), 'type': 'SCALAR'}])
    a = len(accessors) - 4
    meshes.append({'name': name, 'primitives': [{'attributes': {'POSITION': a, 'TEXCOORD_0': a + 1, 'NORMAL': a + 2},
                                                 'indices': a + 3, 'material': mat}]})
    nodes.append({'name': name, 'mesh': len(meshes) - 1})


def rect(axis, c, a0, a1, b0, b1, flip=False):
    """an axis-aligned rectangle at coordinate c on 'axis' (0 x, 1 y, 2 z) spanning [a0, a1] x
    [b0, b1] on the other two axes (in order); front towards +axis unless flip"""
    def P(a, b):
        p = [0.0, 0.0, 0.0]
        o = [k for k in range(3) if k != axis]
        p[axis], p[o[0]], p[o[1]] = c, a, b
        return tuple(p)
    q = (P(a0, b0), P(a1, b0), P(a1, b1), P(a0, b1))
    # (a, b) x (b, c) orientation: for axis y the other axes are (x, z) and x cross z = -y
    if (axis == 1) != flip:
        q = q[::-1]
    return q


def box(x0, x1, y0, y1, z0, z1):
    """five faces, outwards (no bottom: it stands on something)"""
    return [rect(0, x1, y0, y1, z0, z1), rect(0, x0, y0, y1, z0, z1, True), rect(1, y1, x0, x1, z0, z1),
            rect(2, z1, x0, x1, y0, y1), rect(2, z0, x0, x1, y0, y1, True)]


X0, X1, Y1, Z0, Z1 = -2.0, 2.0, 2.6, -2.5, 2.5
WY0, WY1, WZ0, WZ1 = 0.8, 2.2, -0.6, 1.2   # the window opening in the wall x = X0

plaster = material('plaster', (0.75, 0.72, 0.66), double=True)
floor = material('floor_wood', (0.42, 0.30, 0.20))
ceiling = material('ceiling', (0.80, 0.80, 0.78), double=True)
curtain = material('curtain', (0.72, 0.28, 0.22), double=True)
leaf = material('leaf_cards', (1.0, 1.0, 1.0), double=True, alphaMode='MASK', alphaCutoff=0.5)
materials[leaf]['pbrMetallicRoughness']['baseColorTexture'] = {'index': 0}
pot = material('terracotta', (0.55, 0.28, 0.18))
table = material('table', (0.30, 0.32, 0.38))
frame = material('screen_frame', (0.04, 0.04, 0.04))
screen = material('screen', (0.03, 0.03, 0.03), emissiveFactor=[1.0, 1.0, 1.0], emissiveTexture={'index': 1},
                  extensions={'KHR_materials_emissive_strength': {'emissiveStrength': 6.0}})

add_mesh('floor', floor, quads=[rect(1, 0.0, X0, X1, Z0, Z1)])
add_mesh('ceiling', ceiling, quads=[rect(1, Y1, X0, X1, Z0, Z1, True)])
# the left wall around the window: four sheets, facing the room (+x)
add_mesh('wall_window', plaster, quads=[rect(0, X0, 0.0, WY0, Z0, Z1), rect(0, X0, WY1, Y1, Z0, Z1),
                                        rect(0, X0, WY0, WY1, Z0, WZ0), rect(0, X0, WY0, WY1, WZ1, Z1)])
# the right and back walls wound outwards (doubleSided: each side is a surface of its own)
add_mesh('wall_right', plaster, quads=[rect(0, X1, 0.0, Y1, Z0, Z1)], normal=(-1.0, 0.0, 0.0))
add_mesh('wall_back', plaster, quads=[rect(2, Z1, X0, X1, 0.0, Y1)], normal=(0.0, 0.0, -1.0))
add_mesh('wall_front', plaster, quads=[rect(2, Z0, X0, X1, 0.0, Y1)])

# curtain: folds along z, hanging from near the ceiling to just above the floor, across the
# window's far edge
folds, cols = 3, 12
cz0, cz1, cy0, cy1 = 0.55, 1.75, 0.15, 2.45
cq = []
for k in range(cols):
    za, zb = cz0 + (cz1 - cz0) * k / cols, cz0 + (cz1 - cz0) * (k + 1) / cols
    xa = X0 + 0.16 + 0.07 * math.sin(2 * math.pi * folds * k / cols)
    xb = X0 + 0.16 + 0.07 * math.sin(2 * math.pi * folds * (k + 1) / cols)
    cq.append(((xa, cy0, za), (xb, cy0, zb), (xb, cy1, zb), (xa, cy1, za)))
add_mesh('curtain', curtain, quads=cq, normal=(1.0, 0.0, 0.0))  # its room side

# table and pot
add_mesh('table', table, quads=box(0.5, 1.5, 0.0, 0.45, 0.6, 1.5))
px, pz, ph = -0.9, 0.35, 0.35
add_mesh('pot', pot, quads=box(px - 0.16, px + 0.16, 0.0, ph, pz - 0.16, pz + 0.16))
# leaf cards: a rosette of cards rising from the pot, each card a quad along its leaf
lq = []
for k in range(11):
    ang = 2 * math.pi * k / 11 + 0.3 * (k % 3)
    rise = math.radians(20 + 35 * ((k * 7) % 5) / 4)     # each leaf's angle above horizontal
    length, width = 0.55 + 0.1 * (k % 3), 0.22
    base = (px, ph + 0.02 + 0.03 * (k % 2), pz)
    d = (math.cos(ang) * math.cos(rise), math.sin(rise), math.sin(ang) * math.cos(rise))
    s = (-math.sin(ang) * width / 2, 0.0, math.cos(ang) * width / 2)   # across the leaf, horizontal
    tip = tuple(base[i] + length * d[i] for i in range(3))
    lq.append((tuple(base[i] - s[i] for i in range(3)), tuple(tip[i] - s[i] for i in range(3)),
               tuple(tip[i] + s[i] for i in range(3)), tuple(base[i] + s[i] for i in range(3))))
# uvs: u along the leaf (base 0, tip 1), v across
leaf_tris = []
for q in lq:
    uv = [(0, 1), (1, 1), (1, 0), (0, 0)]
    leaf_tris += [((q[0], uv[0]), (q[1], uv[1]), (q[2], uv[2])), ((q[0], uv[0]), (q[2], uv[2]), (q[3], uv[3]))]
add_mesh('plant', leaf, tris=leaf_tris)

# the screen on the back wall, facing into the room (-z), its frame a little behind it
sx0, sx1, sy0, sy1 = -0.1, 1.3, 1.05, 1.85
add_mesh('screen_frame', frame, quads=[rect(2, Z1 - 0.01, sx1 + 0.05, sx0 - 0.05, sy0 - 0.05, sy1 + 0.05)])
add_mesh('screen', screen, quads=[rect(2, Z1 - 0.02, sx1, sx0, sy0, sy1)])

# ---- camera: in the front right corner, looking at the window and the back wall ---------------
eye, target = (1.6, 1.55, -2.3), (-0.5, 0.95, 1.2)
f = [t - e for t, e in zip(target, eye)]
n = math.sqrt(sum(c * c for c in f))
f = [c / n for c in f]
# the camera looks along its local -Z: yaw about +Y, then pitch about the camera's +X
yaw = math.atan2(-f[0], -f[2])
pitch = math.asin(f[1])
qy = (0.0, math.sin(yaw / 2), 0.0, math.cos(yaw / 2))
qx = (math.sin(pitch / 2), 0.0, 0.0, math.cos(pitch / 2))


def qmul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz)


rot = qmul(qy, qx)
nodes.append({'name': 'camera', 'camera': 0, 'translation': list(eye), 'rotation': list(rot)})

g = {'asset': {'version': '2.0', 'generator': 'tests/data/mk_showcase.py',
               'copyright': 'radiosity.h test data, same licence as the repository'},
     'extensionsUsed': ['KHR_materials_emissive_strength'], 'scene': 0,
     'scenes': [{'nodes': list(range(len(nodes)))}], 'nodes': nodes, 'meshes': meshes, 'materials': materials,
     'cameras': [{'type': 'perspective', 'perspective': {'yfov': math.radians(62.0), 'aspectRatio': 1.0,
                                                         'znear': 0.05, 'zfar': 50.0}}],
     'images': [{'uri': 'data:image/png;base64,' + base64.b64encode(leaf_texture()).decode()},
                {'uri': 'data:image/png;base64,' + base64.b64encode(screen_texture()).decode()}],
     'samplers': [{'magFilter': 9729, 'minFilter': 9729}],
     'textures': [{'source': 0, 'sampler': 0}, {'source': 1, 'sampler': 0}],
     'buffers': [{'byteLength': len(buf), 'uri': 'data:application/octet-stream;base64,' +
                  base64.b64encode(bytes(buf)).decode()}],
     'bufferViews': views, 'accessors': accessors}
with open(os.path.join(out_dir, 'showcase.gltf'), 'w') as fp:
    json.dump(g, fp, indent=1)
    fp.write('\n')


def glb(doc, pngs):
    """the same scene as a binary glTF: one BIN chunk holding the geometry and the images
    (images through bufferViews with a mimeType, as exporters write .glb)"""
    doc = json.loads(json.dumps(doc))
    data = bytearray(buf)
    doc['images'] = []
    for p in pngs:
        while len(data) % 4:
            data.append(0)
        doc['bufferViews'].append({'buffer': 0, 'byteOffset': len(data), 'byteLength': len(p)})
        data.extend(p)
        doc['images'].append({'bufferView': len(doc['bufferViews']) - 1, 'mimeType': 'image/png'})
    while len(data) % 4:
        data.append(0)
    doc['buffers'] = [{'byteLength': len(data)}]
    js = json.dumps(doc, separators=(',', ':')).encode()
    js += b' ' * (-len(js) % 4)
    body = struct.pack('<I', len(js)) + b'JSON' + js + struct.pack('<I', len(data)) + b'BIN\0' + bytes(data)
    return b'glTF' + struct.pack('<II', 2, 12 + len(body)) + body


with open(os.path.join(out_dir, 'showcase.glb'), 'wb') as fp:
    fp.write(glb(g, [leaf_texture(), screen_texture()]))
write_hdr(os.path.join(out_dir, 'showcase_sky.hdr'))
