"""Sprites of WAD things in the compiled scene (docs/objects.md, "Sprites"; firmware/scene_format.h):
read back from bspc's blob and checked against the WAD's own lumps, decoded here independently of
tools/bspc: the images of each thing's spawn frame, their rotations and mirror bits, the full-bright
flag, only the lumps the map's things need, the box model around each sprite, none under --flat or
in a text scene, and sprite data at and past the format's limits (crafted PWADs, sanitized build)."""
import struct

import pytest

from conftest import ROOT, freedoom, program, render, room_lumps, run, wad_image

SCN_NONE = 0xFFFFFFFF
SEC = {name: i for i, name in enumerate(
    ["VERTICES", "SECTORS", "LINES", "SEGS", "NODES", "LEAVES", "PVERTS", "PALETTE", "MODELS", "MVERTS", "FACES",
     "FINDEX", "OBJECTS", "NEEDS", "LOOK", "LIGHTS", "TEXTURES", "TEXELS", "SIDES", "PLANES", "SPRITES", "SPRMASK",
     "SPRSETS", "ANIMS"])}
BRIGHT = 1


# ---- the compiled scene ----------------------------------------------------------------------

class Blob:
    """The records of a compiled scene this test reads."""

    def __init__(self, data):
        self.data = data
        magic, version, header_bytes, total, crc, flags = struct.unpack_from("<IHHIII", data, 0)
        assert (data[:4], version, header_bytes, total) == (b"BSCN", 6, 44 + 8 * len(SEC), len(data))
        self.sec = [struct.unpack_from("<II", data, 44 + 8 * i) for i in range(len(SEC))]
        self._images = {}

    def count(self, name):
        return self.sec[SEC[name]][1]

    def records(self, name, fmt):
        off, n = self.sec[SEC[name]]
        size = struct.calcsize(fmt)
        return [struct.unpack_from(fmt, self.data, off + size * i) for i in range(n)]

    def objects(self):
        """[(model, x, y, sprset)] of the things (see-through middle textures, side != NONE, follow them)"""
        return [(r[0], r[1] >> 16, r[2] >> 16, r[10]) for r in self.records("OBJECTS", "<IiiiiIiiIiII")
                if r[11] == 0xFFFFFFFF]

    def models(self):
        return self.records("MODELS", "<IIIIiii")

    def mverts(self):
        return self.records("MVERTS", "<iii")

    def sprites(self):
        """[(first, mask, width, height, left, top)]"""
        return self.records("SPRITES", "<IIHHhh")

    def sprsets(self):
        """[(images[8], mirror, flags, reserved)]"""
        return [(list(r[:8]), r[8], r[9], r[10]) for r in self.records("SPRSETS", "<8HBBH")]

    def image(self, k):
        """Sprite k as (width, height, left, top, texels by column, opaque (u, v) set)."""
        if k not in self._images:
            self._images[k] = self._image(k)
        return self._images[k]

    def _image(self, k):
        first, mask, w, h, left, top = self.sprites()[k]
        toff = self.sec[SEC["TEXELS"]][0] + first
        moff = self.sec[SEC["SPRMASK"]][0] + 4 * mask
        words = (h + 31) >> 5
        texels = [list(self.data[toff + u * h:toff + (u + 1) * h]) for u in range(w)]
        opaque = set()
        for u in range(w):
            for j in range(words):
                bits = struct.unpack_from("<I", self.data, moff + 4 * (u * words + j))[0]
                opaque |= {(u, 32 * j + b) for b in range(32) if bits >> b & 1}
        return w, h, left, top, texels, opaque


def compile_blob(tmp_path, spec, *extra, check=True):
    out = tmp_path / "s.bsc"
    out.unlink(missing_ok=True)
    proc = run([program("bspc"), spec, "-o", out, *extra], check=check)
    assert "Sanitizer" not in proc.stderr and "runtime error" not in proc.stderr, proc.stderr
    return (Blob(out.read_bytes()) if out.exists() else None), proc


# ---- the WAD, read here ----------------------------------------------------------------------

def read_wad(path):
    data = path.read_bytes()
    n, dirofs = struct.unpack_from("<II", data, 4)
    out = []
    for i in range(n):
        pos, size, name = struct.unpack_from("<II8s", data, dirofs + 16 * i)
        out.append((name.split(b"\0", 1)[0].decode("latin-1").upper(), data[pos:pos + size]))
    return out


