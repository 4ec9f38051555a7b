"""reflook.py - a Doom map's look in the reference renderer: the texel and light of each pixel.

docs/textures.md is the contract; this is its double-precision reading, from the WAD itself (its
own lump reading and patch composition, nothing from the compiled scene). Given what each pixel's
centre ray meets (refrender.cast_view: the surface, its depth, a wall's line and part), expect()
gives per pixel the texture and the exact (u, v), the light table, the colour
lights[table][texel], and the colours a renderer may draw there: lights[t'][texel(u', v')] for t'
within one light step and (u', v') within one texel (the 3 x 3 texels round (u, v), wrapped as the
texture wraps), 27 candidates.

Which pixels are compared (Expect.cat): walls (1), floors (2), ceilings (3) and sky (4) with a
texture, sprites (5: WAD things drawn as their sprites, docs/objects.md "Sprites") and see-through
middle textures (6, "midtex": docs/textures.md "See-through middle textures"). Not
compared (0): no surface, objects drawn as their boxes (flat colours), and parts or planes
without a texture ('-', a name the WAD does not have, or Doom's texture 0, which Doom never draws),
which keep their flat colour. compare() takes the world's pixels where the renderer's id buffer
shows no object, and the sprite and middle texture pixels where it shows the same object as the
reference.

A see-through middle texture's pixel (refrender.cast_view gives its exact column and row): the
texel of the side's middle texture there, wrapped as the texture wraps, under the light of the
side's walls (its sector's light, the fake contrast, Doom's scale light at the pixel's depth).
Its candidates are the 3 x 3 texels round it, a neighbour in a hole standing for the texel
itself, under the tables within one step. The texture's texels and coverage are composed here
(Look.mid_texture: compose(..., cover=True) marks the texels some patch's post covers).

A sprite pixel (refrender.cast_view gives its image and texel): the texel of the image at the
column and row the pixel's centre ray meets (a mirrored image flipped), its light table 0 when the
thing's frame is full-bright, else Doom's light of walls at the sprite's depth zc: start -
min(47, floor(2560 / zc)) / 2 clamped to 0..31, start = (15 - lightnum) * 4, lightnum = light >> 4
(at most 15) of the sector under the thing's origin, without the walls' fake contrast. Its
candidates are the 3 x 3 texels round it that are in the image and opaque (any other stands for
the texel itself), under the tables within one step: 27, as for the world.

Doom's lookups: a texture name is the first of that name in TEXTURE1 then TEXTURE2; a patch or a
flat is the last lump of its name (flats among the F_START..F_END lumps). Holes a texture's patches
leave are texel 0. The sky texture is Doom's: freedoom2/Doom II MAPxx: SKY1 below MAP12, SKY2
below MAP21, else SKY3; ExMy: SKYx.
"""
import copy
import math
import struct

import numpy as np

W, H = 320, 200
FOCAL = 160.0
NLIGHTS = 32
CAT_NONE, CAT_WALL, CAT_FLOOR, CAT_CEIL, CAT_SKY, CAT_SPRITE, CAT_MID = 0, 1, 2, 3, 4, 5, 6
CAT_NAMES = {CAT_WALL: "wall", CAT_FLOOR: "floor", CAT_CEIL: "ceiling", CAT_SKY: "sky",
             CAT_SPRITE: "sprite", CAT_MID: "midtex"}
OBJECT_CATS = (CAT_SPRITE, CAT_MID)   # compared where the renderer shows the same object
UNPEG_TOP, UNPEG_BOTTOM = 8, 16      # Doom's linedef flags


def _name8(b):
    return bytes(b).split(b"\0", 1)[0].decode("latin-1").upper()


