#!/usr/bin/env python3
"""Writes the inputs that crashed radiantd, gave a 500 or exhausted its memory (issue #13), one
file each, into requests/ (POST /v1/renders bodies), gltf/ (scene uploads) and http/ (raw HTTP
requests). They are the regression tests of the normal suite (tests/unit/scene/CrashersTest.cpp,
tests/http/hostile) and the seed corpora of the fuzzers (fuzz/, scripts/fuzz.sh). A fuzzer's new
crash is added here by copying its file into the matching folder."""
import json, os, struct

here = os.path.dirname(os.path.abspath(__file__))

def write(sub, name, data):
    os.makedirs(os.path.join(here, sub), exist_ok=True)
    with open(os.path.join(here, sub, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())

# ---- requests
write("requests", "nested_arrays_50000.json", "[" * 50000 + "]" * 50000)
write("requests", "nested_objects_10000.json", '{"a":' * 10000 + "1" + "}" * 10000)
write("requests", "nested_in_passes.json", '{"scene":{"builtin":"cornell_box"},"passes":{"direct":' + '[{"x":' * 10000)
write("requests", "exposure_1e400.json", '{"scene":{"builtin":"cornell_box"},"exposure":1e400}')
write("requests", "camera_1e308_reference.json",
      '{"scene":{"builtin":"cornell_box"},"width":16,"height":16,"camera":{"position":[1e308,0,0]},"passes":{"reference":{"spp":1}}}')
write("requests", "non_ascii_value.json", '{"scene":{"builtin":"' + "\u00e9" * 100 + '"}}')
write("requests", "invalid_utf8_value.json", b'{"scene":{"builtin":"cornell\xff"}}')
write("requests", "duplicate_aovs.json", json.dumps({"scene": {"builtin": "cornell_box"}, "width": 2048, "height": 2048,
      "outputs": [{"format": "exr", "aovs": ["beauty"] * 16}] * 8}))
write("requests", "compare_aov_any_string.json", '{"scene":{"builtin":"cornell_box"},"compare":{"aov":"anything"}}')
write("requests", "up_parallel.json", '{"scene":{"builtin":"cornell_box"},"camera":{"position":[0,1,3],"target":[0,1,0],"up":[0,0,-1e-30]}}')

# ---- glTF
asset = '"asset":{"version":"2.0"}'
write("gltf", "extras_nested_20000.gltf", '{' + asset + ',"extras":' + "[" * 20000 + "]" * 20000 + "}")
write("gltf", "extras_objects_15000.gltf", '{' + asset + ',"extras":' + '{"e":' * 15000 + "0" + "}" * 15000 + "}")
write("gltf", "name_0xff.gltf", b'{"asset":{"version":"2.0"},"nodes":[{"name":"N\xffME"}],"scenes":[{"nodes":[0]}],"scene":0}')
write("gltf", "camera_translation_1e39.gltf", json.dumps({"asset": {"version": "2.0"},
      "cameras": [{"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.1}}],
      "nodes": [{"camera": 0, "translation": [1e39, 0, 0]}], "scenes": [{"nodes": [0]}], "scene": 0}).replace("1e+39", "1e39"))
write("gltf", "accessor_without_view_2e7.gltf", json.dumps({"asset": {"version": "2.0"},
      "accessors": [{"componentType": 5126, "count": 20000001, "type": "VEC3"}],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
      "nodes": [{"mesh": 0} for _ in range(20)], "scenes": [{"nodes": list(range(20))}], "scene": 0}))

def glb(doc, bin_):
    j = json.dumps(doc).encode()
    j += b" " * (-len(j) % 4)
    bin_ += b"\0" * (-len(bin_) % 4)
    total = 12 + 8 + len(j) + (8 + len(bin_) if bin_ else 0)
    out = b"glTF" + struct.pack("<II", 2, total) + struct.pack("<I", len(j)) + b"JSON" + j
    if bin_:
        out += struct.pack("<I", len(bin_)) + b"BIN\0" + bin_
    return out

def image_glb(image, mime):
    doc = {"asset": {"version": "2.0"}, "buffers": [{"byteLength": len(image)}],
           "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(image)}],
           "images": [{"bufferView": 0, "mimeType": mime}], "textures": [{"source": 0}]}
    return glb(doc, image)

bmp = b"BM" + struct.pack("<IIII", 70, 0, 54, 40) + struct.pack("<iiHHIIiiII", 16384, 16384, 1, 24, 0, 0, 2835, 2835, 0, 0) + b"\0" * 16
write("gltf", "bmp_16384_squared.glb", image_glb(bmp, "image/bmp"))
gif = b"GIF89a" + struct.pack("<HH", 16384, 16384) + b"\0\0\0" + b"\0" * 16
write("gltf", "gif_16384_squared.glb", image_glb(gif, "image/gif"))
jpeg = b"\xff\xd8\xff\xc0" + struct.pack(">HBHH", 17, 8, 16384, 16384) + b"\x03\x01\x11\x00\x02\x11\x00\x03\x11\x00\xff\xd9"
write("gltf", "jpeg_16384_squared.glb", image_glb(jpeg, "image/jpeg"))
json_ff = glb({"asset": {"version": "2.0"}, "nodes": [{"name": "NAME"}]}, b"").replace(b"NAME", b"N\xffME")
write("gltf", "glb_json_chunk_0xff.glb", json_ff)

# EXT_meshopt_compression (issue 30): a filter whose stride does not fit aborted radiantd inside
# meshoptimizer (Debian keeps its asserts); "mode": 5 and "filter": [] gave no pointer; a view that
# decodes to 1 GiB from 64 bytes was not charged against --max-decode-bytes.
def meshopt_zero_attributes(count, stride):
    """A valid mode-0 (ATTRIBUTES) stream of `count` zero elements (the README's Appendix A): header
    0xa0, per block one all-zero group header per byte of the element, then the tail (baseline)."""
    out = b"\xa0"
    block = min((8192 // stride) & ~15, 256)
    for start in range(0, count, block):
        groups = (min(block, count - start) + 15) // 16
        out += b"\0" * (stride * ((groups + 3) // 4))
    return out + b"\0" * max(stride, 32)

# meshopt_encodeIndexBuffer / meshopt_encodeIndexSequence of the indices (0, 1, 2)
triangles_012 = bytes.fromhex("e0f0007687566778a9866589689801690000")
indices_012 = bytes.fromhex("d000040400000000")

def meshopt_glb(stream, count, stride, fields):
    ext = {"buffer": 0, "byteOffset": 0, "byteLength": len(stream), "byteStride": stride, "count": count}
    ext.update(fields)
    doc = {"asset": {"version": "2.0"}, "extensionsUsed": ["EXT_meshopt_compression"],
           "extensionsRequired": ["EXT_meshopt_compression"],
           "buffers": [{"byteLength": len(stream)},
                       {"byteLength": count * stride, "extensions": {"EXT_meshopt_compression": {"fallback": True}}}],
           "bufferViews": [{"buffer": 1, "byteOffset": 0, "byteLength": count * stride,
                            "extensions": {"EXT_meshopt_compression": ext}}]}
    return glb(doc, stream)

write("gltf", "meshopt_quaternion_stride4.glb", meshopt_glb(meshopt_zero_attributes(3, 4), 3, 4, {"mode": "ATTRIBUTES", "filter": "QUATERNION"}))
write("gltf", "meshopt_octahedral_stride12.glb", meshopt_glb(meshopt_zero_attributes(3, 12), 3, 12, {"mode": "ATTRIBUTES", "filter": "OCTAHEDRAL"}))
write("gltf", "meshopt_octahedral_stride16.glb", meshopt_glb(meshopt_zero_attributes(3, 16), 3, 16, {"mode": "ATTRIBUTES", "filter": "OCTAHEDRAL"}))
write("gltf", "meshopt_exponential_triangles_stride2.glb", meshopt_glb(triangles_012, 3, 2, {"mode": "TRIANGLES", "filter": "EXPONENTIAL"}))
write("gltf", "meshopt_octahedral_triangles_stride2.glb", meshopt_glb(triangles_012, 3, 2, {"mode": "TRIANGLES", "filter": "OCTAHEDRAL"}))
write("gltf", "meshopt_quaternion_indices_stride4.glb", meshopt_glb(indices_012, 3, 4, {"mode": "INDICES", "filter": "QUATERNION"}))
write("gltf", "meshopt_mode_5.glb", meshopt_glb(meshopt_zero_attributes(3, 8), 3, 8, {"mode": 5}))
write("gltf", "meshopt_filter_array.glb", meshopt_glb(meshopt_zero_attributes(3, 8), 3, 8, {"mode": "ATTRIBUTES", "filter": []}))
write("gltf", "meshopt_decodes_1gib.glb", meshopt_glb(b"\x55" * 64, 1 << 22, 256, {"mode": "ATTRIBUTES"}))

# ---- raw HTTP
write("http", "path_0xff.txt", "GET /%ff HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n")
write("http", "path_overlong_slash.txt", "GET /v1/scenes/%c0%af HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n")
write("http", "delete_chunked.txt", "DELETE /v1/renders/x HTTP/1.1\r\nHost: x\r\nTransfer-Encoding: chunked\r\n\r\n10\r\n")
