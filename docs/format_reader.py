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

# Versions this reader understands (FORMAT.md § Compatibility): 3, and 2 (no `robust`, no
# `Geometry.variants`, no `fps`).
FORMAT_VERSIONS = (2, 3)
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
    g["vertices"] = p.seq(lambda: (p.array(p.f32, 3), p.array(p.f32, 3), p.array(p.f32, 2),
                                   p.u32(), p.u32()))
    g["triangles"] = p.seq(lambda: p.array(p.u32, 3))
    g["materials"] = p.seq(lambda: {
        "name": p.string(), "base_color": p.array(p.f32, 4),
        "base_color_texture": p.option(p.u32), "alpha_mode": p.enum(ALPHA_MODE),
        "alpha_cutoff": p.f32(), "double_sided": p.boolean(), "emissive": p.array(p.f32, 3),
        "transmission": p.f32()})
    g["textures"] = p.seq(lambda: {"name": p.string(), "width": p.u32(), "height": p.u32(),
                                   "rgba8": p.bytes()})
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
    return b


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
        "nodes": len(g["nodes"]),
        "variants": [v["name"] for v in g.get("variants", [])],
        "fps": b["fps"],
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
