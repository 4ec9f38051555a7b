#!/usr/bin/env python3
"""doomcompare.py - the project's frame of a Doom map's player start beside Chocolate Doom's
(make compare-doom), things and all.

For each FILE.wad:MAP (or `all`: the 43 Freedoom starts of ALL_STARTS) it
  1. writes a Doom 1.9 demo (.lmp) that starts MAP on skill 3 ("hurt me plenty", the things the
     project compiles), stands still for --tics game tics (default 1), then pauses the game
     (a pause button in the demo: from then on Doom's thinkers do not run) and holds the pause
     for 3 more tics;
  2. plays it with chocolate-doom -timedemo under SDL's dummy video driver, which saves every
     presented frame as SDL_window1-NNNNNNNN.bmp (SDL_VIDEO_DUMMY_SAVE_FRAMES), with a config
     that draws the whole 320x200 screen as the view (screenblocks 11: no status bar), no
     aspect-ratio correction and a 320x200 window, and takes the last frame (after the screen
     melt; the last two, paused, are checked to be the same). Two things keep Doom's frame to what
     the project draws:
       - a DeHackEd patch (-deh) gives every state of Doom's state table an endless duration,
         so each thing stays in the first state of its spawn state, the frame the project
         draws, and no monster ever looks for the player, wakes or moves (without it Doom
         starts each thing 1 to T tics into its spawn state, so some already show their next
         frame at tic 1);
       - a PWAD merged in (-merge) makes the PAUSE picture empty and holds the lights at their
         sectors' levels, as the project draws them: it carries the map with the light
         specials (blinking, glowing, flickering) taken off its sectors (at tic 1 the
         synchronised blinks have already gone dark and the glows 8 levels down);
       --live keeps Doom's states and lights running (no patch, the map as it is);
     and plays it a second time with every sprite lump but the player's weapons' made empty
     too: Doom's frame without its things, for where Doom draws things;
  3. renders the same view with build/render FILE.wad:MAP (the player start, Doom's eye
     height) and its id buffer;
  4. compares the mean colour of each 8x8 block, taken over the block's pixels that Doom's
     weapon does not cover (the pistol as R_DrawPSprite places it at that tic; a block it
     covers wholly is left out; with the patch the pistol stays lowered, below the screen, and
     covers nothing), within --tol of Chocolate Doom's in every channel:
       frame  - every block;
       things - the blocks that hold a thing: a pixel where the project's id buffer has an
                object (kind 4), or where Doom's frame differs from its frame without things;
       world  - the other blocks (the figure this tool gave before things were drawn);
  5. writes build/compare/NAME_MAP.png (Chocolate Doom left, the project right, 2x), the two
     frames and Doom's frame without things, and prints each start as one line, a summary
     over several, and each start as one JSON object.
"""
import argparse
import json
import os
import shutil
import struct
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
from PIL import Image

ROOT = Path(__file__).resolve().parent.parent
W, H = 320, 200
BLOCK = 8
TOL = 24
KIND_OBJECT = 4
WAD_DIRS = (os.environ.get("DOOMWADDIR", ""), "/usr/share/games/doom")
DEFAULT_MAPS = ("freedoom2.wad:MAP01", "freedoom1.wad:E1M1")
# `all`: the player starts the comparison is measured at (docs/benchmarks.md, "Beside Chocolate
# Doom"): freedoom2 MAP01-MAP12, 15, 20, 25, 29-32 and freedoom1 E1-E4 M1, M2, M3, M5, M7, M9.
ALL_STARTS = tuple([f"freedoom2.wad:MAP{m:02d}" for m in (*range(1, 13), 15, 20, 25, 29, 30, 31, 32)]
                   + [f"freedoom1.wad:E{e}M{m}" for e in (1, 2, 3, 4) for m in (1, 2, 3, 5, 7, 9)])
# the goals, printed beside the summary of several starts
GOAL_FRAME, GOAL_THINGS = 97.0, 85.0

