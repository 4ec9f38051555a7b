#!/usr/bin/env python3
"""refrender.py - the float reference renderer: surface ids by ray casting, without the BSP tree.

It reads the SOURCE map (a text scene, docs/scene-format.md, or a Doom-format map `file.wad:MAP01`)
and casts one ray through the centre of each of the 320x200 pixels, in double precision, against
every wall of the map. The output is the surface-id buffer of /work/shared/DESIGN.md: 320x200
uint32, row-major, id = kind << 24 | index (0 nothing, 1 wall = linedef*2 + side, 2 floor = sector,
3 ceiling = sector, 4 object = object). It is the yardstick for the integer renderer's id buffers
(tools/accuracy.py).

Reading, numbered exactly as build/bspc numbers them (tools/bspc/scene_text.c, wad.c):
- text scene: sectors in declaration order, walls in file order; numbers rounded to 16.16
  (nearest, ties away from zero), as bspc does, so both see the same geometry.
- WAD: the last marker lump of the name wins; the first THINGS/LINEDEFS/SIDEDEFS/VERTEXES/SECTORS
  after it; linedefs whose two vertices are at the same point are skipped (the numbers after one
  shift down); sidedef 0 is the front (sector[0], right of v1 -> v2), sidedef 1 the back; a
  linedef is two-sided when it has a second sidedef. A ceiling flat F_SKY* is a sky. The player
  start is the last thing of type 1 (Doom spawns the player at each; the last one is the player).

Camera (DESIGN.md "Camera", as the C renderer): x east, y north, angle in degrees, 0 = east,
counter-clockwise; forward f = (cos a, sin a), right r = (sin a, -cos a). Pixel (px, py):
xv = (px + 0.5 - 160) / 160, yv = (100 + look - (py + 0.5)) / 160 (plus the tie-break below, TIE_DX). The ray's map-plane direction
is d = f + xv * r, so its point at forward depth t (distance along f) is eye + t * d, at height
eye_z + yv * t. Hits at t < 1/1024 (the near plane) are ignored. The camera values are rounded to
16.16 first, as build/render rounds them; the trigonometry is exact (double).

What a ray sees (Doom's rules, as the C renderer draws them). The ray's 2-D line is walked from
the eye's sector through the walls it crosses, in order of depth. The sector sequence does not
depend on the pixel row, so for each column the crossings are sorted once and every row is
decided with arrays:
- inside the current sector S, between two crossings at depths t0 < t1, the ray hits S's floor
  (kind 2, S) if it goes down through the floor's height there, or S's ceiling (kind 3, S; a sky
  too) if it goes up through the ceiling's height. (Height is linear in t: the ends decide.)
- at a crossing of linedef L, "side" is the side of L the eye is on (0 front/right, 1 back/left),
  N = L's sector on that side, B = the one on the far side. No N (the back of a one-sided wall:
  only with the eye outside the map): back-face culled, the ray passes. One-sided (no B): the
  wall, kind 1, L*2 + side. Two-sided: the upper part (height > B.ceil, when B.ceil < N.ceil and
  not both ceilings sky) or the lower part (height < B.floor, when B.floor > N.floor) is the
  wall, same id; otherwise the ray goes on into B.
- Doom's sky rule: between two sky ceilings there is no upper wall; a ray that goes over it
  (max(B.ceil, N.floor) < height <= N.ceil: where the upper wall would be) sees sky at once:
  kind 3 of N (default, `sky_owner="near"`: Doom's visplane owner, and what build/render draws)
  or of B (`"far"`).
- after a crossing the current sector is the far-side sector (B, or L's front for a one-sided wall
  crossed from behind). Past the last crossing the ray meets the current sector's floor or
  ceiling (yv is never 0), or nothing (kind 0) when there is none.
For an eye inside its sector and between its floor and ceiling these are exactly the rules above.
Beyond that (eye outside the map, or outside its sector's heights, or a map whose sectors are not
closed) the reference draws what is geometrically there, as the C renderer's polygons are: a plane
is seen only from its own side (a floor from above, a ceiling from below), a wall part only
between its own bottom and top heights (one-sided: N.floor..N.ceil; upper: max(B.ceil,
N.floor)..N.ceil; lower: N.floor..min(B.floor, N.ceil)), and N is the line's own sector on the
eye's side rather than the walk's (the C renderer's seg front sector), so an eye outside all
sectors starts in none (no floor, no ceiling) and rays pass through walls seen from behind until
they enter a sector. A wall whose end is exactly on the ray counts as crossed (the ends are
inclusive). An eye exactly on a wall or vertex crosses it at depth 0, which the near plane
ignores; each ray then starts in the near-side sector of the first wall it crosses (the sector it
really goes into) rather than in the eye's sector, and a ray that crosses no wall (it leaves the
map at once: the eye is on the map's outer edge, looking out) sees nothing. Likewise a wall the
ray crosses nearer than the near plane is not seen, but the ray goes through it: it reaches the
near plane in the far-side sector of the last such wall (none past a one-sided wall), as the C
renderer's near-clipped polygons show.

Objects (docs/objects.md). Text scenes: `model NAME` ... `end` blocks of `part box w= d= h=
[at=X,Y,Z]` (vertices at at + (+-W/2, +-D/2, 0 or H), a half of an odd number of 1/65536 units
rounded away from the centre) and `part prism sides=N r=R h=H [at=...]` (vertex k of the bottom
at at + R (cos 360k/N, sin 360k/N), the offset rounded to 16.16, then the same ring H higher),
as tools/bspc/models.c builds them; models numbered in declaration order; `object
MODEL X Y [z=] [yaw=] [path=circle:R:MS | line:DX:DY:MS] [spin=]` numbered in file order, z by
default the floor of the sector under (X, Y); `door=H` a sector's open ceiling. WAD maps: the
things of tools/bspc/things.txt (type radius height colour sprite frame name) that are in skill 3,
not multiplayer-only, not at x or y = -32768 and inside a sector, in THINGS order, each an upright
box 2r x 2r x height on the floor under it, yawed by its angle, one model per distinct (radius,
height, colour) in order of first use; a thing drawn as a sprite (below) has the box of its
images instead: r the largest of left and width - left, height the largest top, over the images
of its rotations (at least 1). WAD doors: the back sector of a line with a door special,
or for the remote specials 63 and 90 the sectors with the line's tag; open at the lowest ceiling
across their two-sided lines - 4, never below their own. Yaws are taken modulo 360.
object_states() gives the objects at a time t along their paths in exact arithmetic. A model's yaw turns model x (forward) towards map
y: world = origin + (x cos yaw - y sin yaw, x sin yaw + y cos yaw, z).

Each object part is a convex solid, the intersection of its faces' half-spaces (planes in world
space, double precision). A ray meets it over [t_in, t_out], t_in the largest depth at which it
enters a face's half-space and t_out the smallest at which it leaves one (Cyrus-Beck, done per
face over all pixels at once with numpy: the ray's component along a face normal is a sum of a
per-column and a per-row term, restricted to the part's screen bounding box when it is wholly in
front of the near plane); the part is seen at depth t_in when t_in < t_out (a ray grazing an edge
or vertex sees nothing) and t_in >= the near plane, which is what the C renderer's clipped,
back-face-culled faces show: an eye inside a part, or a part cut by the near plane, sees nothing
of it where its front faces are behind the near plane. The nearest part of any object wins; the
object wins a pixel where its depth is smaller than the world's (the depth of whichever wall,
floor or ceiling event above decided the pixel), and the pixel gets 4 << 24 | object index.
The tie-break samples (TIE_DX, TIE_DY) are the same rays, so exact ties at object edges fall as
the top-left fill rule has them. Doors: render_ids(ceilings={sector: h}) replaces those ceilings
(a closed door is a sector whose ceiling is its floor).

Sprites (docs/objects.md "Sprites"). A WAD map with its look (bspc compiles it textured: the WAD
has PLAYPAL and COLORMAP and the map uses a texture or flat the WAD has; not --flat) draws each
thing whose type has a usable sprite as that sprite, never its box; text scenes and --flat are
boxes only. The images are read from the WAD here (its own patch decoder, nothing from bspc): the
lumps between S_START and S_END (or SS_START/SS_END), the last of a name winning, named SSSSFR or
SSSSFRFR with SSSS things.txt's sprite and F its frame (the second pair: that rotation shows the
image mirrored left to right; a later lump takes a rotation from an earlier one). The frame's
rotation-0 image serves every rotation when there is one, else its eight rotations 1..8 must all
be there; otherwise, or when an image is not a readable patch within the loader's limits (1..512
texels each way, offsets within +-1024), the type stays a box. For the eye E and the origin O
(the object's position as drawn), theta = atan2(O - E) in degrees, rotation r = floor(((theta -
yaw + 202.5) mod 360) / 45) (image of Doom's rotation r + 1; r = 0 when O = E). The image is a
rectangle in the plane z = zc through O parallel to the screen (zc O's forward depth, xc its
lateral position): lateral X in [xc - left, xc - left + width), heights in (O.z + top - height,
O.z + top] and not below O.z (cut at the floor), one texel a map unit. The pixel's centre ray (the
tie-break sample) meets that plane at X = xv zc and height eye_z + yv zc: column floor(X - (xc -
left)) (a mirrored image: width - 1 - that), row floor(O.z + top - height met); the sprite has the
pixel where that texel is opaque (a post covers it) and zc is nearer than everything else there
(the world, the other objects' faces and sprites; between objects an exact tie goes to the lower
object number, against the world to the world); a transparent texel lets the ray go on. A sprite
with zc < 4 is not drawn. Objects keep the scene's numbering (THINGS order, as bspc's): an object
list given to cast_view (build/render's JSON) draws its object i as the sprite of the scene's
object i (its thing type) at the position given. The View records each pixel's texel of its
sprite image for tools/reflook.py.

See-through middle textures (docs/textures.md "See-through middle textures"). In a WAD map with its
look, each side of a two-sided line whose middle texture has holes is an object (MidSide), after
the things' objects: in line order, side 0 before side 1, each with a model of its own (one quad)
after the things' models, as bspc numbers them (tools/bspc/mids.c). The texture and its coverage
are composed here from TEXTURE1/TEXTURE2, PNAMES and the patches (tools/reflook.py: Look.mid_texture);
it has holes when a texel of its shown columns (the largest power of two not above its width) and
rows is covered by no patch's post. Its quad: the whole line, heights [max(max floor, row0 - H),
min(min ceiling, row0)] with row0 = (lower-unpegged ? max floor + H : min ceiling) + yoff (the
compiled heights: doors closed), none when empty, none when the line's half-length along x or y
or the strip's distance from row0 - yoff exceeds 1024 units; the object's origin is the line's
middle at z = row0 - yoff, yaw 0. The pixel's centre ray (the tie-break sample) meets the quad,
seen only from its side's front (the right of the line going from the side's left end to its
right end, the ends and heights inclusive), at forward depth t >= the near plane, point P,
height h: column u(P) = U . (P - O) + xoff of the side's walls, row floor(z + yoff - h) (z the
object's z as given), both wrapped as the texture wraps; the object has the pixel where that
texel is covered and t is nearer than everything else (ties as for sprites); through a hole the
ray goes on. An object list given to cast_view draws its object i as the scene's object i's
middle texture when that is one: its quad (the model's vertices) at the position and yaw given,
its texel column from the quad's left end (the side's origin O, as compiled), its row from the z
given; the model number given is only checked to exist. The View records each such pixel's exact
(u, v) (mid_u, mid_v) for tools/reflook.py (light: the side's walls', at depth t).

Eye sector (default eye height = its floor + 41, or 41 in none): even-odd ray crossing over each
sector's lines (a line with the sector on both sides counts twice and cancels); if several
sectors claim the point (a map whose sectors overlap), the one facing the point across the
nearest line crossing the ray to +x wins.

Colours (a WAD map; tools/reflook.py, docs/textures.md): --raw writes the expected frame (64,000
palette indices, 0 where not compared: objects drawn as boxes, nothing, no texture), --expect an
.npz of the per-pixel category, texture, u, v, light table, colour and the 27 acceptable colours,
--colour-png the expected frame in the WAD's palette. The colours are of the world, the
sprites (a sprite pixel: lights[table][texel], table 0 when its frame is full-bright, else the
light of walls at depth zc in the light of the sector under its origin; tools/reflook.py) and
the see-through middle textures (the light of the side's walls at the pixel's depth).

usage: tools/refrender.py SCENE --at X,Y[,Z] --angle DEG [--look PX] [--ids OUT.bin] [--png OUT.png]
                          [--raw OUT.raw] [--expect OUT.npz] [--colour-png OUT.png]
                          [--sky-owner far|near] [--time MS] [--no-objects] [--flat]
                          [--door SECTOR=H]...
"""
import argparse
import math
import os
import struct
import sys
from fractions import Fraction

