#!/usr/bin/env python3
"""An independent reader of trisort's baked files and ORDER files, written from docs/FORMAT.md
alone (no trisort code): parses every field and prints counts as JSON.

    python3 docs/format_reader.py FILE.baked     # or an ORDER file (export-order)

Needs Python 3.8+ and the `zstandard` module (Debian: python3-zstandard). The container's
BLAKE3 checksum is not verified (Python's standard library has no BLAKE3); lengths are.
Exit status 1 with a message on anything that does not follow the specification.
"""
import json
import struct
import sys

# Versions this reader understands (FORMAT.md § Compatibility): 7; 6 (no texture blocks); 5
# (no clips); 4 (no raster
# profile in
# `Robust`); 3 (no vertex tangent and
# uv1, no material texture slots and PBR factors, no texture colour space and mips, no
# environment); 2 (no `robust`, no `Geometry.variants`, no `fps` either).
FORMAT_VERSIONS = (2, 3, 4, 5, 6, 7)
ORDER_VERSION = 1


class Bad(Exception):
    pass


class Postcard:
    """Reads postcard's encoding (FORMAT.md § Payload encoding)."""

    def __init__(self, data):
        self.data = data
        self.at = 0

    def take(self, n):
        if self.at + n > len(self.data):
            raise Bad("payload ends inside a field at byte %d" % self.at)
        b = self.data[self.at:self.at + n]
        self.at += n
        return b

    def varint(self, bits):
        value, shift = 0, 0
        while True:
            byte = self.take(1)[0]
            value |= (byte & 0x7F) << shift
            shift += 7
            if not byte & 0x80:
                break
            if shift >= bits + 7:
                raise Bad("varint longer than %d bits" % bits)
        if value >> bits:
            raise Bad("varint overflows %d bits" % bits)
        return value

    def u16(self):
        return self.varint(16)

    def u32(self):
        return self.varint(32)

    def u64(self):
        return self.varint(64)

    def i32(self):
        z = self.varint(32)
        return (z >> 1) ^ -(z & 1)

    def f32(self):
        return struct.unpack("<f", self.take(4))[0]

    def f64(self):
        return struct.unpack("<d", self.take(8))[0]

    def boolean(self):
        b = self.take(1)[0]
        if b > 1:
            raise Bad("bool byte %d" % b)
        return b == 1

    def option(self, read):
        return read() if self.boolean() else None

    def seq(self, read):
        return [read() for _ in range(self.u64())]

    def string(self):
        return self.take(self.u64()).decode("utf-8")

    def bytes(self):
        return self.take(self.u64())

    def array(self, read, n):
        return [read() for _ in range(n)]

    def enum(self, names):
        k = self.u32()
        if k >= len(names):
            raise Bad("enum index %d beyond %s" % (k, names))
        return names[k]


STRATEGY = ["lib", "lbi", "ilb", "ibl", "bli", "bil"]
LAYOUT = ["paper", "compact"]
BRIDGE = ["hidden", "ignored", "visible"]
SEEDING = ["interval", "paper"]
ALPHA_MODE = ["Opaque", "Mask", "Blend"]
BLOCK_FORMAT = ["Etc2Rgb8", "Etc2Rgba8", "Astc4x4", "Bc7"]
PROFILE_NAME = ["exact", "conformant", "snap4", "browser"]
DEPTH_AT = ["sample", "pixel"]


