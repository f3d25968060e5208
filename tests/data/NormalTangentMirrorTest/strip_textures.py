#!/usr/bin/env python3
"""Makes NormalTangentMirrorTest.glb here from the Khronos glTF sample of that name (glTF-Binary form):
the mesh as exported (indices, POSITION, NORMAL, TANGENT, TEXCOORD_0, byte for byte), its three
textures replaced by one 1x1 flat normal map, so that the file stays small and still asks for a
tangent frame. The TANGENT attribute is Blender's MikkTSpace output, the ground truth of
tests/unit/scene/MikkTSpaceTest.cpp.

    python3 strip_textures.py path/to/NormalTangentMirrorTest.glb
"""
import json
import struct
import sys
import zlib
from pathlib import Path


def png_1x1(rgba):
    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)
    raw = b"\x00" + bytes(rgba)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 1, 1, 8, 6, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def main(src):
    data = Path(src).read_bytes()
    magic, version, _ = struct.unpack_from("<4sII", data, 0)
    assert magic == b"glTF" and version == 2
    json_len, _ = struct.unpack_from("<II", data, 12)
    doc = json.loads(data[20:20 + json_len])
    bin_len, _ = struct.unpack_from("<II", data, 20 + json_len)
    blob = data[28 + json_len:28 + json_len + bin_len]

    # Keep the mesh's five buffer views (they come first), drop the images' views.
    views = doc["bufferViews"][:5]
    end = max(v["byteOffset"] + v["byteLength"] for v in views)
    mesh = bytearray(blob[:end])
    while len(mesh) % 4:
        mesh.append(0)
    png = png_1x1((128, 128, 255, 255))
    views.append({"buffer": 0, "byteOffset": len(mesh), "byteLength": len(png)})
    mesh += png
    while len(mesh) % 4:
        mesh.append(0)
    doc["bufferViews"] = views
    doc["buffers"] = [{"byteLength": len(mesh)}]
    doc["images"] = [{"bufferView": 5, "mimeType": "image/png"}]
    doc["textures"] = [{"source": 0}]
    doc.pop("samplers", None)
    doc["materials"] = [{"doubleSided": True, "name": "Material", "normalTexture": {"index": 0}}]
    doc["asset"]["extras"] = {"radiant": "geometry of the Khronos sample NormalTangentMirrorTest; textures replaced "
                                         "by a 1x1 flat normal map (tests/data/NormalTangentMirrorTest/strip_textures.py)"}
    text = json.dumps(doc, separators=(",", ":")).encode()
    while len(text) % 4:
        text += b" "
    out = (struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(text) + 8 + len(mesh))
           + struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(mesh), 0x004E4942) + bytes(mesh))
    (Path(__file__).parent / "NormalTangentMirrorTest.glb").write_bytes(out)


if __name__ == "__main__":
    main(sys.argv[1])