# Doom 1.9 demo: version, skill, episode, map, deathmatch, respawn, fast, nomonsters,
# console player, players in game [4]; then per tic and player forwardmove, sidemove,
# angleturn, buttons; then the end marker.
DEMO_VERSION = 109
DEMO_HEADER = 13
DEMO_END = 0x80
BT_PAUSE = 0x81        # BT_SPECIAL | BTS_PAUSE: G_Ticker toggles the pause before P_Ticker runs
SKILL_HMP = 2          # Doom's skill index 2 = skill 3, the THINGS flag bit 0x0002 bspc keeps
DEFAULT_TICS = 1       # game tics before the pause: P_SetupLevel leaves viewz = 1 until the
                       # first P_PlayerThink, so tic 1 is the first with the eye in place
HOLD_TICS = 3          # paused tics after the pause tic; the last two frames must be the same
                       # (the frames just after the melt can still differ in a few pixels:
                       # freedoom2 MAP03, 12 pixels of one row, though the game is paused)

# The player's weapon: the pistol, the weapon every map starts with. P_SetupPsprites brings it
# up from WEAPONBOTTOM with A_Raise run once at set-up, then once a tic, RAISESPEED a time, until
# WEAPONTOP; A_WeaponReady then sets sx = 1 (no bob standing still). While it rises sx is 0.
WEAPON_SPRITE = "PISGA0"
WEAPONTOP, WEAPONBOTTOM, RAISESPEED = 32, 128, 6
# the sprites Doom draws as the player's weapon and its flash (psprites): kept in the frame
# without things, so the only pixels that differ between the two frames are the things'
WEAPON_SPRITES = frozenset(("PUNG", "PISG", "PISF", "SHTG", "SHTF", "SHT2", "CHGG", "CHGF",
                            "MISG", "MISF", "SAWG", "PLSG", "PLSF", "BFGG", "BFGF"))
NUMSTATES = 967        # Doom 1.9's state table (info.c), S_NULL .. S_TECH2LAMP4

# Sector specials that start a light thinker (P_SpawnSpecials): 1 blinks at random, 2, 3 and 4
# blink (4 also hurts), 8 glows, 12 and 13 blink in step, 17 flickers.
LIGHT_SPECIALS = frozenset((1, 2, 3, 4, 8, 12, 13, 17))
SECTOR_SIZE, SECTOR_SPECIAL = 26, 22
# the lumps of a map, after its marker, in the order Doom reads them (P_SetupLevel)
MAP_LUMPS = ("THINGS", "LINEDEFS", "SIDEDEFS", "VERTEXES", "SEGS", "SSECTORS", "NODES",
             "SECTORS", "REJECT", "BLOCKMAP")

# A Doom picture one column wide with no posts: draws nothing.
EMPTY_PATCH = struct.pack("<hhhhI", 1, 1, 0, 0, 12) + bytes([0xFF])


# ---- the demo and what Chocolate Doom is given besides -----------------------------------------

def demo_lump(episode, mapnum, tics, skill=SKILL_HMP, hold=None):
    """A demo in which player 1 alone stands still for `tics` tics; with `hold`, one tic more
    pauses the game and `hold` paused tics follow."""
    if not (1 <= episode <= 9 and 1 <= mapnum <= 99 and tics >= 1 and (hold is None or hold >= 0)):
        raise ValueError(f"bad demo: episode {episode} map {mapnum} tics {tics} hold {hold}")
    header = bytes([DEMO_VERSION, skill, episode, mapnum, 0, 0, 0, 0, 0, 1, 0, 0, 0])
    cmds = bytes(4 * tics)
    if hold is not None:
        cmds += bytes([0, 0, 0, BT_PAUSE]) + bytes(4 * hold)
    return header + cmds + bytes([DEMO_END])


def parse_demo(data):
    """The header and tics of a single-player Doom 1.9 demo (ValueError if it is not one)."""
    if len(data) < DEMO_HEADER + 1 or data[0] != DEMO_VERSION:
        raise ValueError("not a Doom 1.9 demo")
    keys = ("version", "skill", "episode", "map", "deathmatch", "respawn", "fast", "nomonsters",
            "consoleplayer")
    d = dict(zip(keys, data[:9]))
    d["players"] = list(data[9:13])
    per_tic = 4 * sum(1 for p in d["players"] if p)
    body = data[DEMO_HEADER:]
    end = len(body) - 1
    if per_tic == 0 or body[end] != DEMO_END or end % per_tic:
        raise ValueError("demo tics do not end with the end marker")
    d["tics"] = [tuple(struct.unpack_from("<bbBB", body, i)) for i in range(0, end, 4)]
    return d


