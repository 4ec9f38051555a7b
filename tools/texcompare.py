#!/usr/bin/env python3
"""texcompare.py - a renderer's textured frame against the reference's texels and light.

Given a WAD map, a camera (build/render's --at/--angle/--look/--door/--time) and the renderer's frame
(--raw: 64,000 palette indices) and id buffer (--ids), it casts the reference's view
(tools/refrender.py: the world and the map's things at time 0, those Doom draws as their sprites,
docs/objects.md "Sprites"; --no-objects: the world alone) and its expected colours
(tools/reflook.py), and reports the share of compared pixels whose colour is acceptable: within
one texel and one light step of the reference's (docs/textures.md; a sprite's texel in its
image, its light table by the sprites' light rule). Compared: wall, floor, ceiling and sky pixels
with a texture in the reference where the renderer's id buffer shows no object, and the
reference's sprite pixels and see-through middle texture pixels where the renderer's id buffer
shows the same object ("sprite" and "midtex" in the counts). Prints one JSON object; --diff
writes the frame with the failures in red (the pixels not compared dimmed). Exit status 0, or 1 on bad input.

usage: tools/texcompare.py WAD:MAP --raw FRAME --ids IDS [--at X,Y[,Z]] [--angle DEG] [--look PX]
                           [--door SECTOR=H]... [--no-objects] [--time MS] [--diff OUT.png]

--time MS: the frames animated textures and flats show and how far scrolling walls moved at that
time (docs/textures.md, "Animation"), as build/render --time draws them.
"""
import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import reflook  # noqa: E402
import refrender  # noqa: E402


def reference(scene, at=None, angle=None, look=0, ceilings=None, objects=None, time_ms=0):
    """The reference's Expect for build/render's camera arguments (strings or numbers; None:
    the player start, the eye 41 above the floor) at time time_ms. objects: as refrender.cast_view
    takes them (build/render's JSON "objects"; [] the world alone); None: the map's own things,
    which is what build/render draws at time 0."""
    m = refrender.load(scene)
    x, y, a = m.player if m.player else (0.0, 0.0, 0.0)
    z = None
    if at is not None:
        parts = str(at).split(",")
        if len(parts) not in (2, 3):
            raise ValueError(f"--at '{at}': expected X,Y or X,Y,Z")
        x, y = parts[0], parts[1]
        z = parts[2] if len(parts) == 3 else None
    if angle is not None:
        a = angle
    view = refrender.cast_view(m, x, y, z, a, int(look), objects=objects, ceilings=ceilings or {})
    view.time_ms = int(time_ms)
    return reflook.expect(view)


def summary(counts):
    out = {"share": counts["all"][0] / counts["all"][1] if counts["all"][1] else 1.0,
           "compared": counts["all"][1], "acceptable": counts["all"][0]}
    out["kinds"] = {k: {"acceptable": ok, "compared": n} for k, (ok, n) in counts.items() if k != "all"}
    return out


def read_u8(path, n, what):
    data = np.fromfile(path, np.uint8)
    if data.size != n:
        raise ValueError(f"{path}: {what}: expected {n} bytes, got {data.size}")
    return data


def main(argv=None):
    ap = argparse.ArgumentParser(prog="texcompare.py", description=__doc__.split("\n\n")[1])
    ap.add_argument("scene", help="FILE.wad:MAP")
    ap.add_argument("--at")
    ap.add_argument("--angle")
    ap.add_argument("--look", type=int, default=0)
    ap.add_argument("--door", action="append", default=[], metavar="SECTOR=H")
    ap.add_argument("--time", type=int, default=0, metavar="MS", help="the time animated textures show")
    ap.add_argument("--raw", required=True, help="the renderer's frame: 64,000 palette indices")
    ap.add_argument("--ids", help="the renderer's id buffer (its object pixels are left out)")
    ap.add_argument("--diff", help="write the frame with the failures in red (PNG)")
    ap.add_argument("--no-objects", action="store_true",
                    help="the reference without the map's things (build/render --no-objects)")
    argv = list(sys.argv[1:] if argv is None else argv)
    for i in range(len(argv) - 1):     # let "--at -192,-160" through argparse
        if argv[i] in ("--at", "--angle", "--look") and argv[i + 1].startswith("-"):
            argv[i:i + 2] = [argv[i] + "=" + argv[i + 1], ""]
    a = ap.parse_args([v for v in argv if v != ""])
    try:
        ceilings = {}
        for d in a.door:
            sec, eq, h = d.partition("=")
            if not eq or not sec.isdigit():
                raise ValueError(f"--door '{d}': expected SECTOR=H")
            ceilings[int(sec)] = float(h)
        frame = read_u8(a.raw, 64000, "frame")
        ids = None
        if a.ids:
            ids = read_u8(a.ids, 256000, "id buffer").view("<u4")
        e = reference(a.scene, a.at, a.angle, a.look, ceilings, [] if a.no_objects else None, a.time)
        ok, compared, counts = reflook.compare(e, frame, ids)
        if a.diff:
            refrender.write_png_rgb(a.diff, reflook.diff_rgb(e, frame, ok, compared))
    except (OSError, ValueError) as err:
        print(f"texcompare: {err}", file=sys.stderr)
        return 1
    print(json.dumps(summary(counts)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