class Wad:
    """A WAD's directory: lump(name) the last lump of that name (Doom's W_CheckNumForName)."""

    def __init__(self, path):
        self.data = open(path, "rb").read()
        n, ofs = struct.unpack_from("<II", self.data, 4)
        self.dir = [(*struct.unpack_from("<II", self.data, ofs + 16 * i),
                     _name8(self.data[ofs + 16 * i + 8:ofs + 16 * i + 16])) for i in range(n)]
        self.last = {name: i for i, (_, _, name) in enumerate(self.dir)}
        self.flats = {}
        inside = False
        for i, (_, size, name) in enumerate(self.dir):
            if name in ("F_START", "FF_START"):
                inside = True
            elif name in ("F_END", "FF_END"):
                inside = False
            elif inside and size == 4096:
                self.flats[name] = i

    def body(self, i):
        pos, size, _ = self.dir[i]
        return self.data[pos:pos + size]

    def lump(self, name):
        i = self.last.get(name)
        return None if i is None else self.body(i)


class Texture:
    """Texels cols[u, v] (width x height, column-major as the scene stores them) and Doom's wrap:
    columns at the largest power of two not above the width, rows at the next power of two not
    below the height, the padding rows repeating the texture from its top."""

    def __init__(self, name, cols):
        self.name, self.cols = name, cols
        w, h = cols.shape
        self.width, self.height = w, h
        self.wmask = (1 << (w.bit_length() - 1)) - 1
        self.hmask = (1 << (h - 1).bit_length()) - 1

    def texel(self, u, v):
        """Texels at integer column u and row v (arrays), wrapped."""
        return self.cols[u & self.wmask, (v & self.hmask) % self.height]


def read_patch(data):
    """A patch lump -> (width, height, columns), each column a list of (top, bytes) posts."""
    w, h = struct.unpack_from("<hh", data, 0)
    if w <= 0 or h <= 0 or len(data) < 8 + 4 * w:
        raise ValueError("bad patch")
    cols = []
    for c in range(w):
        (pos,) = struct.unpack_from("<I", data, 8 + 4 * c)
        posts = []
        while pos < len(data) and data[pos] != 0xFF:
            top, n = data[pos], data[pos + 1]
            posts.append((top, data[pos + 3:pos + 3 + n]))
            pos += n + 4
        cols.append(posts)
    return w, h, cols


def compose(width, height, patches, cover=False):
    """Doom's composition: patches [(originx, originy, patch lump)] in order, each post clipped
    to the texture, later over earlier; texel 0 where none covers. cover: return (texels,
    covered) with covered[u, v] True where a post of some patch covers the texel (a texture's
    holes are where it is False: docs/textures.md "See-through middle textures")."""
    cols = np.zeros((width, height), np.uint8)
    covered = np.zeros((width, height), bool)
    for ox, oy, lump in patches:
        _, _, pcols = read_patch(lump)
        for c, posts in enumerate(pcols):
            x = ox + c
            if not 0 <= x < width:
                continue
            for top, px in posts:
                y0 = oy + top
                a, b = max(0, y0), min(height, y0 + len(px))
                if a < b:
                    cols[x, a:b] = np.frombuffer(px, np.uint8)[a - y0:b - y0]
                    covered[x, a:b] = True
    return (cols, covered) if cover else cols


def read_texture_defs(wad):
    """{name: (width, height, [(originx, originy, patch name)])}, TEXTURE1 then TEXTURE2, the
    first of a name winning, and the name of Doom's texture 0 (never drawn)."""
    pn = wad.lump("PNAMES")
    (npn,) = struct.unpack_from("<i", pn, 0)
    pnames = [_name8(pn[4 + 8 * i:12 + 8 * i]) for i in range(npn)]
    defs, first = {}, None
    for lname in ("TEXTURE1", "TEXTURE2"):
        d = wad.lump(lname)
        if d is None:
            continue
        (n,) = struct.unpack_from("<i", d, 0)
        for i in range(n):
            (ofs,) = struct.unpack_from("<i", d, 4 + 4 * i)
            name = _name8(d[ofs:ofs + 8])
            w, h = struct.unpack_from("<hh", d, ofs + 12)
            (np_,) = struct.unpack_from("<h", d, ofs + 20)
            pats = []
            for k in range(np_):
                ox, oy, pi = struct.unpack_from("<hhh", d, ofs + 22 + 10 * k)
                pats.append((ox, oy, pnames[pi] if 0 <= pi < npn else None))
            if first is None:
                first = name
            defs.setdefault(name, (w, h, pats))
    return defs, first


