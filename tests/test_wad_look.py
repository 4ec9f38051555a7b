"""A WAD map's look in the compiled scene (docs/textures.md, firmware/scene_format.h): the
sections' counts, only the textures and flats the map uses (and the other frames of the animated
ones), texels against an independent composition from the WAD, --flat, and damaged texture data
refused with a message (never a crash, under the sanitizer build)."""
import struct
import sys

import pytest

from conftest import ROOT, program, run, freedoom, wad_image

sys.path.insert(0, str(ROOT / "tools"))
from texture_bytes import flat_names, map_lumps, name8, read_wad, sections, side_texture_names  # noqa: E402

SEC_LOOK, SEC_LIGHTS, SEC_TEXTURES, SEC_TEXELS, SEC_SIDES, SEC_PLANES = range(14, 20)
SEC_LINES, SEC_SECTORS, SEC_PALETTE = 2, 1, 7
SEC_SPRITES = 20
TEX_NONE = 0xFFFF


# ---- reading a WAD (independently of tools/bspc) ----------------------------------------------

def last(lumps, name):
    found = None
    for n, d in lumps:
        if n == name:
            found = d
    return found




def texture_defs(lumps):
    """{name: (width, height, [(originx, originy, patch name)])}, TEXTURE1 before TEXTURE2 (first wins)."""
    pn = last(lumps, "PNAMES")
    pnames = [name8(pn[4 + 8 * i:12 + 8 * i]) for i in range(struct.unpack_from("<I", pn)[0])]
    defs = {}
    for lname in ("TEXTURE1", "TEXTURE2"):
        d = last(lumps, lname)
        if d is None:
            continue
        for i in range(struct.unpack_from("<I", d)[0]):
            o = struct.unpack_from("<I", d, 4 + 4 * i)[0]
            name = name8(d[o:o + 8])
            w, h = struct.unpack_from("<hh", d, o + 12)
            np_ = struct.unpack_from("<H", d, o + 20)[0]
            patches = []
            for k in range(np_):
                ox, oy, pi = struct.unpack_from("<hhH", d, o + 22 + 10 * k)
                patches.append((ox, oy, pnames[pi]))
            defs.setdefault(name, (w, h, patches))
    return defs




def compose(lumps, tdef):
    """Column-major w x h texels: patches in order, posts clipped to the texture."""
    w, h, patches = tdef
    pic = [[0] * h for _ in range(w)]
    for ox, oy, pname in patches:
        p = last(lumps, pname)
        pw = struct.unpack_from("<h", p)[0]
        for c in range(pw):
            x = ox + c
            if not 0 <= x < w:
                continue
            at = struct.unpack_from("<I", p, 8 + 4 * c)[0]
            while p[at] != 0xFF:
                top, length = p[at], p[at + 1]
                for k in range(length):
                    y = oy + top + k
                    if 0 <= y < h:
                        pic[x][y] = p[at + 3 + k]
                at += length + 4
    return pic




# Doom's animated textures and flats (P_InitPicAnims: first and last frame; docs/textures.md)
ANIM_FLATS = [("NUKAGE1", "NUKAGE3"), ("FWATER1", "FWATER4"), ("SWATER1", "SWATER4"), ("LAVA1", "LAVA4"),
              ("BLOOD1", "BLOOD3"), ("RROCK05", "RROCK08"), ("SLIME01", "SLIME04"), ("SLIME05", "SLIME08"),
              ("SLIME09", "SLIME12")]
ANIM_WALLS = [("BLODGR1", "BLODGR4"), ("SLADRIP1", "SLADRIP3"), ("BLODRIP1", "BLODRIP4"), ("FIREWALA", "FIREWALL"),
              ("GSTFONT1", "GSTFONT3"), ("FIRELAV3", "FIRELAVA"), ("FIREMAG1", "FIREMAG3"), ("FIREBLU1", "FIREBLU2"),
              ("ROCKRED1", "ROCKRED3"), ("BFALL1", "BFALL4"), ("SFALL1", "SFALL4"), ("WFALL1", "WFALL4"),
              ("DBRAIN1", "DBRAIN4")]