import numpy as np

W, H = 320, 200
FOCAL = 160.0
EYE_HEIGHT = 41.0
ZNEAR = 1.0 / 1024.0
# The C renderer's top-left fill rule, as a sample point: a pixel centre exactly on an edge belongs
# to the surface right of the edge, or below it when the edge is horizontal. Sampling a hair right
# of the centre and a far smaller hair below it decides exact ties the same way and moves nothing
# else (both are far below the C renderer's own 2^-16 pixel rounding).
TIE_DX = 2.0 ** -20
TIE_DY = 2.0 ** -40
KIND_NONE, KIND_WALL, KIND_FLOOR, KIND_CEIL, KIND_OBJECT = 0, 1, 2, 3, 4
NONE = -1


class Map:
    """A source map: lines (v1, v2 as float coordinates, front and back sector), sectors."""

    def __init__(self, name, x1, y1, x2, y2, front, back, floor, ceil, sky, player,
                 models=(), objects=(), open_h=None):
        self.name = name
        self.x1, self.y1 = np.asarray(x1, float), np.asarray(y1, float)
        self.x2, self.y2 = np.asarray(x2, float), np.asarray(y2, float)
        self.front = np.asarray(front, np.int64)       # sector on the right of v1 -> v2
        self.back = np.asarray(back, np.int64)         # NONE for one-sided
        self.floor = np.asarray(floor, float)
        self.ceil = np.asarray(ceil, float)
        self.sky = np.asarray(sky, bool)
        self.player = player                           # (x, y, angle)
        self.models = list(models)                     # Model, numbered as bspc numbers them
        self.objects = list(objects)                   # SceneObject, in file / THINGS order
        self.open_h = self.ceil.copy() if open_h is None else np.asarray(open_h, float)
        self.sprites = [None] * len(self.objects)     # each object's SpriteSet, None: its model
        self.mids = [None] * len(self.objects)        # each object's MidSide, None: not one
        self.textured = False                          # a WAD map drawn with its look and sprites

    @property
    def nlines(self):
        return len(self.front)

    @property
    def nsectors(self):
        return len(self.floor)


# ---- numbers ------------------------------------------------------------------------------

def fx_round(value):
    """A decimal string or number rounded to the nearest 1/65536, ties away from zero (fxtext.c)."""
    f = Fraction(value) * 65536
    q = abs(f)
    n = int(q)
    if (q - n) * 2 >= 1:
        n += 1
    return (n if f >= 0 else -n) / 65536.0


def _num(tok, what):
    try:
        if not tok or tok.lstrip("+-")[:1] not in "0123456789.":
            raise ValueError
        return fx_round(tok)
    except (ValueError, ZeroDivisionError):
        raise ValueError(f"{what}: '{tok}' is not a number") from None


# ---- models and objects (docs/objects.md) -------------------------------------------------

class Model:
    """A model: convex parts, each (verts, faces): verts an (n, 3) array in model space (x
    forward, y left, z up, rounded to 16.16 as bspc stores them), faces lists of vertex numbers
    counter-clockwise seen from outside."""

    def __init__(self, name, parts=()):
        self.name = name
        self.parts = list(parts)


class SceneObject:
    """An object statement (or a WAD thing): model number, position (z None: the floor under
    (x, y)), yaw in degrees, path ("none", "circle", "line") with pa, pb, period_ms, and spin in
    degrees per second."""

    def __init__(self, model, x, y, z=None, yaw=0.0, path="none", pa=0.0, pb=0.0, period_ms=0,
                 spin=0.0):
        self.model, self.x, self.y, self.z, self.yaw = model, x, y, z, yaw
        self.path, self.pa, self.pb, self.period_ms, self.spin = path, pa, pb, period_ms, spin


def _round_away(v):
    """The nearest integer, ties away from zero."""
    return math.floor(v + 0.5) if v >= 0 else -math.floor(-v + 0.5)


def box_part(w, d, h, at=(0.0, 0.0, 0.0)):
    """A box W along x, D along y, H along z, its bottom face centred on `at`. Its corners are
    at +-half the size, a half of an odd number of 1/65536 units rounded away from the centre
    (as bspc builds them, tools/bspc/models.c)."""
    ax, ay, az = at
    hw, hd = math.ceil(w * 65536 / 2) / 65536, math.ceil(d * 65536 / 2) / 65536
    zs = (az, az + h)
    # vertex number = 4 * level + corner, corners counter-clockwise seen from above
    corners = [(ax - hw, ay - hd), (ax + hw, ay - hd), (ax + hw, ay + hd), (ax - hw, ay + hd)]
    verts = np.array([(cx, cy, z) for z in zs for cx, cy in corners], float)
    faces = [[3, 2, 1, 0], [4, 5, 6, 7]] + [[i, (i + 1) % 4, 4 + (i + 1) % 4, 4 + i] for i in range(4)]
    return verts, faces


def prism_part(sides, r, h, at=(0.0, 0.0, 0.0)):
    """An upright prism on the regular N-gon of circumradius R round `at`, the first vertex at
    angle 0, counter-clockwise seen from above; each corner's offset from `at`, R (cos, sin) of
    360 k / N degrees, rounded to 16.16 (nearest, ties away from zero), as bspc builds it."""
    ax, ay, az = at
    ring = [(ax + _round_away(r * 65536 * math.cos(2 * math.pi * k / sides)) / 65536,
             ay + _round_away(r * 65536 * math.sin(2 * math.pi * k / sides)) / 65536)
            for k in range(sides)]
    zs = (az, az + h)
    verts = np.array([(cx, cy, z) for z in zs for cx, cy in ring], float)
    n = sides
    faces = [list(range(n - 1, -1, -1)), list(range(n, 2 * n))] + \
        [[i, (i + 1) % n, n + (i + 1) % n, n + i] for i in range(n)]
    return verts, faces


def _kv(tokens, what):
    kv = {}
    for t in tokens:
        if "=" not in t:
            raise ValueError(f"{what}: expected KEY=VALUE, got '{t}'")
        k, v = t.split("=", 1)
        if k in kv:
            raise ValueError(f"{what}: {k} given twice")
        kv[k] = v
    return kv


def _triple(v, what):
    parts = v.split(",")
    if len(parts) != 3:
        raise ValueError(f"{what}: expected X,Y,Z, got '{v}'")
    return tuple(_num(c, what) for c in parts)


def parse_part(tok):
    """A `part box ...` or `part prism ...` statement's solid."""
    if len(tok) < 2 or tok[1] not in ("box", "prism"):
        raise ValueError("part: expected 'box' or 'prism'")
    kv = _kv(tok[2:], f"part {tok[1]}")
    at = _triple(kv["at"], "part: at") if "at" in kv else (0.0, 0.0, 0.0)
    if tok[1] == "box":
        return box_part(_num(kv["w"], "part: w"), _num(kv["d"], "part: d"), _num(kv["h"], "part: h"), at)
    sides = int(kv["sides"])
    if not 3 <= sides <= 16:
        raise ValueError(f"part prism: sides={sides}, expected 3..16")
    return prism_part(sides, _num(kv["r"], "part: r"), _num(kv["h"], "part: h"), at)


