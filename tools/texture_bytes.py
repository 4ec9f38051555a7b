#!/usr/bin/env python3
"""Bytes of each Freedoom map's look (docs/textures.md), as build/bspc stores it: per map the
textures and flats it uses, their texel bytes, the light tables, and the whole compiled scene;
for MAP01 the largest texture and flat; and the whole Freedoom texture set for comparison.
Writes docs/textures-bytes.md (`make bench-textures`).

usage: tools/texture_bytes.py [--bspc build/bspc] [--doc docs/textures-bytes.md]
"""
import argparse
import datetime
import struct
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
WADDIR = Path("/usr/share/games/doom")
SEC_LINES, SEC_SECTORS = 2, 1
SEC_LOOK, SEC_LIGHTS, SEC_TEXTURES, SEC_TEXELS, SEC_SIDES, SEC_PLANES = range(14, 20)
SEC_ANIMS, SEC_COUNT = 23, 24


def read_wad(path):
    data = path.read_bytes()
    n, dirofs = struct.unpack_from("<II", data, 4)
    out = []
    for i in range(n):
        pos, size, name = struct.unpack_from("<II8s", data, dirofs + 16 * i)
        out.append((name.split(b"\0", 1)[0].decode("latin-1").upper(), data[pos:pos + size]))
    return out


def name8(b):
    return b.split(b"\0", 1)[0].decode("latin-1").upper()


def maps(lumps):
    names = [n for n, _ in lumps]
    return [n for i, n in enumerate(names) if i + 1 < len(names) and names[i + 1] == "THINGS"]


def map_lumps(lumps, mapname):
    i = [n for n, _ in lumps].index(mapname)
    out = {}
    for n, d in lumps[i + 1:i + 12]:
        out.setdefault(n, d)
    return out


def stored_bytes(w, h):
    """Texels stored for a w x h texture: columns to the power of two below, rows to the one above."""
    return (1 << (w.bit_length() - 1)) * (1 << (h - 1).bit_length())


def texture_sizes(lumps):
    sizes = {}
    for lname in ("TEXTURE1", "TEXTURE2"):
        d = next((dd for n, dd in reversed(lumps) if n == lname), None)
        if d is None:
            continue
        for i in range(struct.unpack_from("<I", d)[0]):
            o = struct.unpack_from("<I", d, 4 + 4 * i)[0]
            w, h = struct.unpack_from("<hh", d, o + 12)
            sizes.setdefault(name8(d[o:o + 8]), (w, h))
    return sizes


def flat_names(lumps):
    names, inside = set(), False
    for n, _ in lumps:
        if n in ("F_START", "FF_START"):
            inside = True
        elif n in ("F_END", "FF_END"):
            inside = False
        elif inside and not n.endswith("_START") and not n.endswith("_END"):
            names.add(n)
    return names


def sections(blob):
    return [struct.unpack_from("<II", blob, 44 + 8 * i) for i in range(SEC_COUNT)]


def measure(bspc, wad, mapname, tmp):
    out = Path(tmp) / "m.bsc"
    subprocess.run([bspc, f"{wad}:{mapname}", "-o", out], check=True, capture_output=True)
    blob = out.read_bytes()
    sec = sections(blob)
    toff, ntex = sec[SEC_TEXTURES]
    tex = [struct.unpack_from("<IBB", blob, toff + 12 * i) for i in range(ntex)]
    flats = set()
    poff, npl = sec[SEC_PLANES]
    for i in range(npl):
        flats |= set(struct.unpack_from("<HH", blob, poff + 4 * i)) - {0xFFFF}
    aoff, nan = sec[SEC_ANIMS]
    for i in range(nan):  # the other frames of an animated flat are flats too
        first, count = struct.unpack_from("<IH", blob, aoff + 12 * i)
        if flats & set(range(first, first + count)):
            flats |= set(range(first, first + count))
    nbytes = lambda t: 1 << (tex[t][1] + tex[t][2])
    return {
        "map": mapname, "textures": ntex - len(flats), "flats": len(flats),
        # the textures' texels (the things' sprite images follow them in the section: docs/objects.md)
        "texel_bytes": sum(1 << (t[1] + t[2]) for t in tex), "light_bytes": sec[SEC_LIGHTS][1] * 256,
        "flat_bytes": sum(nbytes(t) for t in flats), "blob": len(blob), "tex": tex, "flat_set": flats,
        "blob_data": blob,
    }