def with_animations(lumps, walls, flats):
    """The wall and flat names, each with every frame of the sequences it is a frame of: the names
    between the sequence's first and last in the WAD's order (texture numbers, TEXTURE1 then
    TEXTURE2; the flats' lumps)."""
    order = []
    for lname in ("TEXTURE1", "TEXTURE2"):
        d = last(lumps, lname)
        if d is not None:
            order += [name8(d[o:o + 8]) for o in struct.unpack_from(f"<{struct.unpack_from('<I', d)[0]}I", d, 4)]
    lumpnames = [n for n, _ in lumps]
    lastlump = {n: i for i, n in enumerate(lumpnames)}
    walls, flats = set(walls), set(flats)
    for a, b in ANIM_WALLS:
        if a in order and b in order:
            seq = set(order[order.index(a):order.index(b) + 1])
            if seq & walls:
                walls |= seq
    for a, b in ANIM_FLATS:
        if a in lastlump and b in lastlump:
            seq = set(lumpnames[lastlump[a]:lastlump[b] + 1])
            if seq & flats:
                flats |= seq
    return walls, flats


# ---- the compiled scene ----------------------------------------------------------------------



def compile_map(tmp_path, spec, *extra):
    out = tmp_path / "m.bsc"
    run([program("bspc"), spec, "-o", out, *extra])
    return out.read_bytes()


def textures(blob):
    off, n = sections(blob)[SEC_TEXTURES]
    return [struct.unpack_from("<IBBBB", blob, off + 12 * i) for i in range(n)]


def sides(blob):
    off, n = sections(blob)[SEC_SIDES]
    return [struct.unpack_from("<iiiiHHHBb", blob, off + 24 * i) for i in range(n)]


MAPS = [("freedoom2.wad", "MAP01"), ("freedoom1.wad", "E1M1")]


