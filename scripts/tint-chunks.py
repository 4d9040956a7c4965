#!/usr/bin/env python3
"""Tints a reconstructed mesh's vertex colours in a 3D checkerboard of its chunks, so that a
rendering shows where the chunk borders run (docs/surface.md's chunk-border picture).

usage: tint-chunks.py IN.ply OUT.ply OX,OY,OZ EDGE
  IN.ply: a binary PLY as `lodforge reconstruct` writes it (double xyz, float normal, RGBA);
  OX,OY,OZ: the lattice's origin; EDGE: the chunk's edge (voxel x --chunk-size).
"""
import struct
import sys


def main():
    source, target, origin, edge = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
    origin = [float(v) for v in origin.split(",")]
    data = open(source, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii")
    if "property double x" not in header or "property uchar alpha" not in header:
        sys.exit(f"{source}: not a PLY as lodforge reconstruct writes it")
    vertices = int(header.split("element vertex ")[1].split()[0])
    record = struct.Struct("<3d3f4B")
    out = bytearray(data)
    for v in range(vertices):
        at = end + v * record.size
        x, y, z, nx, ny, nz, r, g, b, a = record.unpack_from(data, at)
        cell = sum(int((p - o) // edge) for p, o in zip((x, y, z), origin))
        if cell % 2:  # odd chunks: a warm tint
            r, g, b = min(255, r + 70), min(255, g + 25), max(0, b - 30)
        record.pack_into(out, at, x, y, z, nx, ny, nz, r, g, b, a)
    open(target, "wb").write(out)


if __name__ == "__main__":
    main()