def map_numbers(mapname):
    """(episode, map) of E#M# or MAP##."""
    m = mapname.upper()
    if len(m) == 4 and m[0] == "E" and m[2] == "M" and m[1].isdigit() and m[3].isdigit():
        return int(m[1]), int(m[3])
    if len(m) == 5 and m.startswith("MAP") and m[3:].isdigit():
        return 1, int(m[3:])
    raise ValueError(f"not a Doom map name: {mapname}")


def frozen_deh():
    """A DeHackEd patch that makes every state last for ever (duration -1): P_SpawnMapThing then
    leaves each thing's tics alone, no thing leaves the first state of its spawn state (whose
    action, A_Look for monsters, Doom does not run at spawn), and the weapon stays where
    P_SetupPsprites put it."""
    return ("Patch File for DeHackEd v3.0\nDoom version = 21\nPatch format = 6\n\n"
            + "".join(f"Frame {i}\nDuration = -1\n\n" for i in range(NUMSTATES)))


def pwad(lumps):
    """A PWAD of (name, bytes) lumps, in order."""
    dirs, pos = [], 12
    for name, data in lumps:
        dirs.append(struct.pack("<II8s", pos, len(data), name.encode("latin-1")))
        pos += len(data)
    body = b"".join(data for _, data in lumps)
    return struct.pack("<4sII", b"PWAD", len(lumps), 12 + len(body)) + body + b"".join(dirs)


def still_sectors(data):
    """A SECTORS lump with the light specials (LIGHT_SPECIALS) set to 0."""
    out = bytearray(data)
    for ofs in range(SECTOR_SPECIAL, len(out) - len(out) % SECTOR_SIZE, SECTOR_SIZE):
        if struct.unpack_from("<h", out, ofs)[0] in LIGHT_SPECIALS:
            struct.pack_into("<h", out, ofs, 0)
    return bytes(out)


def map_lumps(path, mapname):
    """[(name, bytes)] of MAP's marker and its lumps, as the WAD has them."""
    data = Path(path).read_bytes()
    d = wad_directory(data)
    names = [n for n, _, _ in d]
    if mapname.upper() not in names:
        raise KeyError(f"{path}: no lump {mapname.upper()}")
    i = names.index(mapname.upper())
    out = [(name, data[pos:pos + size]) for name, pos, size in d[i:i + 1 + len(MAP_LUMPS)]]
    if tuple(n for n, _ in out[1:]) != MAP_LUMPS:
        raise ValueError(f"{path}: {mapname} is not followed by {', '.join(MAP_LUMPS)}")
    return out


def chocolate_pwad(wad, things=True, weapon=True, mapname=None):
    """The PWAD Chocolate Doom merges in: an empty PAUSE picture; with `mapname`, that map with
    its sectors' light specials taken off (still_sectors); without `things`, an empty picture
    under the name of each of the WAD's sprite lumps but the weapons' (without `weapon`, of
    each weapon's)."""
    lumps = [("M_PAUSE", EMPTY_PATCH)]
    if mapname:
        lumps += [(n, still_sectors(b) if n == "SECTORS" else b) for n, b in map_lumps(wad, mapname)]
    blank = [n for n in sprite_lumps(wad)
             if not (things if n[:4] not in WEAPON_SPRITES else weapon)]
    if blank:
        lumps += [("S_START", b"")] + [(n, EMPTY_PATCH) for n in blank] + [("S_END", b"")]
    return pwad(lumps)


# ---- the WAD ------------------------------------------------------------------------------------

def find_wad(name):
    if os.path.isfile(name):
        return name
    for d in WAD_DIRS:
        if d and os.path.isfile(os.path.join(d, name)):
            return os.path.join(d, name)
    raise FileNotFoundError(f"{name}: not found (looked in {', '.join(d for d in WAD_DIRS if d)})")


def wad_directory(data):
    """[(NAME, offset, size)] of a WAD's bytes, in directory order."""
    _, n, ofs = struct.unpack_from("<4sII", data, 0)
    out = []
    for i in range(n):
        pos, size, lname = struct.unpack_from("<II8s", data, ofs + 16 * i)
        out.append((lname.split(b"\0")[0].decode("latin-1").upper(), pos, size))
    return out