def sky_name(mapname):
    m = mapname.upper()
    if m.startswith("MAP"):
        n = int(m[3:])
        return "SKY1" if n < 12 else "SKY2" if n < 21 else "SKY3"
    return f"SKY{m[1]}"


class Look:
    """A WAD map's look: palette (256, 3), lights (32, 256), per kept line (refrender's numbering)
    its two sidedefs, per sector its light and flats, and textures and flats by name (composed
    when first asked for)."""

    def __init__(self, m):
        if not hasattr(m, "wad_file"):
            raise ValueError(f"{m.name}: not a WAD map: it has no textures")
        self.wad = wad = Wad(m.wad_file)
        self.palette = np.frombuffer(wad.lump("PLAYPAL")[:768], np.uint8).reshape(256, 3)
        self.lights = np.frombuffer(wad.lump("COLORMAP")[:256 * NLIGHTS], np.uint8).reshape(NLIGHTS, 256)
        lumps = m.wad_lumps
        lin = np.frombuffer(lumps["LINEDEFS"], np.dtype([("v1", "<u2"), ("v2", "<u2"), ("fl", "<u2"),
                                                         ("sp", "<u2"), ("tag", "<u2"), ("s0", "<u2"),
                                                         ("s1", "<u2")]))[m.wad_lines]
        sd = np.frombuffer(lumps["SIDEDEFS"], np.dtype([("xo", "<i2"), ("yo", "<i2"), ("up", "S8"),
                                                        ("lo", "S8"), ("mid", "S8"), ("sec", "<u2")]))
        sec = np.frombuffer(lumps["SECTORS"], np.dtype([("f", "<i2"), ("c", "<i2"), ("ff", "S8"),
                                                        ("cf", "S8"), ("light", "<i2"), ("sp", "<i2"),
                                                        ("tag", "<i2")]))
        self.flags = lin["fl"].astype(np.int64)
        s1 = lin["s1"].astype(np.int64)
        self.side_def = np.stack([lin["s0"].astype(np.int64), np.where(s1 == 0xFFFF, -1, s1)], 1)
        self.xoff, self.yoff = sd["xo"].astype(float), sd["yo"].astype(float)
        self.mid_name = [_name8(n) for n in sd["mid"]]      # each sidedef's middle texture name
        self.sector_light = sec["light"].astype(np.int64)
        self.defs, self.tex0 = read_texture_defs(wad)
        self.sky = sky_name(m.name.rsplit(":", 1)[1])
        # texture numbers: names in order of first use; -1 none
        self.names, self._num, self._tex, self._mid = [], {}, {}, {}
        self.side_tex = np.array([[self.number(_name8(r[k]), False) for k in ("up", "mid", "lo")]
                                  for r in sd], np.int64).reshape(len(sd), 3)
        self.floor_tex = np.array([self.number(_name8(n), True) for n in sec["ff"]], np.int64)
        self.ceil_tex = np.array([self.number(_name8(n), True) for n in sec["cf"]], np.int64)
        self.sky_tex = self.number(self.sky, False)

    def sprite_number(self, image):
        """The number of a sprite image (a refrender.SpriteImage) among the names, as
        (lump name, "sprite"); texture() gives the image back."""
        key = (image.name, "sprite")
        if key not in self._num:
            self._num[key] = len(self.names)
            self.names.append(key)
            self._tex[self._num[key]] = image
        return self._num[key]

    def mid_number(self, name):
        """The number of a see-through middle texture (mid_texture(name) has it) among the
        names, as (name, "mid"); texture() gives its texels (a Texture) back."""
        key = (name, "mid")
        if key not in self._num:
            self._num[key] = len(self.names)
            self.names.append(key)
            self._tex[self._num[key]] = self.mid_texture(name)[0]
        return self._num[key]

    def number(self, name, flat):
        key = (name, flat)
        if key not in self._num:
            ok = name in self.wad.flats if flat else (name in self.defs and name != self.tex0)
            self._num[key] = len(self.names) if ok else -1
            if ok:
                self.names.append(key)
        return self._num[key]

    def mid_texture(self, name):
        """A wall texture as a see-through middle texture (docs/textures.md): (texels, cover),
        both Textures (cover's texels 1 where a patch covers the texel, 0 in a hole), when the
        texture has a hole among its shown columns (the largest power of two not above its
        width) and rows; None when it has none, or the WAD has no such texture ('-', unknown) or
        cannot compose it. Doom's texture 0 counts like any other (bspc draws it)."""
        if name not in self._mid:
            got = None
            if name in self.defs:
                w, h, pats = self.defs[name]
                lumps = [(ox, oy, self.wad.lump(p) if p else None) for ox, oy, p in pats]
                try:
                    if any(lump is None for _, _, lump in lumps) or w <= 0 or h <= 0:
                        raise ValueError
                    texels, covered = compose(w, h, lumps, cover=True)
                    shown = 1 << (w.bit_length() - 1)
                    if not covered[:shown].all():
                        got = (Texture(name, texels), Texture(name, covered.astype(np.uint8)))
                except (ValueError, struct.error, IndexError):
                    got = None
            self._mid[name] = got
        return self._mid[name]

    def texture(self, i):
        """Texture number i (a Texture), composed or read on first use; None if it cannot be.
        A sprite's number gives its refrender.SpriteImage."""
        if i not in self._tex:
            name, flat = self.names[i]
            if flat:
                body = self.wad.body(self.wad.flats[name])
                self._tex[i] = Texture(name, np.frombuffer(body, np.uint8).reshape(64, 64).T.copy())
            else:
                w, h, pats = self.defs[name]
                lumps = [(ox, oy, self.wad.lump(p) if p else None) for ox, oy, p in pats]
                try:
                    if any(lump is None for _, _, lump in lumps) or w <= 0 or h <= 0:
                        raise ValueError
                    self._tex[i] = Texture(name, compose(w, h, lumps))
                except (ValueError, struct.error, IndexError):
                    self._tex[i] = None
        return self._tex[i]