def parse_object(tok, model_names, nmodels):
    """An `object MODEL X Y [z=Z] [yaw=DEG] [path=...] [spin=S]` statement."""
    ref = tok[1]
    if ref in model_names:
        model = model_names[ref]
    elif ref.isdigit() and int(ref) < nmodels:
        model = int(ref)
    else:
        raise ValueError(f"object: unknown model '{ref}'")
    o = SceneObject(model, _num(tok[2], "object: x"), _num(tok[3], "object: y"))
    kv = _kv(tok[4:], "object")
    if "z" in kv:
        o.z = _num(kv["z"], "object: z")
    if "yaw" in kv:
        o.yaw = _num(kv["yaw"], "object: yaw") % 360.0
    if "spin" in kv:
        o.spin = _num(kv["spin"], "object: spin")
    if "path" in kv:
        f = kv["path"].split(":")
        if f[0] == "circle" and len(f) == 3:
            o.path, o.pa, o.period_ms = "circle", _num(f[1], "path: R"), int(f[2])
        elif f[0] == "line" and len(f) == 4:
            o.path, o.pa, o.pb = "line", _num(f[1], "path: DX"), _num(f[2], "path: DY")
            o.period_ms = int(f[3])
        else:
            raise ValueError(f"object: path '{kv['path']}': expected circle:R:PERIOD_MS or "
                             "line:DX:DY:PERIOD_MS")
        if o.period_ms <= 0:
            raise ValueError("object: a path's period must be > 0")
    return o


# ---- text scenes --------------------------------------------------------------------------

def read_text(path):
    names, floor, ceil, sky, open_h = {}, [], [], [], []
    x1, y1, x2, y2, front, back = [], [], [], [], [], []
    player = None
    models, model_names, objects = [], {}, []
    in_model = None

    def sector_ref(tok, lineno):
        if tok[:1].isdigit():      # a number, read as strtol(tok, 0) reads it: 0x.. hex, 0.. octal
            base = 16 if tok[:2].lower() == "0x" else 8 if tok[:1] == "0" and len(tok) > 1 else 10
            try:
                i = int(tok[2:] if base == 16 else tok, base)
            except ValueError:
                i = len(floor)
            if i < len(floor):
                return i
        elif tok in names:
            return names[tok]
        raise ValueError(f"{path}:{lineno}: wall: unknown sector '{tok}'")

    with open(path, "r", encoding="utf-8", errors="replace") as fh:
        for lineno, line in enumerate(fh, 1):
            tok = line.split("#", 1)[0].split()
            if not tok:
                continue
            try:
                if in_model is not None and tok[0] not in ("part", "end"):
                    raise ValueError(f"model {in_model.name}: '{tok[0]}' before 'end'")
                if tok[0] == "model":
                    if len(tok) != 2:
                        raise ValueError("model: expected 'model NAME'")
                    in_model = Model(tok[1])
                    model_names[tok[1]] = len(models)
                    models.append(in_model)
                elif tok[0] == "part":
                    if in_model is None:
                        raise ValueError("part outside a model")
                    in_model.parts.append(parse_part(tok))
                elif tok[0] == "end":
                    if in_model is None or not in_model.parts:
                        raise ValueError("end without a model of one part or more")
                    in_model = None
                elif tok[0] == "object":
                    objects.append(parse_object(tok, model_names, len(models)))
                elif tok[0] == "sector":
                    i = 1
                    if i < len(tok) and "=" not in tok[i] and tok[i] != "sky":
                        names[tok[i]] = len(floor)
                        i += 1
                    kv = {}
                    is_sky = False
                    for t in tok[i:]:
                        if t == "sky":
                            is_sky = True
                        elif "=" in t:
                            k, v = t.split("=", 1)
                            kv[k] = v
                    floor.append(_num(kv["floor"], "sector: floor"))
                    ceil.append(_num(kv["ceil"], "sector: ceil"))
                    open_h.append(_num(kv["door"], "sector: door") if "door" in kv else ceil[-1])
                    sky.append(is_sky)
                elif tok[0] == "wall":
                    a = [_num(t, "wall") for t in tok[1:5]]
                    if a[0] == a[2] and a[1] == a[3]:
                        raise ValueError("wall: zero length")
                    f = sector_ref(tok[5], lineno)
                    b = NONE
                    if len(tok) > 6 and "=" not in tok[6]:
                        b = sector_ref(tok[6], lineno)
                    x1.append(a[0]); y1.append(a[1]); x2.append(a[2]); y2.append(a[3])
                    front.append(f); back.append(b)
                elif tok[0] == "player":
                    player = (_num(tok[1], "player"), _num(tok[2], "player"),
                              _num(tok[3], "player") % 360.0)
                else:
                    raise ValueError(f"unknown statement '{tok[0]}'")
            except (KeyError, IndexError) as e:
                raise ValueError(f"{path}:{lineno}: malformed {tok[0]} ({e})") from None
            except ValueError as e:
                msg = str(e)
                raise ValueError(msg if msg.startswith(path) else f"{path}:{lineno}: {msg}") from None
    if in_model is not None:
        raise ValueError(f"{path}: model {in_model.name} has no 'end'")
    if not front:
        raise ValueError(f"{path}: no walls")
    return Map(path, x1, y1, x2, y2, front, back, floor, ceil, sky, player, models, objects, open_h)


# ---- WAD maps -----------------------------------------------------------------------------

MAP_LUMPS = {"THINGS", "LINEDEFS", "SIDEDEFS", "VERTEXES", "SEGS", "SSECTORS", "NODES", "SECTORS",
             "REJECT", "BLOCKMAP", "BEHAVIOR", "SCRIPTS"}


def find_wad(name):
    if os.path.exists(name) or "/" in name:
        return name if os.path.exists(name) else None
    for d in (os.environ.get("DOOMWADDIR"), "/usr/share/games/doom"):
        if d and os.path.exists(os.path.join(d, name)):
            return os.path.join(d, name)
    return None


def _name8(b):
    return b.split(b"\0", 1)[0].decode("latin-1").upper()


THINGS_TXT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "bspc", "things.txt")
DOOR_SPECIALS = {1, 26, 27, 28, 31, 32, 33, 34, 63, 90, 117, 118}
NOT_OBJECTS = {1, 2, 3, 4, 11, 14}     # player and deathmatch starts, teleport destinations
RAMPS = ["grey", "red", "orange", "yellow", "lime", "green", "teal", "cyan", "blue", "violet",
         "magenta", "brown", "sand", "moss", "slate", "plum"]


def colour_index(text):
    """A colour as docs/scene-format.md writes it (0..255, 0x.., RAMP or RAMP:SHADE) -> index,
    so that two spellings of one colour make one model."""
    t = text.strip().lower()
    if t[:1].isdigit():
        return int(t, 16) if t.startswith("0x") else int(t)
    ramp, _, shade = t.partition(":")
    return RAMPS.index(ramp) * 16 + (int(shade) if shade else 10)


FRAMES = "ABCDEFGHIJKLMNOPQRSTUVWXYZ[\\]"   # Doom's frame letters (frame 0 = 'A')


def _read_things(path=THINGS_TXT):
    """tools/bspc/things.txt, one type a line, `type radius height colour sprite frame name`
    (`#` starts a comment; frame a letter, `*` after it: full-bright): {type: (radius, height,
    colour index, sprite, frame letter, bright)}."""
    table = {}
    with open(path, "r", encoding="utf-8") as fh:
        for lineno, line in enumerate(fh, 1):
            tok = line.split("#", 1)[0].split()
            if not tok:
                continue
            try:
                fr = tok[5] if len(tok) == 7 else ""
                if len(tok) != 7 or len(tok[4]) != 4 or fr[:1] not in FRAMES or \
                        fr[1:] not in ("", "*") or not fr:
                    raise ValueError
                table[int(tok[0])] = (float(tok[1]), float(tok[2]), colour_index(tok[3]),
                                      tok[4].upper(), fr[0], fr[1:] == "*")
            except (IndexError, ValueError):
                raise ValueError(f"{path}:{lineno}: expected 'type radius height colour sprite "
                                 "frame name' (frame a letter, '*' after it: full-bright)") from None
    return table


def read_things_table(path=THINGS_TXT):
    """tools/bspc/things.txt: {type: (radius, height, colour index)}, each type's box (a thing
    drawn as a sprite has a box of its images instead: wad_objects)."""
    return {t: v[:3] for t, v in _read_things(path).items()}


def read_things_sprites(path=THINGS_TXT):
    """tools/bspc/things.txt: {type: (sprite, frame letter, full-bright)}."""
    return {t: v[3:] for t, v in _read_things(path).items()}


# ---- sprites (docs/objects.md "Sprites") --------------------------------------------------

SPRITE_MAX_SIZE, SPRITE_MAX_OFFSET = 512, 1024   # the loader's limits (firmware/scene_format.h)


class SpriteImage:
    """A sprite lump decoded: width x height texels (column-major, texels[u, v]), opaque[u, v]
    where a post covers the texel, and Doom's offsets: left (the origin's column counted from
    the image's left edge) and top (the image's top above the origin)."""

    def __init__(self, name, width, height, left, top, texels, opaque):
        self.name, self.width, self.height, self.left, self.top = name, width, height, left, top
        self.texels, self.opaque = texels, opaque


