#!/usr/bin/python3
"""Per-sample cost of the glTF features (docs/performance.md, "glTF features"):
alpha MASK/BLEND, normal mapping, clearcoat and sheen, each against the same
scene without it, as CPU seconds of `iris render` on one thread, interleaved
repeats, median of each. Optionally a second iris binary (e.g. the build of the
commit before these features) renders the opaque, untextured variants too, for
the "opaque scenes keep today's speed" ratio.

  /usr/bin/python3 bench/gltf/bench_features.py --iris build/tools/iris \
      [--baseline OLD/iris] --out /tmp/bench-gltf --spp 16 --size 128 --repeats 5

The scene: SheenCloth (115,200 triangles) under a white sky, with its material
replaced per variant:
  plain      glTF plastic, no textures (the opaque, untextured scene)
  textured   + base colour texture (the file's)
  normal     + its normal map (tangents from the file)
  mask       + alphaMode MASK, cutoff 0.5 (alpha 0.6 from the factor: nothing cut, the filter runs)
  blend      + alphaMode BLEND, alpha 0.999 (almost opaque: the filter runs on every hit)
  clearcoat  + clearcoat 1, roughness 0.1
  sheen      + sheen colour 1, roughness 0.5 (the file's sheen without its textures)
  spectrans  + transmission 0.5, specular 0.8, specular colour (1, 0.9, 0.8) (factors only)
  spectrans-tex  spectrans + transmission, specular and specular colour textures, three
             textures of a white 64x64 PNG (so the paths are those of spectrans: the
             difference is the three lookups)
  spectrans-packed  the same with specular and specular colour as one texture (the
             extension's packed layout: two lookups)
"""
import argparse
import json
import struct
import zlib
import os
import resource
import shutil
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


def variants(base):
    m0 = base["materials"][0]
    plain = {"name": "plain", "type": "gltf", "color": [0.6, 0.5, 0.4], "roughness": 0.5}
    out = {"plain": dict(plain)}
    out["textured"] = dict(plain, color_texture=m0["color_texture"])
    out["normal"] = dict(out["textured"], normal_texture=m0["normal_texture"])
    out["mask"] = dict(plain, alpha_mode="mask", alpha=0.6, alpha_cutoff=0.5)
    out["blend"] = dict(plain, alpha_mode="blend", alpha=0.999)
    out["clearcoat"] = dict(plain, clearcoat=1.0, clearcoat_roughness=0.1)
    out["sheen"] = dict(plain, sheen_color=[1, 1, 1], sheen_roughness=0.5)
    out["spectrans"] = dict(plain, transmission=0.5, specular=0.8, specular_color=[1, 0.9, 0.8])
    white = len(base["textures"])  # three white textures appended by main()
    out["spectrans-tex"] = dict(out["spectrans"], transmission_texture=white, specular_texture=white + 1,
                                specular_color_texture=white + 2)
    out["spectrans-packed"] = dict(out["spectrans"], transmission_texture=white, specular_texture=white + 1,
                                   specular_color_texture=white + 1)
    return out


def write_white_png(path, size=64):
    raw = b"".join(b"\x00" + b"\xff" * 4 * size for _ in range(size))

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data))

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", size, size, 8, 6, 0, 0, 0)) +
                chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def strip_tangents(src, dst):
    """The same mesh file without its tangents (docs/format.md, "Mesh files")."""
    with open(src, "rb") as f:
        b = f.read()
    flags, nv, nt = struct.unpack_from("<III", b, 12)
    sizes = [(1, 12), (2, 8), (4, 12), (8, 8), (16, 16), (32, 4)]  # normals, uvs, colors, uvs1, tangents, alphas
    off, parts = 64 + 12 * nv, [b[64:64 + 12 * nv]]
    for bit, per in sizes:
        if flags & bit:
            if bit != 16:
                parts.append(b[off:off + per * nv])
            off += per * nv
    parts.append(b[off:off + 12 * nt])
    payload = b"".join(parts)
    head = bytearray(b[:64])
    struct.pack_into("<I", head, 12, flags & ~16)
    struct.pack_into("<I", head, 24, zlib.crc32(payload))
    os.makedirs(os.path.dirname(dst), exist_ok=True)
    with open(dst, "wb") as f:
        f.write(bytes(head) + payload)


def cpu_seconds(cmd):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--iris", required=True)
    ap.add_argument("--baseline")
    ap.add_argument("--out", required=True)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--model", default=os.path.join(HERE, "../../../shared/assets/gltf/SheenCloth/glTF/SheenCloth.gltf"))
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    src = os.path.join(a.out, "cloth.json")
    subprocess.run([a.iris, "import", a.model, "-o", src, "--quiet"], check=True)
    with open(src) as f:
        base = json.load(f)
    # variants without a normal map use the mesh without tangents ("the same scene without them")
    strip_tangents(os.path.join(a.out, "cloth.meshes/0.irmesh"), os.path.join(a.out, "plain.meshes/0.irmesh"))
    files = {}
    for name, mat in variants(base).items():
        s = json.loads(json.dumps(base))
        s["materials"] = [mat]
        if name.startswith("spectrans-"):
            for k in range(3):  # three files, so that no two placements are one texture by accident
                white = os.path.join(os.path.abspath(a.out), "white%d.png" % k)
                write_white_png(white)
                s["textures"].append({"file": white})
        if name != "normal":
            s["meshes"][0]["file"] = "plain.meshes/0.irmesh"
            s["meshes"][0]["attributes"] = [x for x in s["meshes"][0]["attributes"] if x != "tangents"]
        s["environment"] = {"radiance": [1, 1, 1]}
        s.pop("render", None)
        path = os.path.join(a.out, "cloth-%s.json" % name)
        with open(path, "w") as f:
            json.dump(s, f, indent=1)
        files[name] = path
    # every variant's JSON sits next to the same cloth.meshes/ and cloth.textures/
    runs = [(name, a.iris, path) for name, path in files.items()]
    if a.baseline:  # the old binary reads only the opaque, untextured scene
        runs.append(("plain@baseline", a.baseline, files["plain"]))
        runs.append(("plain@baseline2", a.iris, files["plain"]))
    times = {name: [] for name, _, _ in runs}
    for rep in range(a.repeats):
        for name, exe, path in runs:
            cmd = [exe, "render", path, "-o", os.path.join(a.out, "out.exr"), "--spp", str(a.spp), "--width",
                   str(a.size), "--height", str(a.size), "--threads", "1", "--quiet", "--method", "mis", "--seed", "1"]
            times[name].append(cpu_seconds(cmd))
    med = {k: statistics.median(v) for k, v in times.items()}
    print("| variant | CPU s (median of %d) | vs plain |" % a.repeats)
    print("|---|---|---|")
    for name in times:
        ref = med["plain"]
        if name == "plain@baseline":
            ref = med["plain@baseline2"]
        print("| %s | %.3f | %.3f |" % (name, med[name], med[name] / ref))
    with open(os.path.join(a.out, "bench.json"), "w") as f:
        json.dump({"spp": a.spp, "size": a.size, "times": times, "median": med}, f, indent=1)


main()