def read_baked(p, version):
    """The Baked payload, field by field (FORMAT.md § Baked)."""
    b = {}
    b["tool_version"] = p.string()
    b["scene_hash"] = p.take(32).hex()
    b["path_hash"] = p.take(32).hex()
    b["recording_hashes"] = p.seq(lambda: p.take(32).hex())
    b["settings"] = {
        "width": p.u32(), "height": p.u32(), "samples": p.u32(), "saturation": p.f32(),
        "glass_opacity": p.f32(), "max_layers": p.u32(), "split_intersections": p.boolean(),
    }
    if version >= 3:
        b["settings"]["robust"] = {"patterns": p.u32(), "tolerance": p.f32(),
                                   "conservative": p.boolean()}
        if version >= 5:
            b["settings"]["robust"]["profile"] = {
                "name": p.enum(PROFILE_NAME), "subpixel_bits_min": p.u32(),
                "subpixel_bits_max": p.u32(), "depth_at": p.enum(DEPTH_AT)}
    b["device"] = {"adapter": p.string(), "driver": p.string(), "backend": p.string()}
    merge = {
        "strategy": p.enum(STRATEGY), "layout": p.enum(LAYOUT), "bridge": p.enum(BRIDGE),
        "depth_only": p.boolean(), "segment": p.option(p.u32), "seeding": p.enum(SEEDING),
    }
    merge["cells"] = p.seq(lambda: (p.u32(), p.u32(), p.u32(), p.u32()))
    b["merge"] = merge
    names = ["index_triangles", "source_triangles", "unique_visible", "draws_per_frame_mean",
             "draws_per_frame_max", "drawn_not_visible_mean", "unordered_samples", "seconds",
             "cell_constraint_edges", "cell_constraint_edges_reduced", "exact_components",
             "heuristic_components", "heuristic_unordered_samples"]
    kinds = [p.u64, p.u64, p.u64, p.f64, p.u32, p.f64, p.u64, p.f64, p.u64, p.u64, p.u64,
             p.u64, p.u64]
    b["stats"] = {n: k() for n, k in zip(names, kinds)}
    g = {}
    if version >= 4:
        g["vertices"] = p.seq(lambda: (p.array(p.f32, 3), p.array(p.f32, 3), p.array(p.f32, 2),
                                       p.u32(), p.u32(), p.array(p.f32, 4), p.array(p.f32, 2)))
    else:
        g["vertices"] = p.seq(lambda: (p.array(p.f32, 3), p.array(p.f32, 3),
                                       p.array(p.f32, 2), p.u32(), p.u32()))
    g["triangles"] = p.seq(lambda: p.array(p.u32, 3))
    transform = lambda: {"offset": p.array(p.f32, 2), "rotation": p.f32(),
                         "scale": p.array(p.f32, 2)}
    slot = lambda: p.option(lambda: {"texture": p.u32(), "tex_coord": p.u32(),
                                     "transform": transform()})

    def material():
        m = {"name": p.string(), "base_color": p.array(p.f32, 4),
             "base_color_texture": p.option(p.u32), "alpha_mode": p.enum(ALPHA_MODE),
             "alpha_cutoff": p.f32(), "double_sided": p.boolean(),
             "emissive": p.array(p.f32, 3), "transmission": p.f32()}
        if version >= 4:
            m.update({"base_color_tex_coord": p.u32(), "base_color_transform": transform(),
                      "metallic": p.f32(), "roughness": p.f32(),
                      "metallic_roughness_texture": slot(), "normal_texture": slot(),
                      "normal_scale": p.f32(), "occlusion_texture": slot(),
                      "occlusion_strength": p.f32(), "emissive_texture": slot(),
                      "clearcoat": p.f32(), "clearcoat_roughness": p.f32()})
        return m

    g["materials"] = p.seq(material)

    def texture():
        t = {"name": p.string(), "width": p.u32(), "height": p.u32(), "rgba8": p.bytes(),
             "srgb": True, "mips": []}
        if version >= 4:
            t["srgb"] = p.boolean()
            t["mips"] = p.seq(p.bytes)
        t["blocks"] = None
        if version >= 7:
            t["blocks"] = p.option(lambda: {"format": p.enum(BLOCK_FORMAT),
                                            "levels": p.seq(p.bytes)})
        return t

    g["textures"] = p.seq(texture)
    g["nodes"] = p.seq(lambda: {"name": p.string(), "parent": p.option(p.u32),
                                "rest": p.array(p.f64, 16)})
    if version >= 3:
        g["variants"] = p.seq(lambda: {"name": p.string(), "materials": p.seq(p.u32)})
    b["geometry"] = g
    b["scene_ids"] = p.seq(p.u32)
    b["copies"] = p.seq(p.u32)
    b["draws"] = p.seq(lambda: (p.u32(), p.u32(), p.u32(), p.i32(), p.u32()))
    b["frames"] = p.seq(lambda: (p.u32(), p.u32()))
    camera = lambda: {"view": p.array(p.f64, 16), "yfov": p.f64(), "znear": p.f64(),
                      "zfar": p.option(p.f64)}
    b["frame_states"] = p.seq(lambda: {"camera": camera(),
                                       "poses": p.seq(lambda: (p.u32(), p.array(p.f64, 16)))})
    b["removed_edges"] = p.seq(lambda: p.seq(lambda: (p.u32(), p.u32(), p.u32())))
    b["fps"] = p.option(p.f64) if version >= 3 else None
    if version >= 4:
        rgb = lambda: p.array(p.f32, 3)
        b["environment"] = {
            "name": p.string(), "width": p.u32(), "height": p.u32(),
            "levels": p.seq(lambda: p.seq(p.u16)), "sh": p.array(rgb, 9),
            "sun": p.option(lambda: {"direction": rgb(), "color": rgb()}),
            "exposure": p.f32()}
    else:
        b["environment"] = None
    if version >= 6:
        b["clips"] = p.seq(lambda: {
            "name": p.string(), "first": p.u32(), "count": p.u32(), "fps": p.option(p.f64),
            "path_hash": p.take(32).hex(), "path_first": p.u32()})
    else:
        b["clips"] = [{"name": "main", "first": 0, "count": len(b["frames"]), "fps": b["fps"],
                       "path_hash": b["path_hash"], "path_first": 0}]
    next_frame = 0
    for c in b["clips"]:
        if c["first"] != next_frame or c["count"] == 0:
            raise Bad("clip %r does not start where the one before ends" % c["name"])
        next_frame += c["count"]
    if next_frame != len(b["frames"]):
        raise Bad("the clips cover %d frames, the file has %d" % (next_frame, len(b["frames"])))
    return b