def read_sprite_patch(data, name="?"):
    """A patch lump as a SpriteImage, every read bounds-checked. Posts (top delta, length, a pad
    byte, the texels, a pad byte; 0xFF ends a column) are Doom's: the top delta counts from the
    image's top; texels past the image's height are not part of it. ValueError when the lump
    is not a patch or its size or offsets are outside the loader's limits."""
    if len(data) < 8:
        raise ValueError(f"sprite {name}: shorter than a patch header")
    w, h, left, top = struct.unpack_from("<hhhh", data, 0)
    if not (1 <= w <= SPRITE_MAX_SIZE and 1 <= h <= SPRITE_MAX_SIZE):
        raise ValueError(f"sprite {name}: size {w} x {h} outside 1..{SPRITE_MAX_SIZE}")
    if abs(left) > SPRITE_MAX_OFFSET or abs(top) > SPRITE_MAX_OFFSET:
        raise ValueError(f"sprite {name}: offsets {left}, {top} beyond {SPRITE_MAX_OFFSET}")
    if len(data) < 8 + 4 * w:
        raise ValueError(f"sprite {name}: column table cut short")
    texels = np.zeros((w, h), np.uint8)
    opaque = np.zeros((w, h), bool)
    for c in range(w):
        (pos,) = struct.unpack_from("<I", data, 8 + 4 * c)
        while True:
            if pos >= len(data):
                raise ValueError(f"sprite {name}: column {c} runs past the lump")
            row = data[pos]
            if row == 0xFF:
                break
            if pos + 3 > len(data) or pos + 3 + data[pos + 1] > len(data):
                raise ValueError(f"sprite {name}: column {c}: a post runs past the lump")
            n = data[pos + 1]
            a, b = row, min(h, row + n)
            if a < b:
                texels[c, a:b] = np.frombuffer(data, np.uint8, b - a, pos + 3)
                opaque[c, a:b] = True
            pos += n + 4
    return SpriteImage(name, w, h, left, top, texels, opaque)


class SpriteSet:
    """The images a thing type shows: images[r] = (SpriteImage, mirrored) for rotation r = 0..7
    (docs/objects.md: r = 0 seen from the front; Doom's rotation r + 1), full-bright or not, and
    the box around them: radius the largest of left and width - left, height the largest top
    (whole units, at least 1)."""

    def __init__(self, sprite, frame, bright, images):
        self.sprite, self.frame, self.bright, self.images = sprite, frame, bright, images
        self.radius = max(1, max(max(im.left, im.width - im.left) for im, _ in images))
        self.height = max(1, max(im.top for im, _ in images))

    def rotation(self, ex, ey, ox, oy, yaw):
        """r for the eye at (ex, ey) and the thing at (ox, oy) with yaw degrees:
        floor(((theta - yaw + 202.5) mod 360) / 45), theta = atan2(O - E) in degrees; 0 when O = E."""
        if ox == ex and oy == ey:
            return 0
        theta = math.degrees(math.atan2(oy - ey, ox - ex))
        return min(7, int(math.floor(((theta - float(yaw) + 202.5) % 360.0) / 45.0)))


def sprite_lumps(lumps):
    """{name: lump number}: the lumps between S_START and S_END (or SS_START and SS_END), the
    last lump of a name winning; in the order of those last lumps."""
    out, inside = {}, False
    for i, (_, _, name) in enumerate(lumps):
        if name in ("S_START", "SS_START"):
            inside = True
        elif name in ("S_END", "SS_END"):
            inside = False
        elif inside:
            out.pop(name, None)
            out[name] = i
    return out


def sprite_set(data, lumps, named, sprite, frame, bright):
    """The SpriteSet of sprite SSSS, frame F, from the sprite lumps named SSSSFR or SSSSFRFR
    (the second pair: that rotation shows the image mirrored); a later lump taking a rotation
    from an earlier one. Rotation 0 when the frame has one (every rotation that image), else the
    eight rotations 1..8; None when it has neither or an image is not a readable patch."""
    rot = {}
    for name, i in named.items():
        if name[:4] != sprite or len(name) not in (6, 8):
            continue
        pairs = [(name[4], name[5], False)] + ([(name[6], name[7], True)] if len(name) == 8 else [])
        for f, r, mirrored in pairs:
            if f == frame and r in "012345678":
                rot[int(r)] = (name, mirrored)
    if 0 in rot:
        chosen = [rot[0]] * 8
    elif all(k in rot for k in range(1, 9)):
        chosen = [rot[k] for k in range(1, 9)]
    else:
        return None
    images = {}
    try:
        for name, _ in chosen:
            if name not in images:
                pos, size, _ = lumps[named[name]]
                images[name] = read_sprite_patch(data[pos:pos + size], name)
    except (ValueError, struct.error):
        return None
    return SpriteSet(sprite, frame, bright, [(images[n], mir) for n, mir in chosen])


def wad_objects(thing, table, inside, sets=None):
    """Things -> (models, objects, sprite sets) per docs/objects.md: the things of skill 3 that
    are not multiplayer-only, whose type the table lists, inside the coordinate range (x, y >
    -32768) and inside a sector (inside(x, y)), in THINGS order; one upright box model per
    distinct (radius, height, colour), numbered in order of first use; z None (the floor).
    sets: {type: SpriteSet} (a textured scene's sprites): such a thing is drawn as its sprite,
    its box the SpriteSet's radius and height; the third list gives each object's set or None."""
    sets = sets or {}
    models, by_key, objects, sprites = [], {}, [], []
    for t in thing:
        typ, flags, x, y = int(t["type"]), int(t["fl"]), int(t["x"]), int(t["y"])
        if typ in NOT_OBJECTS or typ not in table or not flags & 0x0002 or flags & 0x0010:
            continue
        if x == -32768 or y == -32768 or not inside(x, y):
            continue
        s = sets.get(typ)
        key = table[typ] if s is None else (float(s.radius), float(s.height), table[typ][2])
        if key not in by_key:
            r, h, _ = key
            by_key[key] = len(models)
            models.append(Model(f"thing{typ}", [box_part(2 * r, 2 * r, h)]))
        objects.append(SceneObject(by_key[key], float(x), float(y), None, float(int(t["a"]) % 360)))
        sprites.append(s)
    return models, objects, sprites


def wad_door_heights(sec_ceil, sec_tag, lin_special, lin_tag, front, back):
    """Open ceilings: a door opens to the lowest ceiling among its neighbours (the sectors across
    its two-sided linedefs, zero-length ones included) minus 4, never below its closed ceiling;
    other sectors keep their ceiling. Doors: the back sector of a linedef with a door special,
    or for the remote specials 63 and 90 the sectors tagged with the line's non-zero tag."""
    open_h = sec_ceil.astype(float).copy()
    two = back >= 0
    doors = set()
    for i in np.nonzero(np.isin(lin_special, list(DOOR_SPECIALS)))[0]:
        if lin_special[i] in (63, 90):
            if lin_tag[i]:
                doors.update(int(d) for d in np.nonzero(sec_tag == lin_tag[i])[0])
        elif back[i] >= 0:
            doors.add(int(back[i]))
    for d in doors:
        nb = np.concatenate((back[two & (front == d)], front[two & (back == d)]))
        nb = nb[nb != d]
        if len(nb):
            open_h[d] = max(float(sec_ceil[d]), float(sec_ceil[nb].min()) - 4)
    return open_h


def read_wad(spec, flat=False):
    """A WAD map (see the header); flat: as bspc --flat compiles it (no look: things are boxes)."""
    wadname, mapname = spec.rsplit(":", 1)
    path = find_wad(wadname)
    if path is None:
        raise ValueError(f"{spec}: cannot find {wadname} (looked in the current folder, "
                         "$DOOMWADDIR and /usr/share/games/doom)")
    data = open(path, "rb").read()
    if data[:4] not in (b"IWAD", b"PWAD"):
        raise ValueError(f"{spec}: {path} is not a WAD file")
    nlumps, dirofs = struct.unpack_from("<II", data, 4)
    lumps = [(*struct.unpack_from("<II", data, dirofs + 16 * i),
              _name8(data[dirofs + 16 * i + 8:dirofs + 16 * i + 16])) for i in range(nlumps)]
    want = mapname.upper()
    marker = max((i for i, l in enumerate(lumps) if l[2] == want), default=None)
    if marker is None:
        raise ValueError(f"{spec}: no map {want} in {path}")
    got = {}
    for pos, size, name in lumps[marker + 1:]:
        if name not in MAP_LUMPS:
            break
        if name == "BEHAVIOR":
            raise ValueError(f"{spec}: Hexen-format map")
        got.setdefault(name, data[pos:pos + size])
    for need in ("THINGS", "LINEDEFS", "SIDEDEFS", "VERTEXES", "SECTORS"):
        if need not in got:
            raise ValueError(f"{spec}: map has no {need} lump")
    sec = np.frombuffer(got["SECTORS"], np.dtype([("f", "<i2"), ("c", "<i2"), ("ff", "S8"),
                                                  ("cf", "S8"), ("light", "<i2"), ("sp", "<i2"),
                                                  ("tag", "<i2")]))
    vert = np.frombuffer(got["VERTEXES"], np.dtype([("x", "<i2"), ("y", "<i2")]))
    lin = np.frombuffer(got["LINEDEFS"], np.dtype([("v1", "<u2"), ("v2", "<u2"), ("fl", "<u2"),
                                                   ("sp", "<u2"), ("tag", "<u2"), ("s0", "<u2"),
                                                   ("s1", "<u2")]))
    side_sec = np.frombuffer(got["SIDEDEFS"], np.dtype([("pad", "V28"), ("sec", "<u2")]))["sec"]
    thing = np.frombuffer(got["THINGS"], np.dtype([("x", "<i2"), ("y", "<i2"), ("a", "<i2"),
                                                   ("type", "<u2"), ("fl", "<u2")]))
    if (lin["v1"] >= len(vert)).any() or (lin["v2"] >= len(vert)).any():
        raise ValueError(f"{spec}: a linedef's vertex is out of range")
    if (lin["s0"] == 0xFFFF).any():
        raise ValueError(f"{spec}: linedef {int(np.argmax(lin['s0'] == 0xFFFF))}: no front sidedef")
    vx, vy = vert["x"].astype(float), vert["y"].astype(float)
    x1, y1, x2, y2 = vx[lin["v1"]], vy[lin["v1"]], vx[lin["v2"]], vy[lin["v2"]]
    keep = (x1 != x2) | (y1 != y2)            # zero-length linedefs are skipped, as in wad.c
    s0, s1 = lin["s0"].astype(np.int64), lin["s1"].astype(np.int64)
    if (s0 >= len(side_sec)).any() or ((s1 != 0xFFFF) & (s1 >= len(side_sec))).any():
        raise ValueError(f"{spec}: a linedef's sidedef is out of range")
    front = side_sec[s0].astype(np.int64)
    back = np.where(s1 == 0xFFFF, NONE, side_sec[np.where(s1 == 0xFFFF, 0, s1)].astype(np.int64))
    if (front >= len(sec)).any() or (back >= len(sec)).any():
        raise ValueError(f"{spec}: a sidedef's sector is out of range")
    sky = np.array([_name8(c).startswith("F_SKY") for c in sec["cf"]], bool)
    player = None
    starts = np.nonzero(thing["type"] == 1)[0]
    if len(starts):
        t = thing[starts[-1]]
        player = (float(t["x"]), float(t["y"]), float(int(t["a"]) % 360))
    open_h = wad_door_heights(sec["c"], sec["tag"], lin["sp"].astype(np.int64),
                              lin["tag"].astype(np.int64), front, back)
    m = Map(spec, x1[keep], y1[keep], x2[keep], y2[keep], front[keep], back[keep],
            sec["f"].astype(float), sec["c"].astype(float), sky, player, open_h=open_h)
    # for the map's look (tools/reflook.py): the file, the map's lumps, and each kept line's
    # linedef number
    m.wad_file, m.wad_lumps, m.wad_lines = path, got, np.nonzero(keep)[0]
    m.textured = not flat and _wad_textured(m)
    if os.path.exists(THINGS_TXT):
        things = _read_things()
        table = {t: v[:3] for t, v in things.items()}
        sets = {}
        if m.textured:
            named = sprite_lumps(lumps)
            for typ in sorted(set(int(t) for t in thing["type"]) & set(things)):
                spr, frame, bright = things[typ][3:]
                sets[typ] = sprite_set(data, lumps, named, spr, frame, bright)
        m.models, m.objects, m.sprites = wad_objects(thing, table,
                                                     lambda x, y: sector_at(m, x, y) is not None,
                                                     sets)
    m.nthings = len(m.objects)
    m.mids = [None] * len(m.objects)
    if m.textured:
        import reflook
        for mid in wad_mids(m, reflook.look_of(m)):
            mid.obj, mid.model = len(m.objects), len(m.models)
            m.models.append(Model(f"mid{mid.line}.{mid.side}", [(mid.verts, [[0, 1, 2, 3]])]))
            m.objects.append(SceneObject(mid.model, mid.x, mid.y, mid.top, 0.0))
            m.sprites.append(None)
            m.mids.append(mid)
    return m