_looks = {}


def look_of(m):
    if m.name not in _looks:
        _looks[m.name] = Look(m)
    return _looks[m.name]


# ---- textures by time (docs/textures.md, "Animation") ----------------------------------------

TIC_HZ = 35
ANIM_TICS = 8
# Doom's table (P_InitPicAnims): (flat, first frame, last frame)
DOOM_ANIMS = [(True, "NUKAGE1", "NUKAGE3"), (True, "FWATER1", "FWATER4"), (True, "SWATER1", "SWATER4"),
              (True, "LAVA1", "LAVA4"), (True, "BLOOD1", "BLOOD3"), (True, "RROCK05", "RROCK08"),
              (True, "SLIME01", "SLIME04"), (True, "SLIME05", "SLIME08"), (True, "SLIME09", "SLIME12"),
              (False, "BLODGR1", "BLODGR4"), (False, "SLADRIP1", "SLADRIP3"), (False, "BLODRIP1", "BLODRIP4"),
              (False, "FIREWALA", "FIREWALL"), (False, "GSTFONT1", "GSTFONT3"), (False, "FIRELAV3", "FIRELAVA"),
              (False, "FIREMAG1", "FIREMAG3"), (False, "FIREBLU1", "FIREBLU2"), (False, "ROCKRED1", "ROCKRED3"),
              (False, "BFALL1", "BFALL4"), (False, "SFALL1", "SFALL4"), (False, "WFALL1", "WFALL4"),
              (False, "DBRAIN1", "DBRAIN4")]


def level_tic(time_ms):
    """Doom's level time in tics at time_ms: floor(time_ms * 35 / 1000)."""
    return time_ms * TIC_HZ // 1000


