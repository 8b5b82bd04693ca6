#!/usr/bin/env python3
"""mk_texture_transform.py [OUTDIR]: texture_transform.gltf and texture_transform_baked.gltf.

Two unit quads in the plane z = 0 facing -z, side by side: the left one emissive (emissiveTexture
x emissiveFactor 1, black base colour), the right one white-lit through its baseColorTexture.
Both use one 4 x 4 image of 16 different colours. In texture_transform.gltf the quads' uvs run
0..1 and both texture references carry KHR_texture_transform (offset, rotation and scale); in
texture_transform_baked.gltf the transform is applied to the uvs instead and the references
have none. The transform is affine, so it commutes with the interpolation across a triangle:
a reader that implements the extension renders both files alike."""
import base64, json, math, os, struct, sys, zlib

out_dir = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
OFFSET, ROTATION, SCALE = (0.2, 0.1), 0.6, (0.7, 1.3)


def png(rows):
    raw = b''.join(b'\0' + bytes(v for px in r for v in px) for r in rows)
    chunk = lambda t, d: struct.pack('>I', len(d)) + t + d + struct.pack('>I', zlib.crc32(t + d) & 0xffffffff)
    return (b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', len(rows[0]), len(rows), 8, 2, 0, 0, 0)) +
            chunk(b'IDAT', zlib.compress(raw)) + chunk(b'IEND', b''))


image = png([[(40 + 60 * i, 30 + 70 * j, 220 - 50 * i) for i in range(4)] for j in range(4)])


def transform(uv):
    """KHR_texture_transform: scale, then rotate (u' = u cos + v sin, v' = v cos - u sin), then offset"""
    u, v = uv[0] * SCALE[0], uv[1] * SCALE[1]
    c, s = math.cos(ROTATION), math.sin(ROTATION)
    return (u * c + v * s + OFFSET[0], v * c - u * s + OFFSET[1])


def write(path, baked):
    buf = bytearray()
    views, accessors, meshes, nodes = [], [], [], []
    ext = {} if baked else {'extensions': {'KHR_texture_transform': {'offset': list(OFFSET), 'rotation': ROTATION,
                                                                     'scale': list(SCALE)}}}
    materials = [
        {'name': 'emissive', 'pbrMetallicRoughness': {'baseColorFactor': [0, 0, 0, 1], 'metallicFactor': 0.0},
         'emissiveFactor': [1, 1, 1], 'emissiveTexture': dict({'index': 0}, **ext)},
        {'name': 'textured', 'pbrMetallicRoughness': {'baseColorTexture': dict({'index': 0}, **ext), 'metallicFactor': 0.0,
                                                      'baseColorFactor': [0.9, 0.9, 0.9, 1]}}]
    for k, x0 in enumerate((0.05, -1.05)):  # seen from -z, +x is on the left
        P = [(x0, 0, 0), (x0 + 1, 0, 0), (x0 + 1, 1, 0), (x0, 1, 0)]
        UV = [(1, 1), (0, 1), (0, 0), (1, 0)]
        if baked:
            UV = [transform(t) for t in UV]
        I = [0, 2, 1, 0, 3, 2]  # counter-clockwise seen from -z
        for data in (b''.join(struct.pack('<3f', *p) for p in P), b''.join(struct.pack('<2f', *t) for t in UV),
                     b''.join(struct.pack('<I', i) for i in I)):
            while len(buf) % 4:
                buf.append(0)
            views.append({'buffer': 0, 'byteOffset': len(buf), 'byteLength': len(data)})
            buf.extend(data)
        a = len(accessors)
        accessors += [{'bufferView': a, 'componentType': 5126, 'count': 4, 'type': 'VEC3',
                       'min': [x0, 0, 0], 'max': [x0 + 1, 1, 0]},
                      {'bufferView': a + 1, 'componentType': 5126, 'count': 4, 'type': 'VEC2'},
                      {'bufferView': a + 2, 'componentType': 5125, 'count': 6, 'type': 'SCALAR'}]
        meshes.append({'name': materials[k]['name'], 'primitives': [{'attributes': {'POSITION': a, 'TEXCOORD_0': a + 1},
                                                                     'indices': a + 2, 'material': k}]})
        nodes.append({'name': materials[k]['name'], 'mesh': k})
    g = {'asset': {'version': '2.0', 'generator': 'tests/data/mk_texture_transform.py'}, 'scene': 0,
         'scenes': [{'nodes': [0, 1]}], 'nodes': nodes, 'meshes': meshes, 'materials': materials,
         'images': [{'uri': 'data:image/png;base64,' + base64.b64encode(image).decode()}],
         'samplers': [{'magFilter': 9729, 'minFilter': 9729}], 'textures': [{'source': 0, 'sampler': 0}],
         'buffers': [{'byteLength': len(buf), 'uri': 'data:application/octet-stream;base64,' +
                      base64.b64encode(bytes(buf)).decode()}], 'bufferViews': views, 'accessors': accessors}
    if not baked:
        g['extensionsUsed'] = ['KHR_texture_transform']
    with open(path, 'w') as fp:
        json.dump(g, fp, indent=1)
        fp.write('\n')


write(os.path.join(out_dir, 'texture_transform.gltf'), False)
write(os.path.join(out_dir, 'texture_transform_baked.gltf'), True)