MID_REACH = 1024.0    # a model's coordinate limit (SCN_MODEL_MAX): a mid quad's reach from its origin


class MidSide:
    """A see-through middle texture drawn as an object (docs/textures.md "See-through middle
    textures"): line (refrender's line number) and side (0 front, 1 back), the sidedef's texture
    name, tex and cover (reflook.Texture of its texels and of its coverage: 1 covered, 0 a
    hole), xoff and yoff (the sidedef's offsets), top (the height of the texture's row 0 less
    yoff: the object's z), zb and zt (the quad's heights), sector (the side's) and adj (the fake
    contrast), the object's origin (x, y: the line's middle) and its model's four vertices
    verts (4, 3) relative to (x, y, top): the side's left end (its origin O) and right end as
    its viewer sees them at zb, then the same at zt. obj and model: its numbers in the scene."""


def wad_mids(m, lk):
    """The MidSides of a textured WAD map, in bspc's order (tools/bspc/mids.c): two-sided lines
    in line order, side 0 before side 1; each side whose middle texture has holes
    (lk.mid_texture), pegged as Doom pegs it with the compiled heights (a door closed): row0 =
    (lower-unpegged ? max floor + H : min ceiling) + yoff, the quad [max(max floor, row0 - H),
    min(min ceiling, row0)] along the whole line, none when that is empty; a line whose
    half-length along x or y, or a strip whose distance from row0 - yoff, exceeds 1024 units
    is left out (a model's coordinate limit). lk: the map's reflook.Look."""
    import reflook
    out = []
    for i in np.nonzero(m.back >= 0)[0]:
        a, b = int(m.front[i]), int(m.back[i])
        lo, hi = max(m.floor[a], m.floor[b]), min(m.ceil[a], m.ceil[b])
        for k in (0, 1):
            sd = int(lk.side_def[i, k])
            if sd < 0:
                continue
            got = lk.mid_texture(lk.mid_name[sd])
            if got is None:
                continue
            tex, cover = got
            top = lo + tex.height if lk.flags[i] & reflook.UNPEG_BOTTOM else hi
            row0 = top + lk.yoff[sd]
            zt, zb = min(row0, hi), max(row0 - tex.height, lo)
            if zb >= zt:
                continue
            # the side as its viewer sees it, left end first: v1 -> v2 for the front side
            ax, ay, bx, by = m.x1[i], m.y1[i], m.x2[i], m.y2[i]
            if k:
                ax, ay, bx, by = bx, by, ax, ay
            mx, my = (ax + bx) / 2, (ay + by) / 2
            if max(abs(ax - mx), abs(ay - my), zt - top, top - zb) > MID_REACH:
                continue
            d = MidSide()
            d.line, d.side, d.name, d.tex, d.cover = int(i), k, lk.mid_name[sd], tex, cover
            d.xoff, d.yoff, d.top, d.zb, d.zt = float(lk.xoff[sd]), float(lk.yoff[sd]), float(top), zb, zt
            d.sector = a if k == 0 else b
            d.adj = -1 if m.y1[i] == m.y2[i] else (1 if m.x1[i] == m.x2[i] else 0)
            d.x, d.y = float(mx), float(my)
            d.verts = np.array([(ax - mx, ay - my, zb - top), (bx - mx, by - my, zb - top),
                                (bx - mx, by - my, zt - top), (ax - mx, ay - my, zt - top)], float)
            out.append(d)
    return out


def _wad_textured(m):
    """Whether bspc compiles the map with its look (docs/textures.md): the WAD has PLAYPAL and
    COLORMAP and the map uses a wall texture or flat the WAD has (the sky counted when a ceiling
    is sky). A WAD whose texture lumps cannot be read is not."""
    try:
        import reflook
        lk = reflook.look_of(m)
    except (ValueError, TypeError, KeyError, IndexError, AttributeError, struct.error):
        return False
    return bool((lk.side_tex >= 0).any() or (lk.floor_tex >= 0).any() or (lk.ceil_tex >= 0).any()
                or (m.sky.any() and lk.sky_tex >= 0))


_cache = {}


def load(spec, flat=False):
    """A Map from a scene spec (text scene path or file.wad:MAP), cached by spec. flat: a WAD map
    as bspc --flat compiles it (its things all boxes; text scenes are always so)."""
    if isinstance(spec, Map):
        return spec
    head, _, tail = spec.rpartition(":")
    wad = head.lower().endswith(".wad") and tail
    key = (spec, True) if flat and wad else spec
    if key not in _cache:
        _cache[key] = read_wad(spec, bool(flat)) if wad else read_text(spec)
    return _cache[key]


# ---- eye sector ---------------------------------------------------------------------------