def texture_numbers(wad):
    """Doom's wall texture numbers: the names of TEXTURE1's entries, then TEXTURE2's."""
    names = []
    for lname in ("TEXTURE1", "TEXTURE2"):
        d = wad.lump(lname)
        if d is None:
            continue
        (n,) = struct.unpack_from("<i", d, 0)
        names += [_name8(d[o:o + 8]) for o in struct.unpack_from(f"<{n}i", d, 4)]
    return names


def anim_sequences(wad):
    """{(name, flat): (frames, k, base)}: each frame of each of Doom's sequences the WAD holds (both
    ends there, two frames or more, in the WAD's order: texture numbers, or the flats' lumps), its
    place k in the sequence and the WAD's number of the first frame (P_InitPicAnims)."""
    tnames = texture_numbers(wad)
    tnum = {}
    for i, n in enumerate(tnames):
        tnum.setdefault(n, i)
    fstart = wad.last.get("F_START", wad.last.get("FF_START", -1)) + 1
    out = {}
    for flat, first, last in DOOM_ANIMS:
        if flat:
            if first not in wad.last or last not in wad.last:
                continue
            a, b = wad.last[first], wad.last[last]
            frames, base = [wad.dir[i][2] for i in range(a, b + 1)], a - fstart
        else:
            if first not in tnum or last not in tnum:
                continue
            a, b = tnum[first], tnum[last]
            frames, base = tnames[a:b + 1], a
        if len(frames) >= 2:
            for k, name in enumerate(frames):
                out.setdefault((name, flat), (frames, k, base))
    return out


def scrolled(m):
    """Per sidedef of the map, the lines of special 48 (Doom's scrolling wall) it is the front of:
    its texture moves that many units a tic (P_UpdateSpecials)."""
    lk = look_of(m)
    lin = np.frombuffer(m.wad_lumps["LINEDEFS"], np.dtype([("v1", "<u2"), ("v2", "<u2"), ("fl", "<u2"),
                                                             ("sp", "<u2"), ("tag", "<u2"), ("s0", "<u2"),
                                                             ("s1", "<u2")]))
    front = lin["s0"][(lin["sp"] == 48) & (lin["s0"] < len(lk.xoff))]
    return np.bincount(front.astype(np.int64), minlength=len(lk.xoff))


