#!/usr/bin/env python3
"""Regenerates the web-delivery glTF test files of tests/importers_gltf/test_web.c.

    python3 tests/importers_gltf/data/make_web.py [--gltf-transform PATH]

web-base.glb, a UV sphere with normals, uvs, u16 indices, an RGBA base colour
texture and an RGB emissive texture (float data, PNG images), is written here;
every other file is an encoding of it:
  web-draco.glb          gltf-transform draco (POSITION 14, NORMAL 10, TEXCOORD 12 bits)
  web-meshopt.glb        gltf-transform meshopt --level high (same bit depths)
  web-gltfpack.glb       gltfpack -cc (POSITION 14, NORMAL 8, TEXCOORD 12 bits; required)
  web-gltfpack-fallback.glb  gltfpack -cc -cf (meshopt used, not required: fallback buffer)
  web-webp-lossless.glb  both images as lossless WebP (cwebp -lossless), EXT_texture_webp required
  web-webp-lossy.glb     both images as lossy WebP (cwebp -q 90), EXT_texture_webp required
  web-webp-fallback.glb  WebP and the PNG both present, the extension used but not required
  basisu-fallback.gltf   KHR_texture_basisu used, not required, with a PNG fallback source
  basisu-required.gltf   KHR_texture_basisu required (refused)
  unlit-quads.gltf       KHR_materials_unlit quads (plain and vertex-coloured) before a lit wall
  web-gltfpack-nomeshopt.glb  web-gltfpack-fallback.glb without the extension: reads the fallback
  bad-*.glb              lying, truncated and corrupt compressed data (each refused in one line;
                         what each breaks is in BAD below)
  webp-corrupt-fallback.glb  a WebP that does not decode, with a PNG fallback (the PNG is used)
Tools: Debian's gltfpack and webp (cwebp) packages, and the npm package
@gltf-transform/cli 4.5.1 (npm install @gltf-transform/cli@4.5.1; pass its
bin/gltf-transform with --gltf-transform). Output is deterministic for fixed tool
versions.
"""
import argparse, base64, json, math, os, struct, subprocess, tempfile, zlib

HERE = os.path.dirname(os.path.abspath(__file__))


def png(w, h, channels, pixel):
    raw = b"".join(b"\0" + bytes(c for x in range(w) for c in pixel(x, y)) for y in range(h))
    def chunk(t, d):
        return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
    ct = 6 if channels == 4 else 2
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, ct, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def glb(doc, binary):
    j = json.dumps(doc, separators=(",", ":")).encode()
    j += b" " * (-len(j) % 4)
    binary += b"\0" * (-len(binary) % 4)
    out = struct.pack("<I", len(j)) + b"JSON" + j + struct.pack("<I", len(binary)) + b"BIN\0" + binary
    return b"glTF" + struct.pack("<II", 2, 12 + len(out)) + out


def read_glb(path):
    d = open(path, "rb").read()
    jl = struct.unpack_from("<I", d, 12)[0]
    doc = json.loads(d[20:20 + jl])
    bl = struct.unpack_from("<I", d, 20 + jl)[0]
    return doc, d[28 + jl:28 + jl + bl]


def sphere(rings=12, segments=16):
    pos, nrm, uv, idx = [], [], [], []
    for r in range(rings + 1):
        th = math.pi * r / rings
        for s in range(segments + 1):
            ph = 2 * math.pi * s / segments
            n = (math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph))
            nrm.append(n)
            pos.append((0.8 * n[0] + 0.1, 0.8 * n[1] - 0.2, 0.8 * n[2] + 0.3))
            uv.append((s / segments, r / rings))
    for r in range(rings):
        for s in range(segments):
            a, b = r * (segments + 1) + s, (r + 1) * (segments + 1) + s
            if r > 0: idx += [a, a + 1, b]
            if r < rings - 1: idx += [a + 1, b + 1, b]
    return pos, nrm, uv, idx


