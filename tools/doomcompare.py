#!/usr/bin/env python3
"""doomcompare.py - the project's frame of a Doom map's player start beside Chocolate Doom's
(make compare-doom).

For each FILE.wad:MAP it
  1. writes a Doom 1.9 demo (.lmp) that starts MAP on skill 3 ("hurt me plenty", the things the
     project compiles) and stands still for --tics tics;
  2. plays it with chocolate-doom -timedemo under SDL's dummy video driver, which saves every
     presented frame as SDL_window1-NNNNNNNN.bmp (SDL_VIDEO_DUMMY_SAVE_FRAMES), with a config
     that draws the whole 320x200 screen as the view (screenblocks 11: no status bar), no
     aspect-ratio correction and a 320x200 window, and takes the last frame: the screen melt
     is over by then (it runs before the first tic) and the weapon is fully raised (it rises
     6 pixels a tic for 16 tics);
  3. renders the same view with build/render FILE.wad:MAP (the player start, Doom's eye
     height) and its id buffer;
  4. counts the 8x8 blocks whose mean RGB colour is within --tol of Chocolate Doom's in every
     channel, leaving out the blocks where the project's id buffer has an object pixel
     (kind 4); the blocks that Chocolate Doom's weapon sprite covers stay in and are counted
     apart, as information;
  5. writes build/compare/NAME_MAP.png (Chocolate Doom left, the project right, 2x) and prints
     the figure as one line and as one JSON object.
"""
import argparse
import json
import os
import shutil
import struct
import subprocess
import sys
import tempfile
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

# Doom 1.9 demo: version, skill, episode, map, deathmatch, respawn, fast, nomonsters,
# console player, players in game [4]; then per tic and player forwardmove, sidemove,
# angleturn, buttons; then the end marker.
DEMO_VERSION = 109
DEMO_HEADER = 13
DEMO_END = 0x80
SKILL_HMP = 2          # Doom's skill index 2 = skill 3, the THINGS flag bit 0x0002 bspc keeps
DEFAULT_TICS = 20      # the pistol is up from tic 17 on; few tics leave monsters little time to move

# The pistol, the weapon every map starts with, in its ready state (A_WeaponReady with no
# bob: sx = 1, sy = WEAPONTOP = 32).
WEAPON_SPRITE = "PISGA0"
WEAPON_SX, WEAPON_SY = 1, 32


# ---- the demo ---------------------------------------------------------------------------------

def demo_lump(episode, mapnum, tics, skill=SKILL_HMP):
    """A demo in which player 1 alone stands still for `tics` tics."""
    if not (1 <= episode <= 9 and 1 <= mapnum <= 99 and tics >= 1):
        raise ValueError(f"bad demo: episode {episode} map {mapnum} tics {tics}")
    header = bytes([DEMO_VERSION, skill, episode, mapnum, 0, 0, 0, 0, 0, 1, 0, 0, 0])
    return header + bytes(4 * tics) + bytes([DEMO_END])


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


# ---- the WAD ------------------------------------------------------------------------------------

def find_wad(name):
    if os.path.isfile(name):
        return name
    for d in WAD_DIRS:
        if d and os.path.isfile(os.path.join(d, name)):
            return os.path.join(d, name)
    raise FileNotFoundError(f"{name}: not found (looked in {', '.join(d for d in WAD_DIRS if d)})")


def wad_lump(path, name):
    data = Path(path).read_bytes()
    _, n, ofs = struct.unpack_from("<4sII", data, 0)
    for i in range(n):
        pos, size, lname = struct.unpack_from("<II8s", data, ofs + 16 * i)
        if lname.rstrip(b"\0").decode("latin-1").upper() == name:
            return data[pos:pos + size]
    raise KeyError(f"{path}: no lump {name}")


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


def weapon_mask(path):
    """The screen pixels the ready pistol covers, as R_DrawPSprite places it at 320x200 with
    screenblocks 11 (scale 1): x = sx - leftoffset, y = sy - topoffset."""
    return draw_patch(wad_lump(path, WEAPON_SPRITE), WEAPON_SX, WEAPON_SY)[1]


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