def level_size(width, height, k):
    """Level k of a mip chain or of the environment (FORMAT.md § Baked)."""
    return max(1, width >> k), max(1, height >> k)


def check_blocks(k, t):
    """A block-compressed texture (version 7): power-of-two size, no RGBA8 levels stored, a
    full chain of levels, each of whole 4x4 blocks covering its level."""
    w, h = t["width"], t["height"]
    if w == 0 or h == 0 or w & (w - 1) or h & (h - 1):
        raise Bad("texture %d: %dx%d blocks, not a power-of-two size" % (k, w, h))
    if t["rgba8"] or t["mips"]:
        raise Bad("texture %d: blocks and RGBA8 levels both stored" % k)
    block = 8 if t["blocks"]["format"] == "Etc2Rgb8" else 16
    levels = t["blocks"]["levels"]
    if len(levels) != max(w, h).bit_length():
        raise Bad("texture %d: %d block levels for %dx%d" % (k, len(levels), w, h))
    for level, data in enumerate(levels):
        lw, lh = level_size(w, h, level)
        if len(data) != ((lw + 3) // 4) * ((lh + 3) // 4) * block:
            raise Bad("texture %d block level %d: %d bytes for %dx%d" % (k, level, len(data), lw, lh))


def check_lengths(b, version):
    """The lengths FORMAT.md states, checked again: every texture level and environment level
    has the bytes (halves) its size needs, every texture (from version 4) has its full mip
    chain down to 1x1, slots name textures and texture coordinate sets that exist."""
    g = b["geometry"]
    for k, t in enumerate(g["textures"]):
        w, h = t["width"], t["height"]
        if t["blocks"] is not None:
            # Version 7: the levels as GPU blocks (8 bytes a 4x4 block for ETC2 RGB8, else 16),
            # the RGBA8 levels empty; decoding them is for a texture decoder, not this reader.
            check_blocks(k, t)
            continue
        if w == 0 or h == 0 or len(t["rgba8"]) != w * h * 4:
            raise Bad("texture %d: %dx%d with %d bytes" % (k, w, h, len(t["rgba8"])))
        full = max(w, h).bit_length() - 1
        if version >= 4 and len(t["mips"]) != full:
            raise Bad("texture %d %r (%dx%d): %d mip levels, the full chain down to 1x1 has %d"
                      % (k, t["name"], w, h, len(t["mips"]), full))
        for level, mip in enumerate(t["mips"], start=1):
            lw, lh = level_size(w, h, level)
            if len(mip) != lw * lh * 4:
                raise Bad("texture %d mip %d: %d bytes for %dx%d" % (k, level, len(mip), lw, lh))
    for k, m in enumerate(g["materials"]):
        slots = [m["base_color_texture"]] + [
            (m.get(s) or {}).get("texture") for s in
            ("metallic_roughness_texture", "normal_texture", "occlusion_texture",
             "emissive_texture")]
        if any(t is not None and t >= len(g["textures"]) for t in slots):
            raise Bad("material %d refers to a missing texture" % k)
        sets = [m.get("base_color_tex_coord", 0)] + [
            (m.get(s) or {}).get("tex_coord", 0) for s in
            ("metallic_roughness_texture", "normal_texture", "occlusion_texture",
             "emissive_texture")]
        if any(c > 1 for c in sets):
            raise Bad("material %d samples a texture coordinate set above 1" % k)
    e = b["environment"]
    if e is not None:
        for level, texels in enumerate(e["levels"]):
            lw, lh = level_size(e["width"], e["height"], level)
            if len(texels) != lw * lh * 4:
                raise Bad("environment level %d: %d halves for %dx%d RGBA" % (
                    level, len(texels), lw, lh))


def read_container(data, magic):
    """Header checks and decompression (FORMAT.md § Container)."""
    import zstandard

    if len(data) < 60 or data[:8] != magic:
        raise Bad("not a trisort file of this kind (magic %r)" % data[:8])
    version, packed, raw = struct.unpack_from("<IQQ", data, 8)
    if version not in FORMAT_VERSIONS:
        raise Bad("format version %d, this reader reads %s" % (version, FORMAT_VERSIONS))
    if packed != len(data) - 60:
        raise Bad("header says %d payload bytes, file has %d" % (packed, len(data) - 60))
    payload = zstandard.ZstdDecompressor().decompressobj().decompress(data[60:])
    if len(payload) != raw:
        raise Bad("decompressed to %d bytes, header says %d" % (len(payload), raw))
    return version, payload


def baked_summary(data):
    version, payload = read_container(data, b"TRISBAK\0")
    p = Postcard(payload)
    b = read_baked(p, version)
    if p.at != len(p.data):
        raise Bad("%d trailing payload bytes" % (len(p.data) - p.at))
    check_lengths(b, version)
    g = b["geometry"]
    nidx = 3 * len(b["copies"])
    for d in b["draws"]:
        if d[0] % 3 or d[2] % 3 or d[2] + d[0] > nidx or d[1] != 1:
            raise Bad("draw %r outside the index buffer" % (d,))
    return {
        "kind": "baked",
        "format_version": version,
        "tool_version": b["tool_version"],
        "frames": len(b["frames"]),
        "index_triangles": len(b["copies"]),
        "unique_visible": len(b["scene_ids"]),
        "vertices": len(g["vertices"]),
        "triangles": len(g["triangles"]),
        "materials": len(g["materials"]),
        "textures": len(g["textures"]),
        "srgb_textures": sum(1 for t in g["textures"] if t["srgb"]),
        "texture_bytes": sum(len(t["rgba8"]) + sum(len(m) for m in t["mips"])
                             for t in g["textures"]),
        "mip_levels": [len(t["mips"]) for t in g["textures"]],
        "tangents": sum(1 for v in g["vertices"] if len(v) > 5 and any(v[5])),
        "environment": None if b["environment"] is None else {
            "name": b["environment"]["name"], "width": b["environment"]["width"],
            "height": b["environment"]["height"], "levels": len(b["environment"]["levels"]),
            "sun": b["environment"]["sun"] is not None,
            "exposure": b["environment"]["exposure"]},
        "nodes": len(g["nodes"]),
        "variants": [v["name"] for v in g.get("variants", [])],
        "fps": b["fps"],
        "clips": [{"name": c["name"], "first": c["first"], "count": c["count"], "fps": c["fps"]}
                  for c in b["clips"]],
        "draws": len(b["draws"]),
        "draws_per_frame_max": max((w[1] for w in b["frames"]), default=0),
        "stats_index_triangles": b["stats"]["index_triangles"],
        "unordered_samples": b["stats"]["unordered_samples"],
        "removed_edges": sum(len(e) for e in b["removed_edges"]),
        "strategy": b["merge"]["strategy"],
        "layout": b["merge"]["layout"],
        "split_intersections": b["settings"]["split_intersections"],
        "width": b["settings"]["width"],
        "height": b["settings"]["height"],
        "samples": b["settings"]["samples"],
        # Version 5: the raster profile the file was baked for (null before).
        "raster_profile": b["settings"].get("robust", {}).get("profile"),
    }


def order_summary(data):
    """ORDER files (FORMAT.md § ORDER)."""
    if len(data) < 64 or data[:8] != b"TRISORD\0":
        raise Bad("not an ORDER file")
    version, flags = struct.unpack_from("<II", data, 8)
    if version != ORDER_VERSION or flags & ~1:
        raise Bad("ORDER version %d flags %d not supported" % (version, flags))
    nf, nr, nt, _ = struct.unpack_from("<IIII", data, 48)
    if len(data) != 64 + 8 * (nf + nr) + 16 * nt:
        raise Bad("ORDER length does not match its counts")
    ranges = struct.unpack_from("<%dI" % (2 * nr), data, 64 + 8 * nf)
    tris = struct.unpack_from("<%dI" % (4 * nt), data, 64 + 8 * (nf + nr))
    if any(ranges[2 * k] + ranges[2 * k + 1] > nt for k in range(nr)):
        raise Bad("a range lies outside the triangle list")
    return {"kind": "order", "frames": nf, "ranges": nr, "triangles": nt, "split": bool(flags & 1),
            "meshes": len(set(tris[0::4]))}


def main():
    if len(sys.argv) != 2:
        print("usage: format_reader.py FILE", file=sys.stderr)
        return 2
    path = sys.argv[1]
    try:
        with open(path, "rb") as f:
            data = f.read()
        summary = order_summary(data) if data[:8] == b"TRISORD\0" else baked_summary(data)
    except (Bad, OSError, UnicodeDecodeError) as e:
        print("format_reader: %s: %s" % (path, e), file=sys.stderr)
        return 1
    print(json.dumps(summary, indent=1, sort_keys=True))
    return 0


if __name__ == "__main__":
    sys.exit(main())