def wad_lump(path, name):
    data = Path(path).read_bytes()
    for lname, pos, size in wad_directory(data):
        if lname == name:
            return data[pos:pos + size]
    raise KeyError(f"{path}: no lump {name}")


def sprite_lumps(path):
    """The names of the lumps between S_START and S_END (or SS_START and SS_END)."""
    out, inside = [], False
    for name, _, _ in wad_directory(Path(path).read_bytes()):
        if name in ("S_START", "SS_START"):
            inside = True
        elif name in ("S_END", "SS_END"):
            inside = False
        elif inside and len(name) >= 6:
            out.append(name)
    return out


def palette(path):
    return np.frombuffer(wad_lump(path, "PLAYPAL")[:768], np.uint8).reshape(256, 3)


def draw_patch(patch, x, y):
    """A Doom picture (patch format) drawn at x, y less its offsets, clipped to 320x200:
    (palette indices, mask of the pixels it covers)."""
    w, _, left, top = struct.unpack_from("<hhhh", patch, 0)
    idx = np.zeros((H, W), np.uint8)
    mask = np.zeros((H, W), bool)
    x0, y0 = x - left, y - top
    for c in range(w):
        (pos,) = struct.unpack_from("<I", patch, 8 + 4 * c)
        sx = x0 + c
        while 0 <= sx < W and pos + 1 < len(patch) and patch[pos] != 0xFF:
            row, n = patch[pos], patch[pos + 1]
            for k in range(n):
                sy = y0 + row + k
                if 0 <= sy < H and pos + 3 + k < len(patch):
                    idx[sy, sx] = patch[pos + 3 + k]
                    mask[sy, sx] = True
            pos += n + 4
    return idx, mask


def weapon_place(tics, frozen=True):
    """(sx, sy) of the pistol psprite after `tics` game tics (standing still, not firing)."""
    sy = WEAPONBOTTOM - RAISESPEED                    # A_Raise, run once by P_SetupPsprites
    if frozen:
        return 0, sy                                  # S_PISTOLUP lasts for ever: no more raising
    sy -= RAISESPEED * tics
    return (1, WEAPONTOP) if sy <= WEAPONTOP else (0, sy)


def weapon_mask(path, tics=DEFAULT_TICS, frozen=True):
    """The screen pixels the pistol covers after `tics` tics, as R_DrawPSprite places it at
    320x200 with screenblocks 11 (scale 1): x = sx - leftoffset, y = sy - topoffset."""
    sx, sy = weapon_place(tics, frozen)
    return draw_patch(wad_lump(path, WEAPON_SPRITE), sx, sy)[1]


# ---- the two frames ---------------------------------------------------------------------------

def find_chocolate():
    exe = shutil.which("chocolate-doom") or "/usr/games/chocolate-doom"
    if not os.access(exe, os.X_OK):
        raise FileNotFoundError("chocolate-doom is not installed (make deps installs it)")
    return exe


# -config: the game's own settings; -extraconfig: Chocolate Doom's video settings.
GAME_CFG = "screenblocks 11\nshow_messages 0\nsnd_channels 1\nusegamma 0\n"
VIDEO_CFG = ("fullscreen 0\naspect_ratio_correct 0\nwindow_width 320\nwindow_height 200\n"
             "integer_scaling 1\nforce_software_renderer 1\nstartup_delay 0\ngrabmouse 0\n"
             "png_screenshots 1\n")