@pytest.mark.parametrize("wad, mapname", MAPS)
def test_look_sections_hold_exactly_what_the_map_uses(tmp_path, wad, mapname):
    path = freedoom(wad)
    blob = compile_map(tmp_path, f"{path}:{mapname}")
    sec = sections(blob)
    lumps = read_wad(path)
    assert sec[SEC_LOOK][1] == 1 and sec[SEC_LIGHTS][1] == 32
    assert sec[SEC_SIDES][1] == 2 * sec[SEC_LINES][1] and sec[SEC_PLANES][1] == sec[SEC_SECTORS][1]
    o = sec[SEC_PALETTE][0]
    assert blob[o:o + 768] == last(lumps, "PLAYPAL")[:768]
    o = sec[SEC_LIGHTS][0]
    assert blob[o:o + 32 * 256] == last(lumps, "COLORMAP")[:32 * 256]
    texs = textures(blob)
    # stored one after another, each 2^(wbits + hbits) texels; the things' sprite images follow
    # (docs/objects.md, "Sprites"; tests/test_bspc_sprites.py)
    at = 0
    for first, wb, hb, _, reserved in texs:
        assert first == at and reserved == 0
        at += 1 << (wb + hb)
    off, nspr = sec[SEC_SPRITES]
    at += sum(w * h for _, _, w, h in (struct.unpack_from("<IIHH", blob, off + 16 * i) for i in range(nspr)))
    assert sec[SEC_TEXELS][1] == at

    # the names the map uses, as the WAD gives them (zero-length linedefs are left out)
    m = map_lumps(lumps, mapname)
    defs, flats = texture_defs(lumps), flat_names(lumps)
    walls = side_texture_names(m)
    used_flats, sky = set(), False
    for i in range(len(m["SECTORS"]) // 26):
        r = m["SECTORS"][26 * i:26 * i + 26]
        used_flats.add(name8(r[4:12]))
        if name8(r[12:20]).startswith("F_SKY"):
            sky = True
        else:
            used_flats.add(name8(r[12:20]))
    if sky:
        n = int(mapname[3:]) if mapname.startswith("MAP") else None
        walls.add(("SKY1" if n < 12 else "SKY2" if n < 21 else "SKY3") if n else f"SKY{mapname[1]}")
    # a frame of an animation brings its whole sequence
    walls, used_flats = with_animations(lumps, walls & set(defs), used_flats & flats)
    # and a middle texture with holes on a two-sided line its opacity map (docs/textures.md)
    off, n = sec[SEC_TEXTURES]
    masks = {struct.unpack_from("<H", blob, off + 12 * i + 10)[0] for i in range(n)} - {0xFFFF}
    expected = len(walls & set(defs)) + len(used_flats & flats) + len(masks)
    assert len(texs) == expected, (len(texs), expected)
    look_sky = struct.unpack_from("<I", blob, sec[SEC_LOOK][0])[0]
    assert (look_sky != TEX_NONE) == sky and (not sky or look_sky < len(texs))


@pytest.mark.parametrize("wad, mapname", MAPS)
def test_texels_match_an_independent_composition(tmp_path, wad, mapname):
    """The used wall texture made of the most patches, every stored texel (wrap and padding as
    docs/textures.md says), found through the side that uses it."""
    path = freedoom(wad)
    blob = compile_map(tmp_path, f"{path}:{mapname}")
    lumps = read_wad(path)
    defs = texture_defs(lumps)
    m = map_lumps(lumps, mapname)
    vx = [struct.unpack_from("<hh", m["VERTEXES"], 4 * i) for i in range(len(m["VERTEXES"]) // 4)]
    # scene line j is the j-th linedef that is not of zero length; its front side's middle texture
    best = None
    j = 0
    for i in range(len(m["LINEDEFS"]) // 14):
        v1, v2, _, _, _, s0, _ = struct.unpack_from("<HHHHHHH", m["LINEDEFS"], 14 * i)
        if vx[v1] == vx[v2]:
            continue
        r = m["SIDEDEFS"][30 * s0:30 * s0 + 30]
        for part, o in ((0, 4), (1, 20), (2, 12)):
            name = name8(r[o:o + 8])
            if name in defs and (best is None or len(defs[name][2]) > len(defs[best[0]][2])):
                best = (name, j, part)
        j += 1
    name, line, part = best
    assert len(defs[name][2]) >= 2, "no multi-patch texture to check"
    t = sides(blob)[2 * line][4 + part]
    first, wb, hb, _, _ = textures(blob)[t]
    w, h, _ = defs[name]
    assert wb == w.bit_length() - 1 and (1 << hb) >= h > (1 << hb) // 2 or h == 1 << hb
    pic = compose(lumps, defs[name])
    off = sections(blob)[SEC_TEXELS][0] + first
    bad = sum(blob[off + (u << hb) + v] != pic[u][v % h] for u in range(1 << wb) for v in range(1 << hb))
    assert bad == 0, f"{name}: {bad} texels differ"


def test_flat_leaves_the_look_out(tmp_path):
    path = freedoom("freedoom2.wad")
    blob = compile_map(tmp_path, f"{path}:MAP01", "--flat")
    sec = sections(blob)
    assert all(sec[i][1] == 0 for i in range(SEC_LOOK, SEC_PLANES + 1))
    o = sec[SEC_PALETTE][0]
    assert blob[o:o + 768] == last(read_wad(path), "PLAYPAL")[:768], "--flat keeps the Doom palette"
    textured = compile_map(tmp_path, f"{path}:MAP01")
    # the flat colours (sectors, lines) are the same with and without the look
    for s, size in ((SEC_SECTORS, 16), (SEC_LINES, 24)):
        (a, n), (b, n2) = sec[s], sections(textured)[s]
        assert n == n2 and blob[a:a + size * n] == textured[b:b + size * n2]


# ---- a small WAD with damaged texture data ---------------------------------------------------

def patch_lump(w=64, h=64, colour=5):
    cols = b"".join(bytes([0, h, 0]) + bytes([colour]) * h + bytes([0, 0xFF]) for _ in range(w))
    hdr = struct.pack("<hhhh", w, h, 0, 0)
    start = 8 + 4 * w
    return hdr + b"".join(struct.pack("<I", start + c * (h + 5)) for c in range(w)) + cols


def texture1(name=b"WALLA", w=64, h=64, patch_index=0, count=None):
    tex = struct.pack("<8sIhhIH", name, 0, w, h, 0, 1) + struct.pack("<hhHhh", 0, 0, patch_index, 1, 0)
    n = 1 if count is None else count
    return struct.pack("<II", n, 8) + tex


def small_wad(freedoom2, before=(), **over):
    """A room of 4 one-sided lines, its walls WALLA (one patch), floor and ceiling FLATA; the lumps of
    before (name, data) come ahead of the palette."""
    lumps = read_wad(freedoom2)
    room = [(0, 0), (0, 256), (256, 256), (256, 0)]
    verts = b"".join(struct.pack("<hh", x, y) for x, y in room)
    lines = b"".join(struct.pack("<HHHHHHH", i, (i + 1) % 4, 0, 0, 0, i, 0xFFFF) for i in range(4))
    sides = b"".join(struct.pack("<hh8s8s8sH", 0, 0, b"-", b"-", b"WALLA", 0) for _ in range(4))
    sector = struct.pack("<hh8s8shhh", 0, 128, b"FLATA", b"FLATA", 160, 0, 0)
    things = struct.pack("<hhhhh", 128, 128, 0, 1, 7)
    parts = {
        "PLAYPAL": last(lumps, "PLAYPAL"), "COLORMAP": last(lumps, "COLORMAP"),
        "PNAMES": struct.pack("<I8s", 1, b"PATCHA"), "TEXTURE1": texture1(), "PATCHA": patch_lump(),
        "FLATA": bytes(range(64)) * 64,
    }
    parts.update(over)
    out = [("MAP01", b""), ("THINGS", things), ("LINEDEFS", lines), ("SIDEDEFS", sides), ("VERTEXES", verts),
           ("SECTORS", sector), *before]
    for k in ("PLAYPAL", "COLORMAP", "PNAMES", "TEXTURE1", "PATCHA"):
        if parts[k] is not None:
            out.append((k, parts[k]))
    out += [("F_START", b""), ("FLATA", parts["FLATA"]), ("F_END", b"")]
    return wad_image(out)


def broken_patch_column():
    p = bytearray(patch_lump())
    struct.pack_into("<I", p, 8 + 4 * 3, len(p) + 100)
    return bytes(p)


def broken_patch_post():
    p = bytearray(patch_lump())
    col = struct.unpack_from("<I", p, 8 + 4 * 63)[0]
    p[col + 1] = 200  # a post longer than the lump
    return bytes(p)


BROKEN = [
    ("patch-column-offset", {"PATCHA": broken_patch_column()}, ["PATCHA", "column 3", "past the end"]),
    ("patch-post-length", {"PATCHA": broken_patch_post()}, ["PATCHA", "column 63", "runs past the end"]),
    ("patch-header", {"PATCHA": b"\1\0"}, ["PATCHA", "shorter than its 8-byte header"]),
    ("texture1-count", {"TEXTURE1": texture1(count=100000)}, ["TEXTURE1", "do not fit"]),
    ("pnames-index", {"TEXTURE1": texture1(patch_index=7)}, ["TEXTURE1", "WALLA", "PNAMES entry 7"]),
    ("texture-too-wide", {"TEXTURE1": texture1(w=4096)}, ["WALLA", "larger than 1024"]),
    ("flat-short", {"FLATA": b"\0" * 100}, ["FLATA", "shorter than 4096"]),
    ("colormap-short", {"COLORMAP": b"\0" * 300}, ["COLORMAP", "shorter than 8192"]),
]


@pytest.mark.parametrize("over, needles", [b[1:] for b in BROKEN], ids=[b[0] for b in BROKEN])
def test_damaged_texture_data_is_refused(tmp_path, over, needles):
    wad = tmp_path / "bad.wad"
    wad.write_bytes(small_wad(freedoom("freedoom2.wad"), **over))
    out = tmp_path / "o.bsc"
    proc = run([program("bspc"), f"{wad}:MAP01", "-o", out], check=False)
    assert "Sanitizer" not in proc.stderr and "runtime error" not in proc.stderr, proc.stderr
    assert proc.returncode == 1 and proc.stderr.count("\n") == 1, proc.stderr
    for n in needles:
        assert n in proc.stderr, (n, proc.stderr)
    assert not out.exists()


def test_small_wad_compiles_with_its_look_and_without_texture1_flat(tmp_path):
    wad = tmp_path / "ok.wad"
    wad.write_bytes(small_wad(freedoom("freedoom2.wad")))
    blob = compile_map(tmp_path, f"{wad}:MAP01")
    sec = sections(blob)
    assert sec[SEC_LOOK][1] == 1 and sec[SEC_TEXTURES][1] == 2  # WALLA and FLATA
    assert sec[SEC_TEXELS][1] == 2 * 64 * 64
    sd = sides(blob)
    assert [s[4:7] for s in sd[0::2]] == [(TEX_NONE, 0, TEX_NONE)] * 4 or \
        [s[4:7] for s in sd[0::2]] == [(TEX_NONE, 1, TEX_NONE)] * 4
    # one-sided lines: no back side textures
    assert all(s[4:7] == (TEX_NONE,) * 3 for s in sd[1::2])
    wad.write_bytes(small_wad(freedoom("freedoom2.wad"), TEXTURE1=None))
    blob = compile_map(tmp_path, f"{wad}:MAP01")
    assert all(sections(blob)[i][1] == 0 for i in range(SEC_LOOK, SEC_PLANES + 1))


def texture_lump(entries):
    """A TEXTURE1 of entries in order: (name, width) for a texture of one patch (PNAMES 0), 64 high, or an
    int for an entry whose offset is that number."""
    base, body, offs = 4 + 4 * len(entries), b"", []
    for e in entries:
        if isinstance(e, int):
            offs.append(e)
            continue
        offs.append(base + len(body))
        body += struct.pack("<8sIhhIH", e[0], 0, e[1], 64, 0, 1) + struct.pack("<hhHhh", 0, 0, 0, 1, 0)
    return struct.pack("<I", len(entries)) + b"".join(struct.pack("<I", o) for o in offs) + body


def compile_small(tmp_path, **over):
    wad = tmp_path / "t.wad"
    wad.write_bytes(small_wad(freedoom("freedoom2.wad"), **over))
    out = tmp_path / "o.bsc"
    out.unlink(missing_ok=True)
    proc = run([program("bspc"), f"{wad}:MAP01", "-o", out], check=False)
    assert "Sanitizer" not in proc.stderr and "runtime error" not in proc.stderr, proc.stderr
    return proc, out


def test_texture_definitions_are_searched_in_doom_order(tmp_path):
    """TEXTURE1 is searched from its first entry: a damaged entry after the texture used is never reached,
    one before it refuses the map, and of two definitions of a name the first is used."""
    proc, out = compile_small(tmp_path, TEXTURE1=texture_lump([(b"WALLA", 64), 999999]))
    assert proc.returncode == 0, proc.stderr
    proc, out = compile_small(tmp_path, TEXTURE1=texture_lump([999999, (b"WALLA", 64)]))
    assert proc.returncode == 1 and "TEXTURE1: texture 0 at offset 999999 runs past the end" in proc.stderr
    assert not out.exists()
    for widths, wide in (((128, 64), True), ((64, 128), False)):
        proc, out = compile_small(tmp_path, TEXTURE1=texture_lump([(b"WALLA", w) for w in widths]))
        assert proc.returncode == 0, proc.stderr
        assert any(t[1] == 7 for t in textures(out.read_bytes())) == wide, widths


def test_the_last_lump_of_a_name_is_the_patch(tmp_path):
    """A patch name found twice in the directory is the later lump, as in Doom."""
    proc, out = compile_small(tmp_path, before=[("PATCHA", patch_lump(colour=9))])
    assert proc.returncode == 0, proc.stderr
    blob = out.read_bytes()
    toff = sections(blob)[SEC_TEXELS][0]
    texels = {blob[toff + t[0]:toff + t[0] + 4096] for t in textures(blob)}
    assert bytes([5]) * 4096 in texels and bytes([9]) * 4096 not in texels
