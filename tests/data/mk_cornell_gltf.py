#!/usr/bin/env python3
"""mk_cornell_gltf.py OBJ OUT.gltf [--texture] [--unnamed]: an OBJ + MTL (as `rad export cornell` writes
it) as a glTF 2.0 file with one embedded buffer. Each material's Ke becomes emissiveFactor
Ke / max(Ke) times KHR_materials_emissive_strength max(Ke), the usual way to write a radiance
above 1. With --texture the emitters also get an emissiveTexture: a 2 x 2 black and white
checker (an embedded PNG) over uvs 0..1 across each emitter, whose mean is one half. With
--unnamed the materials have no names and the emitters' meshes come first (an importer that
numbers materials by first use then sees them in another order than the file's)."""
import base64, json, struct, sys, zlib

obj, out = sys.argv[1], sys.argv[2]
textured = '--texture' in sys.argv[3:]
unnamed = '--unnamed' in sys.argv[3:]
mtl, cur, mats, order = None, None, {}, []
verts, meshes, name, usemtl = [], [], 'mesh', None
for line in open(obj):
    w = line.split()
    if not w or w[0].startswith('#'): continue
    if w[0] == 'mtllib': mtl = w[1]
    elif w[0] == 'o': name = w[1]
    elif w[0] == 'v': verts.append(tuple(float(x) for x in w[1:4]))
    elif w[0] == 'usemtl': usemtl = w[1]
    elif w[0] == 'f':
        if not meshes or meshes[-1][0] != name: meshes.append((name, usemtl, []))
        meshes[-1][2].append([int(x.split('/')[0]) - 1 for x in w[1:4]])
for line in open(obj.rsplit('/', 1)[0] + '/' + mtl if '/' in obj else mtl):
    w = line.split()
    if not w: continue
    if w[0] == 'newmtl': cur = w[1]; mats[cur] = {}; order.append(cur)
    elif w[0] in ('Kd', 'Ke'): mats[cur][w[0]] = [float(x) for x in w[1:4]]

def png(rows):  # 8-bit RGB
    raw = b''.join(b'\0' + bytes(v for px in r for v in px) for r in rows)
    chunk = lambda t, d: struct.pack('>I', len(d)) + t + d + struct.pack('>I', zlib.crc32(t + d) & 0xffffffff)
    return (b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', len(rows[0]), len(rows), 8, 2, 0, 0, 0)) +
            chunk(b'IDAT', zlib.compress(raw)) + chunk(b'IEND', b''))

if unnamed:
    meshes.sort(key=lambda me: 0 if max(mats[me[1]].get('Ke', [0.0])) > 0 else 1)
materials = []
for m in order:
    kd, ke = mats[m].get('Kd', [0.5] * 3), mats[m].get('Ke', [0.0] * 3)
    g = {'name': m, 'pbrMetallicRoughness': {'baseColorFactor': kd + [1.0], 'metallicFactor': 0.0}}
    s = max(ke)
    if s > 0:
        g['emissiveFactor'] = [k / s for k in ke]
        if s != 1: g['extensions'] = {'KHR_materials_emissive_strength': {'emissiveStrength': s}}
        if textured: g['emissiveTexture'] = {'index': 0}
    if unnamed: del g['name']
    materials.append(g)
buf, views, accessors, gmeshes, nodes = b'', [], [], [], []
def add(data, target=None):
    global buf
    while len(buf) % 4: buf += b'\0'
    views.append({'buffer': 0, 'byteOffset': len(buf), 'byteLength': len(data)})
    buf += data
    return len(views) - 1
for name, mname, faces in meshes:
    used = sorted({i for f in faces for i in f})
    remap = {v: k for k, v in enumerate(used)}
    P = [verts[i] for i in used]
    # uvs over the quad's own plane: the two widest axes of its bounds, scaled to 0..1
    lo = [min(p[a] for p in P) for a in range(3)]; hi = [max(p[a] for p in P) for a in range(3)]
    ax = sorted(range(3), key=lambda a: hi[a] - lo[a])[1:]
    UV = [tuple((p[a] - lo[a]) / (hi[a] - lo[a]) for a in ax) for p in P]
    pv = add(b''.join(struct.pack('<3f', *p) for p in P))
    uv = add(b''.join(struct.pack('<2f', *t) for t in UV))
    iv = add(b''.join(struct.pack('<3I', *[remap[i] for i in f]) for f in faces))
    accessors += [{'bufferView': pv, 'componentType': 5126, 'count': len(P), 'type': 'VEC3', 'min': lo, 'max': hi},
                  {'bufferView': uv, 'componentType': 5126, 'count': len(P), 'type': 'VEC2'},
                  {'bufferView': iv, 'componentType': 5125, 'count': 3 * len(faces), 'type': 'SCALAR'}]
    a = len(accessors) - 3
    gmeshes.append({'name': name, 'primitives': [{'attributes': {'POSITION': a, 'TEXCOORD_0': a + 1}, 'indices': a + 2,
                                                  'material': order.index(mname)}]})
    nodes.append({'name': name, 'mesh': len(gmeshes) - 1})
g = {'asset': {'version': '2.0', 'generator': 'tests/data/mk_cornell_gltf.py'}, 'scene': 0,
     'scenes': [{'nodes': list(range(len(nodes)))}], 'nodes': nodes, 'meshes': gmeshes, 'materials': materials,
     'extensionsUsed': ['KHR_materials_emissive_strength'],
     'buffers': [{'byteLength': len(buf), 'uri': 'data:application/octet-stream;base64,' + base64.b64encode(buf).decode()}],
     'bufferViews': views, 'accessors': accessors}
if textured:
    W, B = (255, 255, 255), (0, 0, 0)
    g['images'] = [{'uri': 'data:image/png;base64,' + base64.b64encode(png([[W, B], [B, W]])).decode()}]
    g['samplers'] = [{'magFilter': 9729, 'minFilter': 9729}]
    g['textures'] = [{'source': 0, 'sampler': 0}]
json.dump(g, open(out, 'w'), indent=1)