def base_doc(images, rings=12, segments=16):
    pos, nrm, uv, idx = sphere(rings, segments)
    blob = bytearray()
    views, accessors = [], []
    def add(data, count, type_, ct, extra=None):
        while len(blob) % 4: blob.append(0)
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)})
        blob.extend(data)
        a = {"bufferView": len(views) - 1, "componentType": ct, "count": count, "type": type_}
        a.update(extra or {})
        accessors.append(a)
    flat = lambda v: [c for e in v for c in e]
    add(struct.pack("<%df" % (3 * len(pos)), *flat(pos)), len(pos), "VEC3", 5126,
        {"min": [min(p[i] for p in pos) for i in range(3)], "max": [max(p[i] for p in pos) for i in range(3)]})
    add(struct.pack("<%df" % (3 * len(nrm)), *flat(nrm)), len(nrm), "VEC3", 5126)
    add(struct.pack("<%df" % (2 * len(uv)), *flat(uv)), len(uv), "VEC2", 5126)
    big = len(pos) > 65535
    add(struct.pack("<%d%s" % (len(idx), "I" if big else "H"), *idx), len(idx), "SCALAR", 5125 if big else 5123)
    image_json = []
    for mime, data in images:
        while len(blob) % 4: blob.append(0)
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)})
        blob.extend(data)
        image_json.append({"bufferView": len(views) - 1, "mimeType": mime})
    doc = {
        "asset": {"version": "2.0", "generator": "iris tests/importers_gltf/data/make_web.py"},
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0, "name": "sphere"}],
        "meshes": [{"name": "sphere", "primitives": [
            {"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3, "material": 0}]}],
        "materials": [{"name": "web", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0.5,
                                                             "roughnessFactor": 0.4},
                       "emissiveTexture": {"index": 1}, "emissiveFactor": [0.5, 0.5, 0.5]}],
        "samplers": [{"magFilter": 9729, "minFilter": 9729}],
        "textures": [{"source": 0, "sampler": 0}, {"source": 1, "sampler": 0}],
        "images": image_json, "bufferViews": views, "accessors": accessors,
        "buffers": [{"byteLength": len(blob)}],
    }
    return doc, bytes(blob)


# Smooth images (lossy WebP is compared with them by PSNR): gradients, and
# an alpha ramp so that the WebP is RGBA.
def rgba(x, y):
    return (8 * x, 255 - 8 * y, 4 * (x + y), 128 + 4 * x)


def rgb(x, y):
    return (8 * x, 8 * y, 128 + int(100 * math.sin(x / 5.0) * math.cos(y / 7.0)))


def cwebp(png_bytes, args, tmp):
    src, dst = os.path.join(tmp, "in.png"), os.path.join(tmp, "out.webp")
    open(src, "wb").write(png_bytes)
    subprocess.run(["cwebp", "-quiet", *args, src, "-o", dst], check=True)
    return open(dst, "rb").read()


def webp_doc(pngs, webps, required, fallback):
    images = [("image/png", p) for p in pngs] if fallback else []
    first_webp = len(images)
    images += [("image/webp", w) for w in webps]
    doc, blob = base_doc(images)
    for i, t in enumerate(doc["textures"]):
        t["extensions"] = {"EXT_texture_webp": {"source": first_webp + i}}
        if fallback: t["source"] = i
        else: del t["source"]
    doc["extensionsUsed"] = ["EXT_texture_webp"]
    if required: doc["extensionsRequired"] = ["EXT_texture_webp"]
    return glb(doc, blob)


def basisu_doc(required):
    pos = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
    uvs = struct.pack("<6f", 0, 0, 1, 0, 0, 1)
    buf = pos + uvs
    tex = png(4, 4, 3, rgb)
    d = {
        "asset": {"version": "2.0", "generator": "iris tests/importers_gltf/data/make_web.py"},
        "extensionsUsed": ["KHR_texture_basisu"],
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0}}],
        "buffers": [{"byteLength": len(buf), "uri": "data:application/octet-stream;base64," + base64.b64encode(buf).decode()}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 24}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
                      {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}],
        # Not a real KTX2 file: only the fallback is ever read.
        "images": [{"uri": "data:application/octet-stream;base64," + base64.b64encode(b"\xabKTX 20\xbb\r\n\x1a\n").decode(),
                    "mimeType": "image/ktx2"},
                   {"uri": "data:image/png;base64," + base64.b64encode(tex).decode(), "mimeType": "image/png"}],
        "textures": [{"extensions": {"KHR_texture_basisu": {"source": 0}}}],
    }
    if required:
        d["extensionsRequired"] = ["KHR_texture_basisu"]
        d["images"] = d["images"][:1]
    else:
        d["textures"][0]["source"] = 1
    return json.dumps(d, indent=1) + "\n"


def edit_glb(src, dst, edit_doc=None, edit_bin=None):
    doc, binary = read_glb(src)
    if edit_doc: edit_doc(doc)
    if edit_bin: binary = edit_bin(doc, bytearray(binary))
    open(dst, "wb").write(glb(doc, bytes(binary)))