def chocolate_frame(wad, mapname, tics=DEFAULT_TICS, timeout=60, keep=None):
    """Chocolate Doom's last frame of a demo standing still at MAP's player start:
    (320x200x3 uint8 RGB, info)."""
    episode, mapnum = map_numbers(mapname)
    with tempfile.TemporaryDirectory(prefix="doomcompare-") as tmp:
        t = Path(tmp)
        (t / "stand.lmp").write_bytes(demo_lump(episode, mapnum, tics))
        (t / "default.cfg").write_text(GAME_CFG)
        (t / "chocolate-doom.cfg").write_text(VIDEO_CFG)
        env = dict(os.environ, SDL_VIDEODRIVER="dummy", SDL_VIDEO_DUMMY_SAVE_FRAMES="1",
                   SDL_AUDIODRIVER="dummy", HOME=tmp, XDG_DATA_HOME=tmp,
                   XDG_CONFIG_HOME=tmp)
        cmd = [find_chocolate(), "-iwad", os.path.abspath(wad), "-timedemo", "stand.lmp",
               "-config", "default.cfg", "-extraconfig", "chocolate-doom.cfg",
               "-nosound", "-nomusic", "-nogui", "-nograbmouse"]
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
        if f"timed {tics} gametics" not in timed[0]:
            raise RuntimeError(f"chocolate-doom: {timed[0]} (expected {tics} gametics)")
        # the melt wipe runs before the first tic; every tic after it presents one frame
        if len(frames) < tics:
            raise RuntimeError(f"chocolate-doom saved {len(frames)} frames for {tics} tics")
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


# ---- the figure --------------------------------------------------------------------------------

def block_means(rgb):
    return rgb.reshape(H // BLOCK, BLOCK, W // BLOCK, BLOCK, 3).astype(np.float64).mean(axis=(1, 3))


def blocks_any(mask):
    return mask.reshape(H // BLOCK, BLOCK, W // BLOCK, BLOCK).any(axis=(1, 3))


def block_metric(ref, ours, ids, tol=TOL, info_mask=None):
    """Share of 8x8 blocks whose mean colour is within tol of ref's in every channel, blocks
    with an object pixel in `ids` (kind 4) left out. info_mask: pixels whose blocks are counted
    apart (they stay in the figure)."""
    near = (np.abs(block_means(ref) - block_means(ours)) <= tol).all(axis=2)
    objects = blocks_any((ids >> 24) == KIND_OBJECT)
    counted = ~objects
    agree = int((near & counted).sum())
    n = int(counted.sum())
    out = {"share": round(100.0 * agree / n, 2) if n else 0.0, "agree": agree, "blocks": n,
           "object_blocks": int(objects.sum())}
    if info_mask is not None:
        extra = blocks_any(info_mask)
        out["weapon_blocks"] = int(extra.sum())
        out["weapon_blocks_agree"] = int((extra & near & counted).sum())
    return out


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


def compare(spec, render, outdir, tics=DEFAULT_TICS, tol=TOL, timeout=60):
    wadname, _, mapname = spec.partition(":")
    if not mapname:
        raise ValueError(f"{spec}: give FILE.wad:MAP")
    wad = find_wad(wadname)
    map_numbers(mapname)
    wad_lump(wad, mapname.upper())      # a map the WAD lacks is named here, not by Chocolate Doom
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    stem = f"{Path(wadname).stem}_{mapname.upper()}"
    choco, info = chocolate_frame(wad, mapname, tics, timeout)
    with tempfile.TemporaryDirectory(prefix="doomcompare-") as tmp:
        ours, ids, _ = project_frame(render, f"{wad}:{mapname}", tmp)
    res = {"map": spec}
    res.update(block_metric(choco, ours, ids, tol, info_mask=weapon_mask(wad)))
    res.update({"tol": tol, "block": BLOCK, "tics": tics, "chocolate_frame": info["frame"],
                "chocolate_frames": info["frames"], "chocolate_saved_size": info["saved_size"],
                "chocolate_in_palette": in_palette(choco, palette(wad))})
    Image.fromarray(choco).save(outdir / f"{stem}_chocolate.png")
    Image.fromarray(ours).save(outdir / f"{stem}_project.png")
    res["png"] = str(outdir / f"{stem}.png")
    side_by_side(choco, ours, res["png"])
    return res


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("maps", nargs="*", default=list(DEFAULT_MAPS), help="FILE.wad:MAP ...")
    ap.add_argument("--render", default=str(ROOT / "build/render"))
    ap.add_argument("--out", default=str(ROOT / "build/compare"))
    ap.add_argument("--tics", type=int, default=DEFAULT_TICS)
    ap.add_argument("--tol", type=int, default=TOL)
    ap.add_argument("--timeout", type=int, default=60)
    a = ap.parse_args(argv)
    results = []
    for spec in a.maps:
        try:
            r = compare(spec, a.render, a.out, a.tics, a.tol, a.timeout)
        except (ValueError, KeyError, OSError, RuntimeError) as e:
            why = e.args[0] if isinstance(e, KeyError) and e.args else e
            print(f"doomcompare: {spec}: {why}", file=sys.stderr)
            return 1
        results.append(r)
        print(f"{spec}: {r['share']:.1f}% of 8x8 blocks within {r['tol']} of Chocolate Doom "
              f"({r['agree']}/{r['blocks']}; {r['object_blocks']} object blocks left out; "
              f"Chocolate Doom's weapon covers {r['weapon_blocks']}) -> {r['png']}")
    for r in results:
        print(json.dumps(r))
    return 0


if __name__ == "__main__":
    sys.exit(main())