def chocolate_frame(wad, mapname, tics=DEFAULT_TICS, timeout=60, keep=None, things=True,
                    frozen=True, hold=HOLD_TICS, weapon=True):
    """Chocolate Doom's frame of MAP's player start after `tics` game tics standing still, the
    game then paused (demo_lump with `hold`): (320x200x3 uint8 RGB, info). Without `things`
    (`weapon`), every sprite but the weapons' (every weapon sprite) is an empty picture;
    `frozen`: the states last for ever (frozen_deh) and the lights stay at their sectors'
    levels (chocolate_pwad with the map)."""
    episode, mapnum = map_numbers(mapname)
    total = tics + 1 + hold
    with tempfile.TemporaryDirectory(prefix="doomcompare-") as tmp:
        t = Path(tmp)
        (t / "stand.lmp").write_bytes(demo_lump(episode, mapnum, tics, hold=hold))
        (t / "default.cfg").write_text(GAME_CFG)
        (t / "chocolate-doom.cfg").write_text(VIDEO_CFG)
        (t / "look.wad").write_bytes(chocolate_pwad(wad, things, weapon, mapname if frozen else None))
        env = dict(os.environ, SDL_VIDEODRIVER="dummy", SDL_VIDEO_DUMMY_SAVE_FRAMES="1",
                   SDL_AUDIODRIVER="dummy", HOME=tmp, XDG_DATA_HOME=tmp,
                   XDG_CONFIG_HOME=tmp)
        cmd = [find_chocolate(), "-iwad", os.path.abspath(wad), "-timedemo", "stand.lmp",
               "-config", "default.cfg", "-extraconfig", "chocolate-doom.cfg",
               "-merge", "look.wad", "-nosound", "-nomusic", "-nogui", "-nograbmouse"]
        if frozen:
            (t / "frozen.deh").write_text(frozen_deh())
            cmd += ["-deh", "frozen.deh"]
        try:
            proc = subprocess.run(cmd, cwd=tmp, env=env, capture_output=True, text=True,
                                  timeout=timeout)
        except subprocess.TimeoutExpired:
            raise RuntimeError(f"chocolate-doom ran past {timeout} s: {' '.join(cmd)}")
        log = proc.stdout + proc.stderr
        # -timedemo ends with I_Error("timed N gametics ..."), so its exit code is not 0
        timed = [ln for ln in log.splitlines() if ln.startswith("timed ")]
        frames = sorted(t.glob("SDL_window*-*.bmp"))
        if not timed or not frames:
            raise RuntimeError(f"chocolate-doom did not play the demo (exit {proc.returncode}):\n{log[-600:]}")
        if f"timed {total} gametics" not in timed[0]:
            raise RuntimeError(f"chocolate-doom: {timed[0]} (expected {total} gametics)")
        # the melt wipe runs within the first tic's display; every tic after it presents one frame
        if len(frames) < total:
            raise RuntimeError(f"chocolate-doom saved {len(frames)} frames for {total} tics")
        if hold >= 1 and (np.asarray(Image.open(frames[-2]).convert("RGB"))
                          != np.asarray(Image.open(frames[-1]).convert("RGB"))).any():
            raise RuntimeError("chocolate-doom's last two paused frames differ: the pause did not hold")
        img = Image.open(frames[-1]).convert("RGB")
        if keep:
            shutil.copy(frames[-1], keep)
        rgb = to_320x200(np.asarray(img))
        return rgb, {"frames": len(frames), "frame": frames[-1].name, "timed": timed[0],
                     "saved_size": list(img.size)}


def to_320x200(rgb):
    """The saved window as the 320x200 screen: an exact integer downscale of a bigger window."""
    h, w = rgb.shape[:2]
    if w % W or h % H or w // W != h // H:
        raise RuntimeError(f"chocolate-doom's frame is {w}x{h}: not a whole multiple of {W}x{H}")
    k = w // W
    return np.ascontiguousarray(rgb[::k, ::k])


def chocolate_frames(wad, mapname, tics=DEFAULT_TICS, timeout=60, frozen=True):
    """Chocolate Doom's frame with its things and without (two runs at once), the pixels
    where they differ (where Doom draws a thing) and the first run's info."""
    with ThreadPoolExecutor(2) as pool:
        runs = [pool.submit(chocolate_frame, wad, mapname, tics, timeout, None, things, frozen)
                for things in (True, False)]
        (rgb, info), (bare, _) = [r.result() for r in runs]
    return rgb, bare, (rgb != bare).any(axis=2), info


def project_frame(render, spec, tmp):
    """build/render's frame of SPEC's player start: (RGB, id buffer, render's JSON)."""
    png, ids = Path(tmp) / "project.png", Path(tmp) / "project.ids"
    proc = subprocess.run([render, spec, "-o", str(png), "--ids", str(ids)], capture_output=True,
                          text=True, timeout=300)
    if proc.returncode != 0:
        raise RuntimeError(f"{render} {spec} exited {proc.returncode}:\n{proc.stderr}")
    rgb = np.asarray(Image.open(png).convert("RGB"))
    idbuf = np.fromfile(ids, "<u4").reshape(H, W)
    return rgb, idbuf, json.loads(proc.stdout)