def look_at(m, time_ms):
    """The look of WAD map m at time_ms: every texture and flat number replaced by the frame its
    sequence shows at level tic T (frame k of a sequence whose first frame is the WAD's number base
    shows frame (T / 8 + base + k) mod n), every scrolling sidedef's x offset moved T units a line."""
    lk = look_of(m)
    tic = level_tic(int(time_ms))
    if not hasattr(lk, "anims"):
        lk.anims, lk.scroll = anim_sequences(lk.wad), scrolled(m)
    if not lk.anims and not lk.scroll.any():
        return lk
    at = copy.copy(lk)

    def shown(nums, flat):
        out = np.array(nums, np.int64)
        for i in np.unique(out[out >= 0]):
            key = lk.names[int(i)]
            if key in lk.anims:
                frames, k, base = lk.anims[key]
                out[out == i] = lk.number(frames[(tic // ANIM_TICS + base + k) % len(frames)], flat)
        return out

    at.side_tex = shown(lk.side_tex, False)
    at.floor_tex, at.ceil_tex = shown(lk.floor_tex, True), shown(lk.ceil_tex, True)
    at.xoff = lk.xoff + tic * lk.scroll
    return at


def wall_table(start, z):
    """Doom's scale light: start - min(47, floor(2560 / z)) / 2, clamped to 0..31."""
    with np.errstate(divide="ignore"):
        j = np.minimum(47, np.floor(2560.0 / z))
    return np.clip(start - (j.astype(np.int64) // 2), 0, NLIGHTS - 1)


def plane_table(start, z):
    """Doom's z light: start - floor(160 / (min(127, floor(z / 16)) + 1)) / 2, clamped."""
    j = np.minimum(127, np.floor(z / 16.0)).astype(np.int64)
    return np.clip(start - (160 // (j + 1)) // 2, 0, NLIGHTS - 1)


def light_start(light, adj):
    lightnum = np.clip((light >> 4) + adj, 0, 15)
    return (15 - lightnum) * 4


class Expect:
    """Per pixel (200, 320): cat (CAT_*), tex (texture number in look.names, -1; a sprite
    image's entry is (lump name, "sprite")), u, v (float: the exact texture coordinates; for the
    sky, the column and row; for a sprite, its image's), table (light table), ids (the
    reference's surface ids), colour (the palette index; 0 where not compared) and cand (200,
    320, 27): the acceptable palette indices (every one of them colour where not compared)."""

    def accept(self, frame):
        """Boolean (200, 320): the frame's palette index is one of the candidates."""
        return (self.cand == np.asarray(frame, np.uint8)[..., None]).any(-1)


def expect(view):
    """The Expect of a refrender.View of a WAD map."""
    m = view.scene
    lk = look_at(m, getattr(view, "time_ms", 0))
    e = Expect()
    e.look = lk
    e.ids = view.ids
    kind = (view.ids >> 24).astype(np.int64)
    index = (view.ids & 0xFFFFFF).astype(np.int64)
    e.cat = np.zeros((H, W), np.int8)
    e.tex = np.full((H, W), -1, np.int64)
    e.u, e.v = np.full((H, W), np.nan), np.full((H, W), np.nan)
    e.table = np.zeros((H, W), np.int64)
    rr, cc = np.mgrid[0:H, 0:W]
    t = view.t
    px = view.x + t * view.dx[None, :]
    py = view.y + t * view.dy[None, :]
    pz = view.z + t * view.yv[:, None]

    # walls
    w = (kind == 1) & (view.part >= 0) & (view.part <= 2)
    line, part, side = view.line[w], view.part[w].astype(np.int64), index[w] & 1
    sd = lk.side_def[line, side]
    near = np.where(side == 0, m.front[line], m.back[line])
    far = np.where(side == 0, m.back[line], m.front[line])
    tex = np.where(sd >= 0, lk.side_tex[np.maximum(sd, 0), part], -1)
    texh = np.zeros(len(tex))
    for i in np.unique(tex[tex >= 0]):
        tx = lk.texture(int(i))
        if tx is None:
            tex[tex == i] = -1
        else:
            texh[tex == i] = tx.height
    ceil, floor = view.ceil, m.floor
    fl = lk.flags[line]
    farc, farf = ceil[np.maximum(far, 0)], floor[np.maximum(far, 0)]
    top = np.select([part == 0, part == 1],
                    [np.where(fl & UNPEG_TOP, ceil[near], farc + texh),
                     np.where(fl & UNPEG_BOTTOM, floor[near] + texh, ceil[near])],
                    np.where(fl & UNPEG_BOTTOM, ceil[near], farf))
    ox = np.where(side == 0, m.x1[line], m.x2[line])
    oy = np.where(side == 0, m.y1[line], m.y2[line])
    ux, uy = m.x2[line] - m.x1[line], m.y2[line] - m.y1[line]
    ln = np.hypot(ux, uy)
    sgn = np.where(side == 0, 1.0, -1.0)
    ux, uy = sgn * ux / ln, sgn * uy / ln
    sdi = np.maximum(sd, 0)
    e.u[w] = ux * (px[w] - ox) + uy * (py[w] - oy) + lk.xoff[sdi]
    e.v[w] = top - pz[w] + lk.yoff[sdi]
    adj = np.where(m.y1[line] == m.y2[line], -1, np.where(m.x1[line] == m.x2[line], 1, 0))
    e.table[w] = wall_table(light_start(lk.sector_light[near], adj), t[w])
    e.tex[w] = tex
    e.cat[w] = np.where(tex >= 0, CAT_WALL, CAT_NONE)

    # floors and ceilings; the sky
    sky = ((kind == 3) & (view.part == 3)) | ((kind == 3) & m.sky[np.where(kind == 3, index, 0)])
    p = ((kind == 2) | (kind == 3)) & ~sky
    sec = index[p]
    tex = np.where(kind[p] == 2, lk.floor_tex[sec], lk.ceil_tex[sec])
    e.tex[p] = tex
    e.u[p], e.v[p] = px[p], -py[p]
    e.table[p] = plane_table(light_start(lk.sector_light[sec], 0), t[p])
    e.cat[p] = np.where(tex < 0, CAT_NONE, np.where(kind[p] == 2, CAT_FLOOR, CAT_CEIL))
    if lk.sky_tex >= 0 and lk.texture(lk.sky_tex) is not None:
        a = view.angle + np.degrees(np.arctan((FOCAL - (np.arange(W) + 0.5)) / FOCAL))
        e.u[sky] = (a[None, :] * 1024.0 / 360.0 + 0 * rr)[sky]
        e.v[sky] = ((rr - view.look) & 127)[sky]
        e.table[sky] = 0
        e.tex[sky] = lk.sky_tex
        e.cat[sky] = CAT_SKY

    # colours: the exact one and the 27 candidates, texture by texture
    e.colour = np.zeros((H, W), np.uint8)
    e.cand = np.zeros((H, W, 27), np.uint8)
    _sprites(view, lk, e)
    _mids(view, lk, e)
    on = (e.cat > 0) & ~np.isin(e.cat, OBJECT_CATS)
    ui = np.floor(np.where(on, e.u, 0)).astype(np.int64)
    vi = np.floor(np.where(on, e.v, 0)).astype(np.int64)
    du, dv = np.meshgrid([-1, 0, 1], [-1, 0, 1], indexing="ij")
    du, dv = du.ravel(), dv.ravel()
    for i in np.unique(e.tex[on]):
        sel = on & (e.tex == i)
        tx = lk.texture(int(i))
        u0, v0, tb = ui[sel], vi[sel], e.table[sel]
        e.colour[sel] = lk.lights[tb, tx.texel(u0, v0)]
        near9 = tx.texel(u0[:, None] + du[None, :], v0[:, None] + dv[None, :])          # (n, 9)
        tabs = np.clip(tb[:, None] + np.array([-1, 0, 1])[None, :], 0, NLIGHTS - 1)     # (n, 3)
        e.cand[sel] = lk.lights[tabs[:, :, None], near9[:, None, :]].reshape(-1, 27)
    e.cand[e.cat == CAT_NONE] = 0
    return e


def sprite_table(lk, draw):
    """The light table of a sprite (a refrender.SpriteDraw): 0 when full-bright, else Doom's
    light of walls at its depth zc in the light of the sector under its origin (lightnum =
    light >> 4, no fake contrast; no sector: light 0)."""
    if draw.bright:
        return 0
    light = lk.sector_light[draw.sector] if draw.sector is not None else 0
    return int(wall_table(light_start(np.array([light]), 0), np.array([draw.zc]))[0])


def _sprites(view, lk, e):
    """The sprite pixels of a view: cat, tex (the image's number), u, v, table, the colour
    lights[table][texel] and the candidates: the 3 x 3 texels round it (a neighbour outside
    the image or transparent counts as the texel itself) under the tables within one step."""
    du, dv = np.meshgrid([-1, 0, 1], [-1, 0, 1], indexing="ij")
    du, dv = du.ravel(), dv.ravel()
    for d in getattr(view, "sprites", None) or []:
        if d is None:
            continue
        sel = (view.obj == d.obj) & (view.spr_col >= 0)
        if not sel.any():
            continue
        im = d.image
        c0, r0 = view.spr_col[sel], view.spr_row[sel]
        table = sprite_table(lk, d)
        e.cat[sel] = CAT_SPRITE
        e.tex[sel] = lk.sprite_number(im)
        e.u[sel], e.v[sel] = view.spr_u[sel], view.spr_v[sel]
        e.table[sel] = table
        texel = im.texels[c0, r0]
        e.colour[sel] = lk.lights[table, texel]
        cn, rn = c0[:, None] + du[None, :], r0[:, None] + dv[None, :]          # (n, 9)
        inside = (cn >= 0) & (cn < im.width) & (rn >= 0) & (rn < im.height)
        cn, rn = np.clip(cn, 0, im.width - 1), np.clip(rn, 0, im.height - 1)
        usable = inside & im.opaque[cn, rn]
        near9 = np.where(usable, im.texels[cn, rn], texel[:, None])
        tabs = np.clip(table + np.array([-1, 0, 1]), 0, NLIGHTS - 1)              # (3,)
        e.cand[sel] = lk.lights[tabs[None, :, None], near9[:, None, :]].reshape(-1, 27)


def _mids(view, lk, e):
    """The see-through middle texture pixels of a view (refrender.MidDraw; docs/textures.md):
    cat, tex (the texture's number as (name, "mid")), u, v (the exact column and row), table
    (the light of the side's walls: its sector's light, the fake contrast, the scale light at
    the pixel's depth), the colour lights[table][texel] and the candidates: the 3 x 3 texels
    round it (a neighbour in a hole counts as the texel itself) under the tables within one
    step."""
    du, dv = np.meshgrid([-1, 0, 1], [-1, 0, 1], indexing="ij")
    du, dv = du.ravel(), dv.ravel()
    for d in getattr(view, "mids", None) or []:
        if d is None:
            continue
        sel = (view.obj == d.obj) & ~np.isnan(view.mid_u)
        if not sel.any():
            continue
        mid = d.mid
        tex, cover = mid.tex, mid.cover
        u0 = np.floor(view.mid_u[sel]).astype(np.int64)
        v0 = np.floor(view.mid_v[sel]).astype(np.int64)
        table = wall_table(light_start(lk.sector_light[mid.sector], mid.adj), view.obj_t[sel])
        e.cat[sel] = CAT_MID
        e.tex[sel] = lk.mid_number(mid.name)
        e.u[sel], e.v[sel] = view.mid_u[sel], view.mid_v[sel]
        e.table[sel] = table
        texel = tex.texel(u0, v0)
        e.colour[sel] = lk.lights[table, texel]
        un, vn = u0[:, None] + du[None, :], v0[:, None] + dv[None, :]           # (n, 9)
        near9 = np.where(cover.texel(un, vn) != 0, tex.texel(un, vn), texel[:, None])
        tabs = np.clip(table[:, None] + np.array([-1, 0, 1])[None, :], 0, NLIGHTS - 1)  # (n, 3)
        e.cand[sel] = lk.lights[tabs[:, :, None], near9[:, None, :]].reshape(-1, 27)


def compare(e, frame, ids=None):
    """Compare a renderer's frame (200, 320 palette indices) with an Expect: the pixels compared
    are those with a texture in the reference and no object in the renderer's id buffer (ids,
    optional), and the reference's sprite and middle texture pixels where the renderer's id
    buffer shows the same object. Returns (ok (200, 320) bool, compared (200, 320) bool,
    counts {category name: (acceptable, compared)}, with "all")."""
    frame = np.asarray(frame, np.uint8).reshape(H, W)
    compared = e.cat > 0
    if ids is not None:
        ids = np.asarray(ids).reshape(H, W)
        compared &= np.where(np.isin(e.cat, OBJECT_CATS), ids == e.ids, (ids >> 24) != 4)
    ok = e.accept(frame) & compared
    counts = {name: (int(ok[e.cat == c].sum()), int(compared[e.cat == c].sum()))
              for c, name in CAT_NAMES.items()}
    counts["all"] = (int(ok.sum()), int(compared.sum()))
    return ok, compared, counts


def diff_rgb(e, frame, ok, compared):
    """RGB (200, 320, 3): the frame in its palette, dimmed where not compared, failures red."""
    rgb = e.look.palette[np.asarray(frame, np.uint8).reshape(H, W)].astype(np.uint16)
    rgb[~compared] = rgb[~compared] // 3
    rgb[compared & ~ok] = (255, 0, 0)
    return rgb.astype(np.uint8)