def side_texture_names(m):
    """The texture names the sides of a map's lumps m (map_lumps) name, upper, lower and middle,
    "-" included; linedefs of zero length are left out, as the compiler leaves them out."""
    vx = [struct.unpack_from("<hh", m["VERTEXES"], 4 * i) for i in range(len(m["VERTEXES"]) // 4)]
    names = set()
    for i in range(len(m["LINEDEFS"]) // 14):
        v1, v2, _, _, _, s0, s1 = struct.unpack_from("<HHHHHHH", m["LINEDEFS"], 14 * i)
        if vx[v1] == vx[v2]:
            continue
        for sd in (s0, s1):
            if sd != 0xFFFF:
                rec = m["SIDEDEFS"][30 * sd:30 * sd + 30]
                names |= {name8(rec[o:o + 8]) for o in (4, 12, 20)}
    return names


def largest_of_map01(lumps, r):
    """Names of MAP01's largest wall texture and flat: the WAD's names of what its sides and
    sectors use (scene line j is the j-th linedef of non-zero length)."""
    m = map_lumps(lumps, "MAP01")
    sizes = texture_sizes(lumps)
    walls = side_texture_names(m) & set(sizes)
    wall = max(sorted(walls), key=lambda n: stored_bytes(*sizes[n]))
    flats = {name8(m["SECTORS"][26 * i + 4:26 * i + 12]) for i in range(len(m["SECTORS"]) // 26)}
    flat = sorted(flats & flat_names(lumps))[0]
    return wall, stored_bytes(*sizes[wall]), sizes[wall], flat, 4096


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bspc", default=str(ROOT / "build" / "bspc"))
    ap.add_argument("--doc", default=str(ROOT / "docs" / "textures-bytes.md"))
    a = ap.parse_args()
    lines = ["# Texture bytes per map", "",
             f"Generated by `make bench-textures` (tools/texture_bytes.py) on {datetime.date.today()}; "
             "do not edit by hand. Each Freedoom map compiled by build/bspc with its look (docs/textures.md): "
             "the wall textures and flats it uses (sky included among the textures), their texel bytes as "
             "stored (columns to the power of two below the width, rows to the one above the height), the "
             "light tables (32 x 256 bytes) and the whole compiled scene.", ""]
    whole = []
    with tempfile.TemporaryDirectory() as tmp:
        for wadname in ("freedoom1.wad", "freedoom2.wad"):
            wad = WADDIR / wadname
            lumps = read_wad(wad)
            lines += [f"## {wadname}", "", "| map | textures | flats | texel bytes | light table bytes | blob bytes |",
                      "|---|---:|---:|---:|---:|---:|"]
            rows = []
            for mapname in maps(lumps):
                r = measure(a.bspc, wad, mapname, tmp)
                rows.append(r)
                lines.append(f"| {mapname} | {r['textures']} | {r['flats']} | {r['texel_bytes']:,} | "
                             f"{r['light_bytes']:,} | {r['blob']:,} |")
                print(f"{wadname}:{mapname}: {r['textures']} textures, {r['flats']} flats, "
                      f"{r['texel_bytes']} texel bytes, {r['light_bytes']} light table bytes, {r['blob']} blob bytes")
                if mapname == "MAP01":
                    wall, wb, wsize, flat, fb = largest_of_map01(lumps, r)
                    map01 = (wadname, wall, wb, wsize, flat, fb)
            tb = [r["texel_bytes"] for r in rows]
            lines += ["", f"{len(rows)} maps: texel bytes min {min(tb):,}, median {sorted(tb)[len(tb) // 2]:,}, "
                      f"max {max(tb):,}.", ""]
            sizes = texture_sizes(lumps)
            set_bytes = sum(stored_bytes(w, h) for w, h in sizes.values())
            nflats = len(flat_names(lumps))
            whole.append((wadname, len(sizes), set_bytes, nflats, nflats * 4096))
    wadname, wall, wb, wsize, flat, fb = map01
    lines += ["## MAP01's largest", "",
              f"{wadname}:MAP01: largest wall texture {wall} ({wsize[0]} x {wsize[1]}, {wb:,} bytes stored); "
              f"every flat is 64 x 64 = {fb:,} bytes (the first by name: {flat}).", "",
              "## The whole Freedoom texture set, for comparison", "",
              "| WAD | wall textures | their bytes as stored | flats | flat bytes | total |",
              "|---|---:|---:|---:|---:|---:|"]
    for w, nt, tb_, nf, fb_ in whole:
        lines.append(f"| {w} | {nt} | {tb_:,} | {nf} | {fb_:,} | {tb_ + fb_:,} |")
        print(f"{w}: whole set {nt} textures {tb_} bytes, {nf} flats {fb_} bytes, total {tb_ + fb_}")
    print(f"{wadname}:MAP01: largest texture {wall} {wsize[0]}x{wsize[1]} {wb} bytes; flat {flat} {fb} bytes")
    Path(a.doc).write_text("\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
