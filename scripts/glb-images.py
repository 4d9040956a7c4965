#!/usr/bin/env python3
"""Writes the images embedded in GLB files into a folder, one file per image named
<glb stem>_<image index>.<png|jpg|webp>: for comparing the texture pages of two tilesets
(`lodforge compare` pairs frames by name without the extension). Usage: glb-images.py OUT GLB..."""
import json
import os
import struct
import sys

EXTENSIONS = {"image/png": "png", "image/jpeg": "jpg", "image/webp": "webp"}


def images_of(path):
    data = open(path, "rb").read()
    magic, _, _ = struct.unpack_from("<III", data, 0)
    if magic != 0x46546C67:
        sys.exit(f"{path}: not a GLB")
    length, _ = struct.unpack_from("<II", data, 12)
    gltf = json.loads(data[20:20 + length])
    binary = 20 + length + 8  # the BIN chunk's data follows its 8-byte header
    for index, image in enumerate(gltf.get("images", [])):
        view = gltf["bufferViews"][image["bufferView"]]
        start = binary + view.get("byteOffset", 0)
        yield index, EXTENSIONS[image["mimeType"]], data[start:start + view["byteLength"]]


def main():
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    count = 0
    for path in sys.argv[2:]:
        stem = os.path.splitext(os.path.basename(path))[0]
        for index, extension, data in images_of(path):
            with open(os.path.join(out, f"{stem}_{index}.{extension}"), "wb") as f:
                f.write(data)
            count += 1
    print(count)


if __name__ == "__main__":
    main()