# ---- the figures --------------------------------------------------------------------------------

def block_sums(a):
    """Per 8x8 block sums of an HxW or HxWxC array."""
    return a.reshape(H // BLOCK, BLOCK, W // BLOCK, BLOCK, *a.shape[2:]).sum(axis=(1, 3))


def blocks_any(mask):
    return mask.reshape(H // BLOCK, BLOCK, W // BLOCK, BLOCK).any(axis=(1, 3))


def share(agree, n):
    """{share, agree, blocks}; share None where there are no blocks."""
    return {"share": round(100.0 * agree / n, 2) if n else None, "agree": int(agree),
            "blocks": int(n)}


def block_metric(ref, ours, ids, tol=TOL, ref_things=None, weapon=None):
    """The 8x8 blocks whose mean colour is within tol of ref's in every channel, the means taken
    over the pixels `weapon` (Doom's weapon) does not cover; a block it covers wholly is left
    out. Three figures: frame (every block), things (the blocks with a pixel where `ids` has an
    object, kind 4, or where `ref_things` is set: where Doom draws a thing) and world (the
    other blocks)."""
    shown = np.ones((H, W), bool) if weapon is None else ~weapon
    n = block_sums(shown.astype(np.int64))
    counted = n > 0
    keep = shown[..., None].astype(np.int64)
    diff = (block_sums(ref.astype(np.int64) * keep) - block_sums(ours.astype(np.int64) * keep)) \
        / np.maximum(n, 1)[..., None]
    near = (np.abs(diff) <= tol).all(axis=2) & counted
    ours_obj = blocks_any(((ids >> 24) == KIND_OBJECT) & shown) & counted
    doom_obj = (blocks_any(ref_things & shown) if ref_things is not None
                else np.zeros_like(counted)) & counted
    things = ours_obj | doom_obj
    world = counted & ~things
    return {"frame": share((near & counted).sum(), counted.sum()),
            "things": share((near & things).sum(), things.sum()),
            "world": share((near & world).sum(), world.sum()),
            "our_thing_blocks": int(ours_obj.sum()), "doom_thing_blocks": int(doom_obj.sum()),
            "weapon_pixels": int(weapon.sum()) if weapon is not None else 0,
            "weapon_blocks": int(blocks_any(weapon).sum()) if weapon is not None else 0,
            "weapon_blocks_left_out": int((~counted).sum())}


def chocolate_palette(pal):
    """The RGB Chocolate Doom shows for each palette entry: gamma table 0 (usegamma 0) adds one
    below 128, and the VGA DAC's 6 bits per channel drop the low two bits."""
    p = pal.astype(int)
    return np.where(p < 128, p + 1, p) & ~3


def in_palette(rgb, pal):
    """Share of pixels whose colour is one Chocolate Doom shows for a palette entry: 100 when the
    frame reached the BMP unscaled and unfiltered."""
    shown = chocolate_palette(pal)
    codes = shown[:, 0] << 16 | shown[:, 1] << 8 | shown[:, 2]
    px = rgb.reshape(-1, 3).astype(int)
    return round(100.0 * np.isin(px[:, 0] << 16 | px[:, 1] << 8 | px[:, 2], codes).mean(), 2)


def side_by_side(left, right, path, scale=2):
    img = Image.new("RGB", (2 * W + 4, H), (255, 255, 255))
    img.paste(Image.fromarray(left), (0, 0))
    img.paste(Image.fromarray(right), (W + 4, 0))
    img.resize((img.width * scale, img.height * scale), Image.NEAREST).save(path)


def compare(spec, render, outdir, tics=DEFAULT_TICS, tol=TOL, timeout=60, frozen=True):
    wadname, _, mapname = spec.partition(":")
    if not mapname:
        raise ValueError(f"{spec}: give FILE.wad:MAP")
    wad = find_wad(wadname)
    map_numbers(mapname)
    wad_lump(wad, mapname.upper())      # a map the WAD lacks is named here, not by Chocolate Doom
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    stem = f"{Path(wadname).stem}_{mapname.upper()}"
    choco, bare, doom_things, info = chocolate_frames(wad, mapname, tics, timeout, frozen)
    with tempfile.TemporaryDirectory(prefix="doomcompare-") as tmp:
        ours, ids, _ = project_frame(render, f"{wad}:{mapname}", tmp)
    res = {"map": spec}
    res.update(block_metric(choco, ours, ids, tol, ref_things=doom_things,
                            weapon=weapon_mask(wad, tics, frozen)))
    res.update({"tol": tol, "block": BLOCK, "tics": tics, "frozen": frozen,
                "doom_thing_pixels": int(doom_things.sum()),
                "chocolate_frame": info["frame"], "chocolate_frames": info["frames"],
                "chocolate_saved_size": info["saved_size"],
                "chocolate_in_palette": in_palette(choco, palette(wad))})
    Image.fromarray(choco).save(outdir / f"{stem}_chocolate.png")
    Image.fromarray(bare).save(outdir / f"{stem}_chocolate_nothings.png")
    Image.fromarray(ours).save(outdir / f"{stem}_project.png")
    res["png"] = str(outdir / f"{stem}.png")
    side_by_side(choco, ours, res["png"])
    return res


def fmt(m):
    return "no blocks" if m["share"] is None else f"{m['share']:.1f}% ({m['agree']}/{m['blocks']})"


def line(r):
    return (f"{r['map']}: 8x8 blocks within {r['tol']} of Chocolate Doom: frame {fmt(r['frame'])}; "
            f"things {fmt(r['things'])}, {r['our_thing_blocks']} blocks ours, "
            f"{r['doom_thing_blocks']} Doom's; world {fmt(r['world'])}; Doom's weapon "
            f"{r['weapon_pixels']} px -> {r['png']}")


def summary(results):
    """Lowest and median of each figure over several starts, and how many meet the goals."""
    out = []
    for key, goal in (("frame", GOAL_FRAME), ("things", GOAL_THINGS), ("world", None)):
        got = [(r[key]["share"], r["map"]) for r in results if r[key]["share"] is not None]
        if not got:
            out.append(f"{key}: no start has such blocks")
            continue
        vals = sorted(v for v, _ in got)
        low = min(got)
        text = (f"{key}: {len(got)} starts, lowest {low[0]:.1f}% ({low[1]}), "
                f"median {float(np.median(vals)):.1f}%")
        if goal is not None:
            text += f", {sum(v >= goal for v in vals)} of {len(got)} at least {goal:g}%"
        out.append(text)
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0],
        epilog="Figures (8x8 blocks whose mean colour is within --tol of Chocolate Doom's in every "
               "channel, Doom's weapon left out): frame = every block; things = the blocks "
               "with a thing, ours (an object pixel in the id buffer) or Doom's (a pixel where "
               "its frame differs from its frame without things); world = the other blocks. "
               "MAP `all`: the 43 starts of ALL_STARTS.")
    ap.add_argument("maps", nargs="*", default=list(DEFAULT_MAPS), help="FILE.wad:MAP ... or all")
    ap.add_argument("--render", default=str(ROOT / "build/render"))
    ap.add_argument("--out", default=str(ROOT / "build/compare"))
    ap.add_argument("--tics", type=int, default=DEFAULT_TICS,
                    help="game tics Doom runs before it is paused (default 1, the first with the "
                         "eye at its height)")
    ap.add_argument("--live", action="store_true",
                    help="Doom's states and lights run (no DeHackEd patch, the map's light "
                         "specials kept): things may show a later frame, monsters that see the "
                         "player move, lights blink, the pistol rises into view from tic 5")
    ap.add_argument("--tol", type=int, default=TOL)
    ap.add_argument("--timeout", type=int, default=60)
    a = ap.parse_args(argv)
    if a.tics < 1:
        ap.error("--tics must be at least 1")
    maps = [m for spec in a.maps for m in (ALL_STARTS if spec == "all" else (spec,))]
    results = []
    for spec in maps:
        try:
            r = compare(spec, a.render, a.out, a.tics, a.tol, a.timeout, not a.live)
        except (ValueError, KeyError, OSError, RuntimeError) as e:
            why = e.args[0] if isinstance(e, KeyError) and e.args else e
            print(f"doomcompare: {spec}: {why}", file=sys.stderr)
            return 1
        results.append(r)
        print(line(r), flush=True)
    if len(results) > 1:
        for text in summary(results):
            print(text)
    for r in results:
        print(json.dumps(r))
    return 0


if __name__ == "__main__":
    sys.exit(main())
