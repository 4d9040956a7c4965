#!/usr/bin/env python3
"""Writes the corpus of malformed input files next to this script, and expected.tsv: for each
file, a fragment its error message must contain. Run it again after changing a case; the files
are committed so tests and fuzzers never depend on Python."""
import json
import os
import struct

here = os.path.dirname(os.path.abspath(__file__))
expected = []


def write(name, data, fragment):
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(here, name), 'wb') as f:
        f.write(data)
    expected.append((name, fragment))


def floats(*values):
    return struct.pack('<%df' % len(values), *values)


def ply_binary_header(vertices, faces):
    return ('ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n'
            'property float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n'
            % (vertices, faces)).encode()


def face(*indices):
    return struct.pack('<B%di' % len(indices), len(indices), *indices)


tri = floats(0, 0, 0, 1, 0, 0, 0, 1, 0)
nan = float('nan')

# --- PLY ---
write('ply-empty.ply', b'', 'byte 0: not a PLY file')
write('ply-wrong-magic.ply', 'PLY\nformat ascii 1.0\nend_header\n', 'byte 0: not a PLY file')
write('ply-bad-header.ply', 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float\nend_header\n', ':4: expected')
write('ply-no-end-header.ply', 'ply\nformat ascii 1.0\nelement vertex 3\n', "no 'end_header'")
write('ply-huge-count.ply', ply_binary_header(10**12, 0) + tri,
      "header declares 1000000000000 'vertex' elements")
write('ply-truncated.ply', ply_binary_header(3, 1) + tri[:20], 'the file is truncated')
write('ply-nan-binary.ply', ply_binary_header(3, 1) + floats(0, 0, 0, nan, 0, 0, 0, 1, 0) + face(0, 1, 2),
      'byte 181: vertex 1: coordinate is not a finite number')
write('ply-nan-ascii.ply', 'ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n'
      'property float z\nend_header\n0 0 0\n1 inf 0\n', ':9: vertex 1: coordinate is not a finite number')
write('ply-index-out-of-range.ply', ply_binary_header(3, 1) + tri + face(0, 1, 7),
      'face 0: vertex index 7 out of range (the file has 3 vertices)')
write('ply-list-too-long.ply', ply_binary_header(3, 1) + tri + struct.pack('<B', 200) + struct.pack('<3i', 0, 1, 2),
      "face 0: list 'vertex_indices' claims 200 items")
write('ply-ascii-word.ply', 'ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n'
      'property float z\nend_header\n0 zero 0\n', ":8: vertex 0: expected a number for 'y', found 'zero'")

# --- OBJ ---
write('obj-nan.obj', 'v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n', ':2: expected a finite number')
write('obj-too-few-coordinates.obj', 'v 0 0 0\nv 1 0\n', ":2: 'v' needs three coordinates")
write('obj-index-out-of-range.obj', 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 30\n',
      ':5: face refers to vertex 30 but the file has 3 vertices')
write('obj-zero-index.obj', 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n', 'line 4')

# --- STL ---
stl_triangle = floats(0, 0, 1) + tri + b'\0\0'
write('stl-count-mismatch.stl', b'\0' * 80 + struct.pack('<I', 3) + stl_triangle,
      'byte 80: binary STL declares 3 triangles (234 bytes) but the file has 134 bytes')
write('stl-huge-count.stl', b'\0' * 80 + struct.pack('<I', 4000000000) + stl_triangle, 'declares 4000000000 triangles')
write('stl-nan.stl', b'\0' * 80 + struct.pack('<I', 1) + floats(0, 0, 1) + floats(0, 0, 0, 1, nan, 0, 0, 1, 0) + b'\0\0',
      'byte 108: triangle 0: coordinate is not finite')
write('stl-too-short.stl', b'\0' * 40, 'too short for a binary header')
write('stl-ascii-unterminated.stl', 'solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n'
      'vertex 0 1 0\nendloop\nendfacet\n', "file ends inside a solid (no 'endsolid')")
write('stl-ascii-word.stl', 'solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 zero\n', ":4: expected a number, found 'zero'")


# --- glTF / GLB ---
def glb(document, binary):
    text = json.dumps(document).encode()
    text += b' ' * (-len(text) % 4)
    binary += b'\0' * (-len(binary) % 4)
    total = 12 + 8 + len(text) + 8 + len(binary)
    return (b'glTF' + struct.pack('<II', 2, total) + struct.pack('<I', len(text)) + b'JSON' + text +
            struct.pack('<I', len(binary)) + b'BIN\0' + binary)


def triangle_document():
    return {
        'asset': {'version': '2.0'}, 'scene': 0, 'scenes': [{'nodes': [0]}],
        'nodes': [{'mesh': 0}],
        'meshes': [{'primitives': [{'attributes': {'POSITION': 0}, 'indices': 1}]}],
        'buffers': [{'byteLength': 44}],
        'bufferViews': [{'buffer': 0, 'byteOffset': 0, 'byteLength': 36},
                        {'buffer': 0, 'byteOffset': 36, 'byteLength': 6}],
        'accessors': [{'bufferView': 0, 'componentType': 5126, 'count': 3, 'type': 'VEC3',
                       'min': [0, 0, 0], 'max': [1, 1, 0]},
                      {'bufferView': 1, 'componentType': 5123, 'count': 3, 'type': 'SCALAR'}],
    }


good_binary = tri + struct.pack('<3H', 0, 1, 2)
good = glb(triangle_document(), good_binary)
bad_version = bytearray(good)
bad_version[4] = 1
write('glb-bad-version.glb', bytes(bad_version), 'byte 4: GLB version 1 (expected 2)')
write('glb-truncated.glb', good[:-10], 'byte 8: GLB header says')
doc = triangle_document()
doc['accessors'][0]['count'] = 300
write('glb-accessor-overrun.glb', glb(doc, good_binary), 'do not fit in bufferView 0 (36 bytes), file byte')
write('glb-index-out-of-range.glb', glb(triangle_document(), tri + struct.pack('<3H', 0, 1, 3)),
      'index 3 out of range (3 vertices)')
doc = triangle_document()
doc['nodes'] = [{'mesh': 0, 'children': [1]}, {'children': [0]}]
write('glb-cycle.glb', glb(doc, good_binary), 'node 0 appears twice in the hierarchy')
write('glb-nan.glb', glb(triangle_document(), floats(0, 0, 0, 1, 0, 0, nan, 1, 0) + struct.pack('<3H', 0, 1, 2)),
      'POSITION 2 is not finite')
doc = triangle_document()
doc['accessors'][0] = {'componentType': 5126, 'count': 10**12, 'type': 'VEC3',
                       'sparse': {'count': 0, 'indices': {'bufferView': 1, 'componentType': 5125},
                                  'values': {'bufferView': 0}}}
write('glb-huge-count.glb', glb(doc, good_binary), '1000000000000 elements without a bufferView')
doc = triangle_document()
doc['buffers'][0]['byteLength'] = 0  # tinygltf throws std::out_of_range on this one
write('glb-empty-buffer.glb', glb(doc, good_binary), 'tinygltf cannot parse the file')
doc = triangle_document()
doc['buffers'][0]['byteLength'] = 48
overrun = bytearray(glb(doc, good_binary))
chunk = len(overrun) - 8 - (len(good_binary) + -len(good_binary) % 4)
overrun[chunk:chunk + 4] = struct.pack('<I', 48)  # 4 bytes more than the file holds
write('glb-bin-chunk-overrun.glb', bytes(overrun), 'BIN chunk of 48 bytes runs past the end of the file')
write('glb-buffer-beyond-bin.glb', glb(doc, good_binary), 'Must be equal or less than binary size')
write('gltf-not-json.gltf', 'this is not glTF', 'byte 0: neither GLB')
write('gltf-broken-json.gltf', '{"asset": {"version": "2.0"}, "nodes": [', 'gltf-broken-json.gltf')

with open(os.path.join(here, 'expected.tsv'), 'w') as f:
    f.write('# file\tfragment of the error message (see make_corpus.py)\n')
    for name, fragment in expected:
        f.write('%s\t%s\n' % (name, fragment))
