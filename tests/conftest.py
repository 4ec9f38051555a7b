"""Shared helpers for the integration tests: where the programs are, and how to run them.

The tests run the sanitized build (build/san: ASan + UBSan) of every program that
has one, so every scene and camera the tests try is also checked for undefined
behaviour and out-of-bounds access. BSPVGA_BIN overrides the folder.
"""
import json
import os
import struct
import subprocess
import zlib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
BUILD = ROOT / "build"
SAN = Path(os.environ.get("BSPVGA_BIN", BUILD / "san"))
WADDIR = Path(os.environ.get("DOOMWADDIR", "/usr/share/games/doom"))
# Every render mode of build/render --mode, in one place: tests that run each mode take them from here.
RENDER_MODES = ["direct", "spans", "painter", "columns"]

SAN_ENV = dict(os.environ, ASAN_OPTIONS="detect_leaks=1:abort_on_error=0",
               UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1")


def program(name, sanitized=True):
    path = (SAN if sanitized else BUILD) / name
    if not path.exists():
        pytest.fail(f"{path} is missing: run make first")
    return str(path)


def run(args, check=True, timeout=300, **kw):
    """Run a program; return the CompletedProcess (text mode)."""
    proc = subprocess.run([str(a) for a in args], capture_output=True, text=True, timeout=timeout,
                          env=kw.pop("env", SAN_ENV), **kw)
    if check and proc.returncode != 0:
        raise AssertionError(f"{args} exited {proc.returncode}:\n{proc.stderr}")
    return proc


def render(scene, *extra, at=None, angle=None, sanitized=True, check=True):
    """build/render with a camera (default: the player start); returns the parsed JSON."""
    cam = (["--at", at] if at is not None else []) + (["--angle", angle] if angle is not None else [])
    proc = run([program("render", sanitized), scene, *cam, *extra], check=check)
    assert proc.stdout.count("\n") == 1, proc.stdout
    out = json.loads(proc.stdout)
    # the scene's proven per-frame bounds (docs/needs.md) sized the pools: none may run full
    assert out.get("overflow", 0) == 0, (scene, cam, extra)
    return out


def read_png_indexed(path):
    """Decode an 8-bit palette PNG as written by host/png.c: (width, height, pixels, palette)."""
    data = Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, width = 8, b"", None
    palette = None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind = data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + length]
        assert zlib.crc32(kind + body) == struct.unpack(">I", data[pos + 8 + length:pos + 12 + length])[0]
        if kind == b"IHDR":
            width, height, depth, ctype = struct.unpack(">IIBB", body[:10])
            assert (depth, ctype) == (8, 3)
        elif kind == b"PLTE":
            palette = body
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    rows = [raw[y * (width + 1) + 1:(y + 1) * (width + 1)] for y in range(height)]
    assert all(raw[y * (width + 1)] == 0 for y in range(height))
    return width, height, b"".join(rows), palette


def wad_image(lumps, magic=b"PWAD"):
    """The bytes of a WAD of lumps [(name, bytes)] in order (a name str or bytes), the directory at the end."""
    body, directory, pos = b"", b"", 12
    for name, data in lumps:
        directory += struct.pack("<II8s", pos, len(data), name.encode() if isinstance(name, str) else name)
        body += data
        pos += len(data)
    return magic + struct.pack("<II", len(lumps), pos) + body + directory


def write_pwad_map(path, things, linedefs, sidedefs, vertexes, sectors):
    """Write a PWAD holding one Doom-format map, MAP01, from its lumps' bytes."""
    Path(path).write_bytes(wad_image([("MAP01", b""), ("THINGS", things), ("LINEDEFS", linedefs),
                                      ("SIDEDEFS", sidedefs), ("VERTEXES", vertexes), ("SECTORS", sectors)]))


def room_lumps(x0=0, y0=0, x1=256, y1=256, floor=0, ceil=128):
    """The lumps of a map that is one rectangular one-sided room, its player in the middle: name -> bytes,
    in a map's order."""
    verts = [(x0, y0), (x0, y1), (x1, y1), (x1, y0)]
    return {
        "THINGS": struct.pack("<hhhHH", (x0 + x1) // 2, (y0 + y1) // 2, 0, 1, 7),
        "LINEDEFS": b"".join(struct.pack("<HHHHHHH", i, (i + 1) % 4, 1, 0, 0, i, 0xFFFF) for i in range(4)),
        "SIDEDEFS": b"".join(struct.pack("<hh8s8s8sH", 0, 0, b"-", b"-", b"STARTAN3", 0) for _ in range(4)),
        "VERTEXES": b"".join(struct.pack("<hh", x, y) for x, y in verts),
        "SECTORS": struct.pack("<hh8s8shhh", floor, ceil, b"FLOOR4_8", b"CEIL3_5", 160, 0, 0),
    }


def freedoom(name):
    path = WADDIR / name
    if not path.exists():
        pytest.fail(f"{path} is missing: run make deps (Debian package freedoom)")
    return path