def sector_at(scene, x, y):
    """The sector containing (x, y) by even-odd ray crossing (see the header), or None."""
    m = load(scene)
    ay, by = m.y1, m.y2
    crosses = (ay > y) != (by > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        xi = m.x1 + (y - ay) * (m.x2 - m.x1) / (by - ay)
    crosses &= xi > x
    cnt = np.bincount(m.front[crosses], minlength=m.nsectors)
    bk = m.back[crosses]
    cnt += np.bincount(bk[bk >= 0], minlength=m.nsectors)
    inside = np.nonzero(cnt % 2 == 1)[0]
    if len(inside) == 0:
        return None
    if len(inside) == 1:
        return int(inside[0])
    # overlapping sectors: the one facing the point across the nearest crossing line
    idx = np.nonzero(crosses)[0]
    for i in idx[np.argsort(xi[idx], kind="stable")]:
        # the point is on the right (front) of v1 -> v2 when the cross product is negative
        c = (m.x2[i] - m.x1[i]) * (y - m.y1[i]) - (m.y2[i] - m.y1[i]) * (x - m.x1[i])
        s = m.front[i] if c < 0 else m.back[i]
        if s in inside:
            return int(s)
    return int(inside[0])


eye_sector = sector_at


def eye_height(scene, x, y):
    """The default eye height at (x, y): the floor of its sector + 41, or 41 in none."""
    s = sector_at(scene, x, y)
    return EYE_HEIGHT if s is None else float(load(scene).floor[s]) + EYE_HEIGHT


# ---- objects at a time, in world space ----------------------------------------------------

def object_states(scene, t_ms=0):
    """The scene's objects at time t_ms as docs/objects.md defines them, in exact arithmetic:
    [(model, x, y, z, yaw)]; z None in the scene is the floor of the sector under (x, y) (0 in
    none). circle: centre (x, y), angle th = 360 t / period, origin at centre + R (cos th,
    sin th), facing along the motion (yaw + th + 90). line: (x, y) + s (dx, dy) with s going
    0 -> 1 -> 0 linearly over a period. spin adds spin * t / 1000 degrees."""
    m = load(scene)
    out = []
    for o in m.objects:
        z = o.z
        if z is None:
            sec = sector_at(m, o.x, o.y)
            z = 0.0 if sec is None else float(m.floor[sec])
        x, y, yaw = o.x, o.y, o.yaw + o.spin * t_ms / 1000.0
        if o.path == "circle":
            th = 360.0 * (t_ms % o.period_ms) / o.period_ms
            x += o.pa * math.cos(math.radians(th))
            y += o.pa * math.sin(math.radians(th))
            yaw += th + 90.0
        elif o.path == "line":
            ph = (t_ms % o.period_ms) / o.period_ms
            f = 2 * ph if ph < 0.5 else 2 - 2 * ph
            x += f * o.pa
            y += f * o.pb
        out.append((o.model, x, y, z, yaw))
    return out


def world_parts(m, states, skip=()):
    """Every convex part of every object in world space: [(object index, verts (n, 3), normals
    (f, 3), offsets (f,))], where the part is {p : normals @ p <= offsets}. The normals come
    from the faces' vertices (Newell's sum) and point away from the part's centroid. Objects in
    skip (those drawn as sprites) have no parts; their model must exist all the same."""
    parts = []
    for i, (model, x, y, z, yaw) in enumerate(states):
        model = int(model)
        if not 0 <= model < len(m.models):
            raise ValueError(f"object {i}: model {model} does not exist (the scene has "
                             f"{len(m.models)})")
        if i in skip:
            continue
        c, s_ = math.cos(math.radians(float(yaw))), math.sin(math.radians(float(yaw)))
        for verts, faces in m.models[model].parts:
            w = np.empty_like(verts)
            w[:, 0] = float(x) + c * verts[:, 0] - s_ * verts[:, 1]
            w[:, 1] = float(y) + s_ * verts[:, 0] + c * verts[:, 1]
            w[:, 2] = float(z) + verts[:, 2]
            centre = w.mean(axis=0)
            normals, offsets = [], []
            for f in faces:
                p = w[f]
                q = np.roll(p, -1, axis=0)
                n = np.array([np.sum((p[:, 1] - q[:, 1]) * (p[:, 2] + q[:, 2])),
                              np.sum((p[:, 2] - q[:, 2]) * (p[:, 0] + q[:, 0])),
                              np.sum((p[:, 0] - q[:, 0]) * (p[:, 1] + q[:, 1]))])
                n /= np.linalg.norm(n)
                d = float(n @ p.mean(axis=0))
                if n @ centre > d:
                    n, d = -n, -d
                normals.append(n)
                offsets.append(d)
            parts.append((i, w, np.array(normals), np.array(offsets)))
    return parts


def _object_hits(parts, ex, ey, ez, fxd, fyd, rx, ry, look, dx, dy, yv):
    """Nearest object hit per pixel: (depth (H, W), object index (H, W), -1 for none)."""
    best = np.full((H, W), np.inf)
    who = np.full((H, W), -1, np.int64)
    for obj, verts, normals, offsets in parts:
        rel = verts - (ex, ey, ez)
        depth = rel[:, 0] * fxd + rel[:, 1] * fyd
        if depth.max() < ZNEAR:
            continue                                      # wholly behind the near plane
        c0, c1, r0, r1 = 0, W, 0, H
        if depth.min() >= ZNEAR:                          # in front: its screen bounding box
            sx = W / 2 + FOCAL * (rel[:, 0] * rx + rel[:, 1] * ry) / depth
            sy = H / 2 + look - FOCAL * rel[:, 2] / depth
            c0, c1 = max(0, int(math.floor(sx.min())) - 1), min(W, int(math.ceil(sx.max())) + 1)
            r0, r1 = max(0, int(math.floor(sy.min())) - 1), min(H, int(math.ceil(sy.max())) + 1)
            if c0 >= c1 or r0 >= r1:
                continue
        sub_dx, sub_dy, sub_yv = dx[c0:c1], dy[c0:c1], yv[r0:r1]
        t_in = np.full((r1 - r0, c1 - c0), -np.inf)
        t_out = np.full((r1 - r0, c1 - c0), np.inf)
        for n, off in zip(normals, offsets):
            # the ray E + t (dx, dy, yv) is inside the face's half-space where t * nd <= num
            num = off - (n[0] * ex + n[1] * ey + n[2] * ez)
            nd = (n[0] * sub_dx + n[1] * sub_dy)[None, :] + n[2] * sub_yv[:, None]
            with np.errstate(divide="ignore", invalid="ignore"):
                t = num / nd
            t_in = np.where(nd < 0, np.maximum(t_in, t), t_in)
            t_out = np.where(nd > 0, np.minimum(t_out, t), t_out)
            if num < 0:                                   # parallel and outside: missed
                t_out = np.where(nd == 0, -np.inf, t_out)
        # an eye inside the part, or a part cut by the near plane, shows nothing of it there:
        # its front faces are behind the eye or clipped away, its back faces culled
        seen = (t_in < t_out) & (t_in >= ZNEAR)
        sub = best[r0:r1, c0:c1]
        nearer = seen & (t_in < sub)
        sub[nearer] = t_in[nearer]
        who[r0:r1, c0:c1][nearer] = obj
    return best, who


SPRITE_ZMIN = 4.0    # a sprite nearer than this (forward depth) is not drawn (Doom's MINZ)


class SpriteDraw:
    """One object drawn as a sprite in a view: its object index, origin (x, y, z), the rotation
    r seen and its image (SpriteImage, mirrored), the view depth zc and lateral position xc of
    the origin, full-bright or not, and the sector under the origin (None: none)."""


def sprite_draws(m, states, ex, ey, fxd, fyd, rx, ry):
    """[SpriteDraw or None] per object of states: those whose scene object has a SpriteSet and
    whose origin is at least SPRITE_ZMIN ahead of the eye."""
    out = []
    for i, (_, ox, oy, oz, yaw) in enumerate(states):
        sset = m.sprites[i] if i < len(m.sprites) else None
        if sset is None:
            out.append(None)
            continue
        relx, rely = float(ox) - ex, float(oy) - ey
        zc = relx * fxd + rely * fyd
        if not zc >= SPRITE_ZMIN:
            out.append(None)
            continue
        d = SpriteDraw()
        d.obj, d.x, d.y, d.z, d.zc, d.xc = i, float(ox), float(oy), float(oz), zc, relx * rx + rely * ry
        d.rotation = sset.rotation(ex, ey, float(ox), float(oy), yaw)
        d.image, d.mirrored = sset.images[d.rotation]
        d.bright = sset.bright
        d.sector = sector_at(m, d.x, d.y)
        out.append(d)
    return out


def _sprite_hits(draws, best, who, ez, xv, yv):
    """Draw the sprites into (best, who) (depth and object per pixel, as _object_hits leaves
    them): a sprite takes a pixel where the pixel's centre ray meets an opaque texel of its
    rectangle and zc is nearer than what the pixel has (an exact tie: the lower object number).
    Returns per pixel the image column and row (-1: no sprite) and the exact image coordinates
    (u, v; nan), valid where who is a sprite's object."""
    col = np.full((H, W), -1, np.int64)
    row = np.full((H, W), -1, np.int64)
    su, sv = np.full((H, W), np.nan), np.full((H, W), np.nan)
    for d in draws:
        if d is None:
            continue
        im, zc = d.image, d.zc
        a = xv * zc - (d.xc - im.left)                 # from the image's left edge, per column
        hh = ez + yv * zc                              # height met, per row
        b = d.z + im.top - hh                          # from the image's top, per row
        cs = np.nonzero((a >= 0) & (a < im.width))[0]
        rs = np.nonzero((b >= 0) & (b < im.height) & (hh >= d.z))[0]   # cut at the floor
        if not len(cs) or not len(rs):
            continue
        ai = np.floor(a[cs]).astype(np.int64)
        ci = im.width - 1 - ai if d.mirrored else ai
        ri = np.floor(b[rs]).astype(np.int64)
        ix = np.ix_(rs, cs)
        sub_best, sub_who = best[ix], who[ix]
        nearer = im.opaque[ci[None, :], ri[:, None]] & \
            ((zc < sub_best) | ((zc == sub_best) & (d.obj < sub_who)))
        if not nearer.any():
            continue
        best[ix] = np.where(nearer, zc, sub_best)
        who[ix] = np.where(nearer, d.obj, sub_who)
        col[ix] = np.where(nearer, ci[None, :], col[ix])
        row[ix] = np.where(nearer, ri[:, None], row[ix])
        uu = (im.width - a[cs]) if d.mirrored else a[cs]
        su[ix] = np.where(nearer, uu[None, :], su[ix])
        sv[ix] = np.where(nearer, b[rs][:, None], sv[ix])
    return col, row, su, sv


def mid_draws(m, states):
    """[MidDraw or None] per object of states: object i of the list is drawn as the scene's
    object i's see-through middle texture when that object is one (m.mids), its quad (the
    model's four vertices) placed at the position and yaw given; None else."""
    out = []
    for i, (_, ox, oy, oz, yaw) in enumerate(states):
        mid = m.mids[i] if i < len(m.mids) else None
        if mid is None:
            out.append(None)
            continue
        c, s_ = math.cos(math.radians(float(yaw))), math.sin(math.radians(float(yaw)))
        w = np.empty_like(mid.verts)
        w[:, 0] = float(ox) + c * mid.verts[:, 0] - s_ * mid.verts[:, 1]
        w[:, 1] = float(oy) + s_ * mid.verts[:, 0] + c * mid.verts[:, 1]
        w[:, 2] = float(oz) + mid.verts[:, 2]
        d = MidDraw()
        d.obj, d.mid, d.z, d.quad = i, mid, float(oz), w
        out.append(d)
    return out


class MidDraw:
    """One see-through middle texture drawn in a view: its object index, its MidSide (mid), the
    object's z as drawn (row 0 of the texture is at z + mid.yoff) and its quad in world space
    (4, 3): left end, right end at the bottom, then the right and left ends at the top."""


def _mid_hits(draws, best, who, ex, ey, ez, dx, dy, yv):
    """Draw the see-through middle textures into (best, who) (depth and object per pixel, as
    _object_hits and _sprite_hits leave them): the pixel's centre ray meets the quad (seen only
    from its front, the right of its bottom edge left to right; the ends and heights inclusive)
    at depth t >= the near plane, point P and height h; the texel column is the side's u(P) =
    U . (P - O) + xoff (O the quad's left end, U the unit vector to its right end), the row
    z + yoff - h; the object has the pixel where that texel is covered and t is nearer than
    what the pixel has (an exact tie: the lower object number), else the ray goes on.
    Returns per pixel the exact (u, v) (nan where no middle texture won)."""
    su, sv = np.full((H, W), np.nan), np.full((H, W), np.nan)
    for d in draws:
        if d is None:
            continue
        (axx, ayy, z0), (bxx, byy, _), (_, _, z1), _ = d.quad
        wx, wy = bxx - axx, byy - ayy
        ax, ay = axx - ex, ayy - ey                             # A - E
        if not wx * (-ay) - wy * (-ax) < 0:                     # the eye is not on its front
            continue
        denom = dx * wy - dy * wx
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (ax * wy - ay * wx) / denom
            s = (ax * dy - ay * dx) / denom
        cs = np.nonzero((denom != 0) & (s >= 0) & (s <= 1) & (t >= ZNEAR))[0]
        if not len(cs):
            continue
        tc = t[cs]
        h = ez + yv[:, None] * tc[None, :]                      # (200, n)
        inside = (h >= z0) & (h <= z1)
        ln = math.hypot(wx, wy)
        ux, uy = wx / ln, wy / ln
        u = (-ax) * ux + (-ay) * uy + tc * (dx[cs] * ux + dy[cs] * uy) + d.mid.xoff
        v = d.z + d.mid.yoff - h
        ui = np.floor(u).astype(np.int64)
        vi = np.floor(np.where(inside, v, 0)).astype(np.int64)
        covered = d.mid.cover.texel(ui[None, :], vi) != 0
        sub_best, sub_who = best[:, cs], who[:, cs]
        nearer = inside & covered & ((tc[None, :] < sub_best) |
                                     ((tc[None, :] == sub_best) & (d.obj < sub_who)))
        if not nearer.any():
            continue
        best[:, cs] = np.where(nearer, tc[None, :], sub_best)
        who[:, cs] = np.where(nearer, d.obj, sub_who)
        su[:, cs] = np.where(nearer, u[None, :], su[:, cs])
        sv[:, cs] = np.where(nearer, v, sv[:, cs])
    return su, sv


# ---- rendering ----------------------------------------------------------------------------

class View:
    """What each pixel's centre ray meets (cast_view): the camera as rendered (x, y, z, angle,
    look, after rounding), the ray directions per column (dx, dy) and per row (yv), and per
    pixel (200, 320): ids (uint32 surface ids), t (the world surface's forward depth, inf for
    none; objects are not in it), line (the linedef of a wall pixel, else -1), part (0 upper,
    1 middle, 2 lower for a wall pixel; 3 where the ray went over the missing upper wall between
    two sky ceilings and met sky; -1 else). ceil: the ceiling heights used (doors applied).
    Objects: obj (the object a pixel shows, -1 none) and obj_t (its forward depth, inf);
    sprites[i] the SpriteDraw of object i (None: not drawn as a sprite), and per pixel of a
    sprite spr_col, spr_row (the texel of its image; -1 elsewhere) and spr_u, spr_v (the exact
    image coordinates, u from the right edge for a mirrored image; nan elsewhere); mids[i] the
    MidDraw of object i (None: not a see-through middle texture) and per pixel of one mid_u,
    mid_v (its texture's exact column and row; nan elsewhere)."""


def render_ids(scene_spec, x, y, z=None, angle=0.0, look=0, fx=True, sky_owner="near",
               objects=None, ceilings=None, flat=False):
    """Surface ids of the view from (x, y, z) at angle degrees: numpy uint32 (200, 320).
    (cast_view(...).ids; the arguments are cast_view's.)"""
    return cast_view(scene_spec, x, y, z, angle, look, fx, sky_owner, objects, ceilings, flat).ids


def cast_view(scene_spec, x, y, z=None, angle=0.0, look=0, fx=True, sky_owner="near",
              objects=None, ceilings=None, flat=False):
    """The View from (x, y, z) at angle degrees (see View).

    z None: the floor of the eye's sector + 41. fx: round the camera to 16.16 first, as
    build/render does (pass False for the exact values). sky_owner: whose ceiling the sky seen
    over the missing upper wall between two sky sectors is: "near" (the sector on the eye's
    side, as Doom's visplanes have it, the default) or "far" (the sector beyond).
    objects: [(model, x, y, z, yaw)] in map units and degrees (build/render's JSON "objects",
    as dicts with those keys or as tuples), drawn with ids 4 << 24 | their position in the
    list; None: the scene's own objects at time 0 (object_states). Object i of the list is drawn
    as the sprite of the scene's object i (its thing type, in THINGS order) when that one has
    sprites, as its see-through middle texture when it is one (m.mids: the objects after the
    things'), else as its model. ceilings: {sector: height} (keys may be strings, as in
    build/render's JSON "ceilings"), for doors. flat: a WAD map as bspc --flat compiles it
    (scene_spec a spec, not a Map): no sprites, every thing its box."""
    m = load(scene_spec, flat)
    rnd = fx_round if fx else float
    x, y, angle = rnd(x), rnd(y), rnd(angle)
    z = None if z is None else rnd(z)
    look = int(look)
    eye_sec = sector_at(m, x, y)
    if z is None:
        z = EYE_HEIGHT if eye_sec is None else float(m.floor[eye_sec]) + EYE_HEIGHT
    if objects is None:
        states = object_states(m, 0)
    else:
        states = [(o["model"], o["x"], o["y"], o["z"], o["yaw"]) if isinstance(o, dict) else tuple(o)
                  for o in objects]
        states = [(int(mo), rnd(ox), rnd(oy), rnd(oz), rnd(oyaw)) for mo, ox, oy, oz, oyaw in states]
    a = np.radians(float(angle) % 360.0)
    fxd, fyd = np.cos(a), np.sin(a)
    rx, ry = fyd, -fxd
    xv = (np.arange(W) + 0.5 + TIE_DX - W / 2) / FOCAL        # (320,)
    yv = (H / 2 + look - (np.arange(H) + 0.5 + TIE_DY)) / FOCAL  # (200,)
    dx, dy = fxd + xv * rx, fyd + xv * ry                      # ray directions per column

    # every column against every line: E + t d = A + u w
    wx, wy = m.x2 - m.x1, m.y2 - m.y1
    ax, ay = m.x1 - x, m.y1 - y                                # A - E
    denom = dx[:, None] * wy[None, :] - dy[:, None] * wx[None, :]
    tnum = ax * wy - ay * wx                                   # (A - E) x w, per line
    unum = ax[None, :] * dy[:, None] - ay[None, :] * dx[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = tnum[None, :] / denom
        u = unum / denom
    hit = (denom != 0) & (u >= 0) & (u <= 1) & (t >= ZNEAR)
    # walls nearer than the near plane are gone but the ray still passes them: it reaches the
    # near plane in the sector beyond the last of them (possibly none)
    pre = (denom != 0) & (u >= 0) & (u <= 1) & (t > 0) & (t < ZNEAR)
    # side of each line the eye is on: 0 front (right of v1 -> v2), 1 back
    side = ((wx * (-ay) - wy * (-ax)) >= 0).astype(np.int64)   # cross(w, E - A) >= 0
    near = np.where(side == 0, m.front, m.back)
    far = np.where(side == 0, m.back, m.front)
    wall_id = (KIND_WALL << 24) | (np.arange(m.nlines, dtype=np.int64) * 2 + side)

    fl = np.append(m.floor, np.nan)      # index NONE (-1) -> nan: no floor, no ceiling
    ce = m.ceil.copy()
    for sec, h in (ceilings or {}).items():
        ce[int(sec)] = rnd(h)
    ce = np.append(ce, np.nan)
    sk = np.append(m.sky, False)
    out = np.zeros((H, W), np.uint32)
    # the world's depth per pixel (where objects must be compared with it), and what was met
    world_t = np.full((H, W), np.inf)
    hit_line = np.full((H, W), -1, np.int64)
    hit_part = np.full((H, W), -1, np.int8)
    rows = np.arange(H)
    start = NONE if eye_sec is None else eye_sec
    # the eye exactly on a wall (or vertex): which sector a ray starts in depends on its direction;
    # take the near-side sector of the first wall it crosses
    cross = wx * (-ay) - wy * (-ax)
    along = -(ax * wx + ay * wy)
    wlen2 = wx * wx + wy * wy
    on_wall = bool(np.any((np.abs(cross) <= 1e-9 * wlen2) & (along >= 0) & (along <= wlen2)))
    for px in range(W):
        li = np.nonzero(hit[px])[0]
        tk = t[px, li]
        order = np.argsort(tk, kind="stable")
        li, tk = li[order], tk[order]
        k = len(li)
        nsec, bsec = near[li], far[li]
        # the walk: sector of interval j (before crossing j; interval k is past the last)
        cur = np.empty(k + 1, np.int64)
        pj = np.nonzero(pre[px])[0]
        if len(pj):   # the sector past the walls it crossed before the near plane
            cur[0] = far[pj[np.argmax(t[px, pj])]]
        elif on_wall:   # a ray that crosses nothing leaves the map at once: it sees nothing
            cur[0] = nsec[0] if k else NONE
        else:
            cur[0] = start
        cur[1:] = bsec        # after a crossing: the far side's sector (NONE past a one-sided
                              # wall the ray missed: only with the eye outside the map)
        t0 = np.concatenate(([ZNEAR], tk))                     # (k+1,)
        t1 = np.concatenate((tk, [np.inf]))
        z0 = z + yv[:, None] * t0[None, :]                     # (200, k+1)
        with np.errstate(invalid="ignore"):
            z1 = z + yv[:, None] * t1[None, :]
        z1 = np.where(np.isinf(t1)[None, :], np.sign(yv)[:, None] * np.inf, z1)
        # crossings
        zc = z0[:, 1:]                                         # height at each crossing
        nf, nc, ns = fl[nsec][None, :], ce[nsec][None, :], sk[nsec][None, :]
        bf, bc, bs = fl[bsec][None, :], ce[bsec][None, :], sk[bsec][None, :]
        one_sided = (bsec < 0)[None, :]
        # a wall part is hit where the ray is within its heights (always so for an eye inside
        # its sector: a ray that left a sector's height range met its floor or ceiling first)
        mid = one_sided & (zc >= nf) & (zc <= nc)
        upper = ~(ns & bs) & (bc < nc) & (zc > np.maximum(bc, nf)) & (zc <= nc)
        lower = (bf > nf) & (zc < np.minimum(bf, nc)) & (zc >= nf)
        wall_stop = mid | upper | lower                        # no near sector: nan, culled
        # Doom's sky rule: a ray that goes over the missing upper wall between two sky
        # ceilings meets sky at once
        over_sky = ns & bs & (zc > np.maximum(bc, nf)) & (zc <= nc) & ~wall_stop
        sky_id = (KIND_CEIL << 24) | (nsec if sky_owner == "near" else bsec)
        cf, cc = fl[cur][None, :], ce[cur][None, :]
        # a plane is seen from its own side only: the ray goes down through the floor or up
        # through the ceiling inside the interval (so only when the eye is on that side)
        floor_hit = (z0 >= cf) & (z1 < cf)
        ceil_hit = (z0 <= cc) & (z1 > cc)
        plane_stop = floor_hit | ceil_hit                      # nan compares false: none
        plane_id = np.where(ceil_hit, (KIND_CEIL << 24) | cur[None, :],
                            (KIND_FLOOR << 24) | cur[None, :])
        # events in depth order: interval 0, crossing 0, interval 1, ..., interval k
        ev = np.empty((H, 2 * k + 1), bool)
        ev[:, 0::2] = plane_stop
        ev[:, 1::2] = wall_stop | over_sky
        ids = np.empty((H, 2 * k + 1), np.int64)
        ids[:, 0::2] = plane_id
        ids[:, 1::2] = np.where(over_sky, sky_id[None, :], wall_id[li][None, :])
        first = np.argmax(ev, axis=1)
        col = ids[rows, first]
        got = ev[rows, first]
        col[~got] = 0
        out[:, px] = col.astype(np.uint32)
        with np.errstate(divide="ignore", invalid="ignore"):
            tp = np.where(ceil_hit, cc, cf) - z
            tp = tp / yv[:, None]
        tev = np.empty((H, 2 * k + 1))
        tev[:, 0::2] = tp
        tev[:, 1::2] = tk[None, :]
        world_t[:, px] = np.where(got, tev[rows, first], np.inf)
        if k:
            crossing = got & (first % 2 == 1)
            j = np.where(crossing, (first - 1) // 2, 0)
            part = np.where(upper, 0, np.where(mid, 1, np.where(lower, 2, 3)))[rows, j]
            hit_line[:, px] = np.where(crossing, li[j], -1)
            hit_part[:, px] = np.where(crossing, part, -1)
    draws = sprite_draws(m, states, x, y, fxd, fyd, rx, ry)
    mids = mid_draws(m, states)
    skip = {i for i in range(len(states)) if mids[i] is not None or
            (i < len(m.sprites) and m.sprites[i] is not None)}
    parts = world_parts(m, states, skip)
    obj_t, obj = np.full((H, W), np.inf), np.full((H, W), -1, np.int64)
    if parts:
        obj_t, obj = _object_hits(parts, x, y, z, fxd, fyd, rx, ry, look, dx, dy, yv)
    spr = _sprite_hits(draws, obj_t, obj, z, xv, yv)
    mid_u, mid_v = _mid_hits(mids, obj_t, obj, x, y, z, dx, dy, yv)
    front = obj_t < world_t
    out[front] = ((KIND_OBJECT << 24) | obj[front]).astype(np.uint32)
    obj[~front] = -1
    obj_t[~front] = np.inf
    is_spr = np.array([d is not None for d in draws] + [False], bool)[obj]   # obj -1: the last
    spr_col, spr_row, spr_u, spr_v = spr
    spr_col[~is_spr], spr_row[~is_spr] = -1, -1
    spr_u[~is_spr], spr_v[~is_spr] = np.nan, np.nan
    is_mid = np.array([d is not None for d in mids] + [False], bool)[obj]
    mid_u[~is_mid], mid_v[~is_mid] = np.nan, np.nan
    v = View()
    v.scene, v.x, v.y, v.z, v.angle, v.look = m, x, y, z, float(angle), look
    v.dx, v.dy, v.yv = dx, dy, yv
    v.ids, v.t, v.line, v.part, v.ceil = out, world_t, hit_line, hit_part, ce[:-1]
    v.obj, v.obj_t, v.sprites = obj, obj_t, draws
    v.spr_col, v.spr_row, v.spr_u, v.spr_v = spr_col, spr_row, spr_u, spr_v
    v.mids, v.mid_u, v.mid_v = mids, mid_u, mid_v
    return v


# ---- output -------------------------------------------------------------------------------

def write_ids(path, ids):
    np.ascontiguousarray(ids, dtype="<u4").tofile(path)


def false_colour(ids):
    """RGB (200, 320, 3) uint8: black for nothing, walls bright, floors dark, ceilings mid;
    the hue is a hash of the id, so neighbouring surfaces differ."""
    ids = ids.astype(np.uint64)
    h = (ids * np.uint64(2654435761)) & np.uint64(0xFFFFFFFF)
    h ^= h >> np.uint64(15)
    rgb = np.stack([(h >> np.uint64(s)) & np.uint64(0xFF) for s in (0, 8, 16)], -1).astype(float)
    kind = (ids >> np.uint64(24)).astype(np.int64)
    lo = np.array([0, 96, 16, 56, 96])[np.clip(kind, 0, 4)][..., None]
    hi = np.array([0, 255, 120, 180, 255])[np.clip(kind, 0, 4)][..., None]
    return (lo + rgb * (hi - lo) / 255.0).astype(np.uint8)


def write_png_rgb(path, rgb):
    """An 8-bit RGB PNG (h x w x 3 uint8) through Pillow."""
    from PIL import Image  # only the PNG outputs need it; the ids alone need numpy only
    Image.fromarray(np.ascontiguousarray(rgb, dtype=np.uint8)).save(path, optimize=True)


def main(argv=None):
    ap = argparse.ArgumentParser(
        prog="refrender.py",
        description="Reference renderer: ray-cast surface ids of a source map (no BSP tree), "
                    "320x200 little-endian uint32, kind << 24 | index. Objects are their models' "
                    "faces; in a WAD map with its look (not --flat), a thing whose type has "
                    "sprites is its sprite instead (docs/objects.md \"Sprites\"): the image "
                    "of its rotation as seen from the eye (a mirrored lump flipped), a "
                    "rectangle parallel to the screen at its origin's depth, one texel a map "
                    "unit, cut at the floor under it, its transparent texels letting the ray "
                    "through, sorted against everything else by that depth; not drawn nearer "
                    "than 4 units.")
    ap.add_argument("scene", help="text scene, or FILE.wad:MAP01 / FILE.wad:E1M1")
    ap.add_argument("--at", help="X,Y[,Z] eye position (default: the player start; Z: the "
                                 "floor of the eye's sector + 41)")
    ap.add_argument("--angle", help="degrees, 0 = east, counter-clockwise "
                                               "(default: the player start's)")
    ap.add_argument("--look", type=int, default=0, help="vertical shear in pixels, -100..100")
    ap.add_argument("--ids", help="output id buffer")
    ap.add_argument("--raw", help="output the expected colours (WAD maps): 64,000 palette indices")
    ap.add_argument("--expect", help="output the per-pixel texture, u, v, light and acceptable "
                                     "colours (WAD maps), .npz")
    ap.add_argument("--colour-png", help="output the expected colours as an RGB PNG (WAD maps)")
    ap.add_argument("--png", help="also write a false-colour PNG of the ids")
    ap.add_argument("--sky-owner", choices=("far", "near"), default="near",
                    help="sky seen over the missing upper wall between two sky sectors: the "
                         "ceiling of the eye's side (near, default) or of the sector beyond (far)")
    argv = list(sys.argv[1:] if argv is None else argv)
    for i in range(len(argv) - 1):     # let "--at -192,-160" through argparse
        if argv[i] in ("--at", "--angle", "--look") and argv[i + 1].startswith("-"):
            argv[i:i + 2] = [argv[i] + "=" + argv[i + 1], ""]
    ap.add_argument("--time", type=int, default=0,
                    help="the scene's objects along their paths at MS milliseconds (default 0)")
    ap.add_argument("--no-objects", action="store_true", help="draw no objects")
    ap.add_argument("--flat", action="store_true",
                    help="a WAD map as bspc --flat compiles it: its things boxes, no sprites "
                         "(by default a WAD map with its look draws the things Doom draws as "
                         "their sprites)")
    ap.add_argument("--door", action="append", default=[], metavar="SECTOR=H",
                    help="set a sector's ceiling (repeatable)")
    a = ap.parse_args([v for v in argv if v != ""])
    try:
        m = load(a.scene, a.flat)
        px, py, pa = m.player if m.player else (0.0, 0.0, 0.0)
        z = None
        if a.at:
            parts = a.at.split(",")
            if len(parts) not in (2, 3):
                ap.error("--at: expected X,Y or X,Y,Z")
            px, py = parts[0], parts[1]            # strings: rounded to 16.16 exactly
            z = parts[2] if len(parts) == 3 else None
        if a.angle is not None:
            pa = a.angle
        if not -100 <= a.look <= 100:
            ap.error("--look: expected -100..100")
        ceilings = {}
        for d in a.door:
            sec, eq, h = d.partition("=")
            if not eq or not sec.isdigit() or int(sec) >= m.nsectors:
                ap.error(f"--door '{d}': expected SECTOR=H with SECTOR < {m.nsectors}")
            ceilings[int(sec)] = _num(h, "--door")
        if not (a.ids or a.raw or a.expect or a.colour_png):
            ap.error("no output: give --ids, --raw, --expect or --colour-png")
        objs = [] if a.no_objects else object_states(m, a.time)
        view = cast_view(m, px, py, z, pa, a.look, sky_owner=a.sky_owner, objects=objs,
                         ceilings=ceilings)
        ids = view.ids
        if a.ids:
            write_ids(a.ids, ids)
        if a.png:
            write_png_rgb(a.png, false_colour(ids))
        if a.raw or a.expect or a.colour_png:
            import reflook
            e = reflook.expect(view)
            if a.raw:
                e.colour.tofile(a.raw)
            if a.colour_png:
                write_png_rgb(a.colour_png, e.look.palette[e.colour])
            if a.expect:
                np.savez_compressed(a.expect, cat=e.cat, tex=e.tex, u=e.u, v=e.v, table=e.table,
                                    colour=e.colour, cand=e.cand,
                                    names=np.array([n for n, _ in e.look.names] or [""]))
    except (OSError, ValueError) as e:
        print(f"refrender: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