def thing_table():
    """{type: (radius, height, sprite, frame, bright)} from tools/bspc/things.txt."""
    table = {}
    for line in (ROOT / "tools/bspc/things.txt").read_text().splitlines():
        tok = line.split("#", 1)[0].split()
        if tok:
            assert len(tok) == 7, line
            table[int(tok[0])] = (int(tok[1]), int(tok[2]), tok[4], tok[5][0], tok[5][1:] == "*")
    return table


def map_things(lumps, mapname, table):
    """The types of the things that become objects, in THINGS order."""
    i = [n for n, _ in lumps].index(mapname)
    things = next(d for n, d in lumps[i + 1:] if n == "THINGS")
    out = []
    for k in range(len(things) // 10):
        x, y, _, typ, flags = struct.unpack_from("<hhhHH", things, 10 * k)
        if typ in table and flags & 2 and not flags & 0x10 and x != -32768 and y != -32768:
            out.append(typ)
    return out


def sprite_lumps(lumps):
    """[(name, data)] between S_START/S_END (or SS_), in directory order."""
    out, inside = [], False
    for n, d in lumps:
        if n in ("S_START", "SS_START"):
            inside = True
        elif n in ("S_END", "SS_END"):
            inside = False
        elif inside:
            out.append((n, d))
    return out


def frame_images(sprites, spr, frame):
    """[(lump name, mirrored)] for rotations 0..7 (Doom's 1..8), or None: rotation 0 serves all; a
    name's second frame/rotation pair shows it mirrored; a later lump replaces an earlier one."""
    rot = {}
    for name, _ in sprites:
        if len(name) not in (6, 8) or name[:4] != spr or name[5] not in "012345678":
            continue
        if len(name) == 8 and name[7] not in "012345678":
            continue
        if name[4] == frame:
            rot[int(name[5])] = (name, False)
        if len(name) == 8 and name[6] == frame:
            rot[int(name[7])] = (name, True)
    if 0 in rot:
        return [rot[0]] * 8
    if all(r in rot for r in range(1, 9)):
        return [rot[r] for r in range(1, 9)]
    return None


def decode_patch(p):
    """Doom's patch: (width, height, left, top, texels by column (0 where no post), opaque set)."""
    w, h, left, top = struct.unpack_from("<hhhh", p, 0)
    texels = [[0] * h for _ in range(w)]
    opaque = set()
    for u in range(w):
        at = struct.unpack_from("<I", p, 8 + 4 * u)[0]
        while p[at] != 0xFF:
            row, length = p[at], p[at + 1]
            for k in range(length):
                if row + k < h:
                    texels[u][row + k] = p[at + 3 + k]
                    opaque.add((u, row + k))
            at += length + 4
    return w, h, left, top, texels, opaque


def reach(img):
    w, _, left = img[:3]
    return max(left, w - left)


# ---- Freedoom maps -----------------------------------------------------------------------------

@pytest.fixture(scope="module")
def map01(tmp_path_factory):
    path = freedoom("freedoom2.wad")
    out = tmp_path_factory.mktemp("map01") / "m.bsc"
    run([program("bspc"), f"{path}:MAP01", "-o", out])
    lumps = read_wad(path)
    return Blob(out.read_bytes()), lumps, map_things(lumps, "MAP01", thing_table())


def test_each_thing_shows_its_spawn_frame(map01):
    """Every object's sprite set holds, per rotation, the image of the lump Doom would draw, decoded here
    from the WAD: size, offsets, every texel and which texels are opaque; the mirror bits and the
    full-bright flag are the table's and the lump names'."""
    blob, lumps, types = map01
    table, sprites = thing_table(), sprite_lumps(lumps)
    last = dict(sprites)
    objs = blob.objects()
    assert len(objs) == len(types) == 101  # every thing stands in a sector: objects follow THINGS order
    sets, decoded, checked = blob.sprsets(), {}, {}
    for (model, _, _, sprset), typ in zip(objs, types):
        _, _, spr, frame, bright = table[typ]
        want = frame_images(sprites, spr, frame)
        assert want is not None, typ  # Freedoom has every frame the map needs
        assert sprset != SCN_NONE, typ
        images, mirror, flags, reserved = sets[sprset]
        assert reserved == 0 and flags == (BRIGHT if bright else 0), typ
        for r, (name, mirrored) in enumerate(want):
            assert bool(mirror >> r & 1) == mirrored, (typ, r)
            if name not in decoded:
                decoded[name] = decode_patch(last[name])
            assert checked.setdefault(name, images[r]) == images[r], f"{name} stored twice"
            got = blob.image(images[r])
            assert got == decoded[name], f"{name}: image {images[r]} differs from the lump"
    assert blob.count("SPRITES") == len(checked)
    assert blob.count("SPRSETS") == len({table[t][2:] for t in types})


def test_imp_rotations_and_mirrors(map01):
    """TROOA1, TROOA2A8, TROOA3A7, TROOA4A6, TROOA5: rotations 2..4 are their lumps, 8..6 the same
    images mirrored."""
    blob, lumps, types = map01
    objs = blob.objects()
    sprset = objs[types.index(3001)][3]
    images, mirror, flags, _ = blob.sprsets()[sprset]
    assert flags == 0
    assert mirror == 0b11100000  # Doom rotations 6, 7, 8
    assert len(set(images)) == 5
    assert images[1] == images[7] and images[2] == images[6] and images[3] == images[5]
    last = dict(sprite_lumps(lumps))
    for r, name in ((0, "TROOA1"), (1, "TROOA2A8"), (2, "TROOA3A7"), (3, "TROOA4A6"), (4, "TROOA5")):
        assert blob.image(images[r]) == decode_patch(last[name]), name


def test_bright_types(map01):
    """The soul sphere (SOUL A) and the floor lamp (COLU A) are full-bright; the barrel is not."""
    blob, _, types = map01
    objs, sets = blob.objects(), blob.sprsets()
    flags = {t: sets[o[3]][2] for o, t in zip(objs, types)}
    assert flags[2013] == BRIGHT and flags[2028] == BRIGHT
    assert flags[2035] == 0 and flags[3001] == 0


def test_sprite_models_hold_their_images(map01):
    """A sprite thing's model is the upright box around its images: radius the largest reach (left or
    width - left), height the largest top, bottom at 0; what the loader asks of it follows."""
    blob, _, _ = map01
    models, mverts, sets = blob.models(), blob.mverts(), blob.sprsets()
    for model, _, _, sprset in blob.objects():
        first, nv, _, _, radius, zmin, zmax = models[model]
        imgs = [blob.sprites()[k] for k in sets[sprset][0]]
        r = max(1, max(max(s[4], s[2] - s[4]) for s in imgs))
        h = max(1, max(s[5] for s in imgs))
        vs = mverts[first:first + nv]
        assert {abs(v[0]) for v in vs} == {r << 16} and {abs(v[1]) for v in vs} == {r << 16}
        assert {v[2] for v in vs} == {0, h << 16}
        for s in imgs:
            assert max(s[4], s[2] - s[4]) << 16 <= radius and s[5] << 16 <= zmax and zmin <= 0


def test_sprite_texels_follow_the_textures(map01):
    """The images' texels sit after the textures' in SCN_SEC_TEXELS, one after another, and their masks
    fill SCN_SEC_SPRMASK."""
    blob = map01[0]
    tex = blob.records("TEXTURES", "<IBBBBHH")
    at = max(t[0] + (1 << (t[1] + t[2])) for t in tex)
    mask = 0
    for first, m, w, h, _, _ in blob.sprites():
        assert (first, m) == (at, mask)
        at += w * h
        mask += w * ((h + 31) >> 5)
    assert (at, mask) == (blob.count("TEXELS"), blob.count("SPRMASK"))


def test_flat_and_text_scenes_carry_no_sprites(tmp_path, map01):
    """--flat: no sprite sections, every object its box of things.txt's size; a text scene neither."""
    blob, proc = compile_blob(tmp_path, f"{freedoom('freedoom2.wad')}:MAP01", "--flat")
    assert all(blob.count(s) == 0 for s in ("SPRITES", "SPRMASK", "SPRSETS", "TEXTURES"))
    table, types = thing_table(), map01[2]
    models, mverts = blob.models(), blob.mverts()
    objs = blob.objects()
    assert len(objs) == len(types)
    for (model, _, _, sprset), typ in zip(objs, types):
        assert sprset == SCN_NONE
        first, nv = models[model][:2]
        vs = mverts[first:first + nv]
        assert max(v[0] for v in vs) == table[typ][0] << 16 and max(v[2] for v in vs) == table[typ][1] << 16
    scene = tmp_path / "t.scene"
    scene.write_text("sector a floor=0 ceil=128\nwall 0 0 0 256 a\nwall 0 256 256 256 a\n"
                     "wall 256 256 256 0 a\nwall 256 0 0 0 a\nplayer 10 10 0\n"
                     "model crate\npart box w=32 d=32 h=32\nend\nobject crate 100 100\n")
    blob, _ = compile_blob(tmp_path, str(scene))
    assert [o[3] for o in blob.objects()] == [SCN_NONE]
    assert blob.count("SPRITES") == blob.count("SPRSETS") == 0


@pytest.mark.parametrize("spec", ["freedoom2.wad:MAP12", "freedoom1.wad:E1M1"])
def test_only_the_frames_the_things_need(tmp_path, spec):
    """The images are exactly the lumps of the spawn frames of the types present, each once."""
    wad, mapname = spec.split(":")
    path = freedoom(wad)
    blob, _ = compile_blob(tmp_path, f"{path}:{mapname}")
    table, lumps = thing_table(), read_wad(path)
    sprites, types = sprite_lumps(lumps), map_things(lumps, mapname, table)
    assert len(blob.objects()) == len(types)
    need = set()
    for t in set(types):
        want = frame_images(sprites, *table[t][2:4])
        assert want is not None, t
        need |= {name for name, _ in want}
    assert blob.count("SPRITES") == len(need)
    assert all(o[3] != SCN_NONE for o in blob.objects())


# ---- crafted WADs ------------------------------------------------------------------------------

def patch(w, h, left, top, colour=7, rows=None):
    """A patch whose every column has one post over rows (start, length), default the whole height
    (at most 255 rows); texel (u, v) = (colour + u + v) & 255."""
    start, length = rows if rows else (0, min(h, 255))
    cols, offs = b"", []
    base = 8 + 4 * w
    for u in range(w):
        offs.append(base + len(cols))
        cols += bytes([start, length, 0]) + bytes((colour + u + start + k) & 255 for k in range(length)) + b"\0\xff"
    return struct.pack("<hhhh", w, h, left, top) + b"".join(struct.pack("<I", o) for o in offs) + cols


def crafted_wad(path, sprites, things=((64, 64, 2035),)):
    """A textured room (one wall texture, one flat each way) with things (x, y, type) and the lumps
    sprites [(name, data)] between S_START and S_END."""
    fd = read_wad(freedoom("freedoom2.wad"))
    last = dict(fd)
    room = room_lumps()
    room["THINGS"] += b"".join(struct.pack("<hhhHH", x, y, 90, t, 7) for x, y, t in things)
    tex = struct.pack("<II", 1, 8) + struct.pack("<8sIhhIH", b"STARTAN3", 0, 64, 64, 0, 1) + \
        struct.pack("<hhHhh", 0, 0, 0, 1, 0)
    lumps = [("MAP01", b"")] + list(room.items()) + [
        ("PLAYPAL", last["PLAYPAL"]), ("COLORMAP", last["COLORMAP"]), ("PNAMES", struct.pack("<I8s", 1, b"WALLP")),
        ("TEXTURE1", tex), ("WALLP", patch(64, 64, 0, 0)),
        ("F_START", b""), ("FLOOR4_8", bytes(range(64)) * 64), ("CEIL3_5", bytes(64) * 64), ("F_END", b""),
        ("S_START", b""), *sprites, ("S_END", b"")]
    path.write_bytes(wad_image(lumps))
    return f"{path}:MAP01"


@pytest.mark.parametrize("w, h, drawn", [(512, 8, True), (513, 8, False), (8, 512, True), (8, 513, False)])
def test_image_size_at_the_limit(tmp_path, w, h, drawn):
    """An image up to 512 x 512 is stored; a larger one leaves its things boxes of things.txt's size,
    with a warning naming the lump and the limit (-v)."""
    spec = crafted_wad(tmp_path / "big.wad", [("BAR1A0", patch(w, h, w // 2, h - 2))])
    blob, proc = compile_blob(tmp_path, spec, "-v")
    objs = blob.objects()
    assert len(objs) == 1
    model = blob.models()[objs[0][0]]
    if drawn:
        assert blob.count("SPRITES") == 1 and objs[0][3] == 0
        assert blob.image(0) == decode_patch(patch(w, h, w // 2, h - 2))
        r = max(w // 2, w - w // 2)
        assert blob.mverts()[model[0]][0] == -r << 16 and model[6] == max(1, h - 2) << 16
        render(spec)  # the loader takes it
    else:
        assert blob.count("SPRITES") == blob.count("SPRSETS") == 0 and objs[0][3] == SCN_NONE
        assert "BAR1A0" in proc.stderr and "512" in proc.stderr and "boxes" in proc.stderr, proc.stderr
        assert model[6] == 42 << 16  # the barrel's height in things.txt


def test_mirrored_rotations_and_the_later_lump(tmp_path):
    """Eight rotations from four named pairs and two single lumps; a second lump of a name replaces
    the first; a frame lacking a rotation leaves its type a box (-v says which)."""
    sprites = [("TROOA1", patch(8, 9, 4, 9, 1)), ("TROOA2A8", patch(9, 9, 3, 9, 2)),
               ("TROOA3A7", patch(10, 9, 5, 9, 3)), ("TROOA4A6", patch(11, 9, 6, 9, 4)),
               ("TROOA5", patch(12, 9, 6, 9, 5)), ("TROOA1", patch(13, 9, 6, 12, 6)),
               ("POSSA1", patch(8, 8, 4, 8)), ("POSSA2A8", patch(8, 8, 4, 8))]
    spec = crafted_wad(tmp_path / "rot.wad", sprites, things=((64, 64, 3001), (96, 96, 3004), (32, 32, 3001)))
    blob, proc = compile_blob(tmp_path, spec, "-v")
    objs = blob.objects()
    assert objs[0][3] == objs[2][3] == 0 and objs[1][3] == SCN_NONE
    assert "POSS" in proc.stderr and "3 4 5 6 7" in proc.stderr, proc.stderr
    images, mirror, flags, _ = blob.sprsets()[0]
    assert mirror == 0b11100000 and flags == 0
    assert [blob.image(k)[0] for k in images] == [13, 9, 10, 11, 12, 11, 10, 9]
    assert blob.image(images[0]) == decode_patch(patch(13, 9, 6, 12, 6))
    assert blob.count("SPRITES") == 5
    model = blob.models()[objs[0][0]]
    assert blob.mverts()[model[0]][0] == -7 << 16 and model[6] == 12 << 16  # reach 13 - 6, top 12
    render(spec)


def test_rows_below_the_height_and_holes(tmp_path):
    """Texels are opaque only where a post covers them; a post running below the image's height is cut."""
    spec = crafted_wad(tmp_path / "holes.wad", [("BAR1A0", patch(4, 20, 2, 20, rows=(5, 30)))])
    blob, _ = compile_blob(tmp_path, spec)
    w, h, _, _, texels, opaque = blob.image(0)
    assert (w, h) == (4, 20) and opaque == {(u, v) for u in range(4) for v in range(5, 20)}
    assert all(texels[u][v] == 0 for u in range(4) for v in range(5))


def damaged(kind):
    p = bytearray(patch(8, 8, 4, 8))
    if kind == "column":
        struct.pack_into("<I", p, 8 + 4 * 5, len(p) + 10)
    elif kind == "post":
        p[struct.unpack_from("<I", p, 8 + 4 * 7)[0] + 1] = 200
    else:
        p = p[:6]
    return bytes(p)


@pytest.mark.parametrize("kind, needles", [("column", ["column 5", "past the end"]),
                                           ("post", ["column 7", "runs past the end"]),
                                           ("header", ["shorter than its 8-byte header"])])
def test_damaged_sprite_is_refused(tmp_path, kind, needles):
    spec = crafted_wad(tmp_path / "bad.wad", [("BAR1A0", damaged(kind))])
    blob, proc = compile_blob(tmp_path, spec, check=False)
    assert proc.returncode == 1 and proc.stderr.count("\n") == 1 and blob is None, proc.stderr
    for n in [str(tmp_path / "bad.wad"), "patch BAR1A0", *needles]:
        assert n in proc.stderr, (n, proc.stderr)
    # --flat does not read it as a sprite (the box keeps things.txt's colour)
    blob, proc = compile_blob(tmp_path, spec, "--flat")
    assert blob.count("SPRITES") == 0