def strip_meshopt(doc):
    for v in doc["bufferViews"]:
        v.pop("extensions", None)
    for b in doc["buffers"]:
        b.pop("extensions", None)
    doc["extensionsUsed"].remove("EXT_meshopt_compression")


def draco_ext(doc):
    return doc["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]


def meshopt_view(doc, mode, filter_=None):
    for v in doc["bufferViews"]:
        e = v.get("extensions", {}).get("EXT_meshopt_compression")
        if e and e["mode"] == mode and e.get("filter") == filter_:
            return e


def zero_range(doc, binary, start, length):
    binary[start:start + length] = bytes(length)
    return binary


def image_view(doc, i):
    return doc["bufferViews"][doc["images"][i]["bufferView"]]


def set_bytes(binary, at, data):
    binary[at:at + len(data)] = data
    return binary


def draco_view(doc):
    return doc["bufferViews"][draco_ext(doc)["bufferView"]]


BAD = {
    # Draco: an accessor lying about the point count, a truncated stream, a broken header,
    # an attribute id that is not in the stream, indices declaring the wrong count.
    "bad-draco-count.glb": ("web-draco.glb", lambda d: d["accessors"][1].update(count=218), None),
    "bad-draco-truncated.glb": ("web-draco.glb", lambda d: draco_view(d).update(byteLength=draco_view(d)["byteLength"] // 2), None),
    "bad-draco-header.glb": ("web-draco.glb", None, lambda d, b: zero_range(d, b, draco_view(d)["byteOffset"], 8)),
    "bad-draco-attribute-id.glb": ("web-draco.glb", lambda d: draco_ext(d)["attributes"].update(NORMAL=7), None),
    "bad-draco-indices.glb": ("web-draco.glb", lambda d: d["accessors"][0].update(count=1053), None),
    "bad-draco-type.glb": ("web-draco.glb", lambda d: d["accessors"][3].update(type="VEC3"), None),
    # meshopt: truncated data, a count that no longer matches the view, a corrupt stream,
    # a filter the stride does not allow, an unknown mode.
    "bad-meshopt-truncated.glb": ("web-meshopt.glb", lambda d: meshopt_view(d, "ATTRIBUTES", "OCTAHEDRAL").update(byteLength=100), None),
    "bad-meshopt-count.glb": ("web-meshopt.glb", lambda d: meshopt_view(d, "TRIANGLES").update(count=1059), None),
    "bad-meshopt-corrupt.glb": ("web-meshopt.glb", None, lambda d, b: zero_range(d, b, meshopt_view(d, "TRIANGLES")["byteOffset"], 1)),
    "bad-meshopt-filter.glb": ("web-meshopt.glb", lambda d: meshopt_view(d, "ATTRIBUTES", "OCTAHEDRAL").update(filter="QUATERNION"), None),
    "bad-meshopt-mode.glb": ("web-meshopt.glb", lambda d: meshopt_view(d, "TRIANGLES").update(mode="STRIPS"), None),
    # WebP: image 0 cut to 40 bytes; image 0's lossless header declaring 16384 x 16384 pixels;
    # the same cut with a PNG fallback (imports, using the PNG).
    "bad-webp-truncated.glb": ("web-webp-lossy.glb", lambda d: image_view(d, 0).update(byteLength=40), None),
    "bad-webp-dims.glb": ("web-webp-lossless.glb", None, lambda d, b: set_bytes(b, image_view(d, 0)["byteOffset"] + 21, b"\xff\xff\xff\x0f")),
    "webp-corrupt-fallback.glb": ("web-webp-fallback.glb", lambda d: image_view(d, 2).update(byteLength=40), None),
}


def unlit_doc():
    """Two quads facing +z, KHR_materials_unlit: x in [-1, 0] base colour (0.2, 0.5, 0.8);
    x in [0, 1] base colour (0.8, 0.6, 0.4) times COLOR_0 (0.5, 1, 0.25) at every vertex;
    behind them (z = -0.5) a lit white diffuse quad, so the lighting is visible elsewhere."""
    def quad(x0, x1, z):
        return struct.pack("<12f", x0, -1, z, x1, -1, z, x1, 1, z, x0, 1, z)
    buf = quad(-1, 0, 0) + quad(0, 1, 0) + quad(-3, 3, -0.5) + struct.pack("<12f", *([0.5, 1, 0.25] * 4)) + \
        struct.pack("<6H", 0, 1, 2, 0, 2, 3)
    views = [{"buffer": 0, "byteOffset": 48 * i, "byteLength": 48} for i in range(4)] + \
        [{"buffer": 0, "byteOffset": 192, "byteLength": 12}]
    acc = [{"bufferView": i, "componentType": 5126, "count": 4, "type": "VEC3"} for i in range(4)] + \
        [{"bufferView": 4, "componentType": 5123, "count": 6, "type": "SCALAR"}]
    for i, (x0, x1, z) in enumerate([(-1, 0, 0), (0, 1, 0), (-3, 3, -0.5)]):
        acc[i]["min"], acc[i]["max"] = [x0, -1, z], [x1, 1, z]
    d = {
        "asset": {"version": "2.0", "generator": "iris tests/importers_gltf/data/make_web.py"},
        "extensionsUsed": ["KHR_materials_unlit"],
        "scene": 0, "scenes": [{"nodes": [0, 1, 2, 3]}],
        "nodes": [{"mesh": 0}, {"mesh": 1}, {"mesh": 2}, {"camera": 0, "translation": [0, 0, 4], "name": "front"}],
        # sees x, y in [-1.25, 1.25] at z = 0: the wall shows around the quads
        "cameras": [{"type": "perspective", "perspective": {"yfov": 2 * math.atan(1.25 / 4), "aspectRatio": 1,
                                                            "znear": 0.1}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 4, "material": 0}]},
                   {"primitives": [{"attributes": {"POSITION": 1, "COLOR_0": 3}, "indices": 4, "material": 1}]},
                   {"primitives": [{"attributes": {"POSITION": 2}, "indices": 4, "material": 2}]}],
        "materials": [
            {"name": "unlit-blue", "pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.5, 0.8, 1], "metallicFactor": 0.3},
             "emissiveFactor": [1, 0, 0], "extensions": {"KHR_materials_unlit": {}}},
            {"name": "unlit-vertex", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.6, 0.4, 1]},
             "extensions": {"KHR_materials_unlit": {}}},
            {"name": "wall", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1], "metallicFactor": 0}}],
        "buffers": [{"byteLength": len(buf), "uri": "data:application/octet-stream;base64," + base64.b64encode(buf).decode()}],
        "bufferViews": views, "accessors": acc,
    }
    return json.dumps(d, indent=1) + "\n"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gltf-transform", default="gltf-transform")
    a = ap.parse_args()
    out = lambda n: os.path.join(HERE, n)
    pngs = [png(32, 32, 4, rgba), png(32, 32, 3, rgb)]
    doc, blob = base_doc([("image/png", p) for p in pngs])
    open(out("web-base.glb"), "wb").write(glb(doc, blob))
    gt = a.gltf_transform
    subprocess.run([gt, "draco", out("web-base.glb"), out("web-draco.glb")], check=True, stdout=subprocess.DEVNULL)
    subprocess.run([gt, "meshopt", "--level", "high", out("web-base.glb"), out("web-meshopt.glb")], check=True,
                   stdout=subprocess.DEVNULL)
    subprocess.run(["gltfpack", "-cc", "-i", out("web-base.glb"), "-o", out("web-gltfpack.glb")], check=True,
                   stdout=subprocess.DEVNULL)
    subprocess.run(["gltfpack", "-cc", "-cf", "-i", out("web-base.glb"), "-o", out("web-gltfpack-fallback.glb")],
                   check=True, stdout=subprocess.DEVNULL)
    with tempfile.TemporaryDirectory() as tmp:
        lossless = [cwebp(p, ["-lossless", "-exact"], tmp) for p in pngs]
        lossy = [cwebp(p, ["-q", "90"], tmp) for p in pngs]
    open(out("web-webp-lossless.glb"), "wb").write(webp_doc(pngs, lossless, True, False))
    open(out("web-webp-lossy.glb"), "wb").write(webp_doc(pngs, lossy, True, False))
    open(out("web-webp-fallback.glb"), "wb").write(webp_doc(pngs, lossy, False, True))
    open(out("basisu-fallback.gltf"), "w").write(basisu_doc(False))
    open(out("unlit-quads.gltf"), "w").write(unlit_doc())
    edit_glb(out("web-gltfpack-fallback.glb"), out("web-gltfpack-nomeshopt.glb"), strip_meshopt)
    for name, (src, edit_doc, edit_bin) in BAD.items():
        edit_glb(out(src), out(name), edit_doc, edit_bin)
    open(out("basisu-required.gltf"), "w").write(basisu_doc(True))


if __name__ == "__main__":
    main()
