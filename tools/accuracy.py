#!/usr/bin/env python3
"""accuracy.py - compare two surface-id buffers (320x200 little-endian uint32, kind << 24 | index).

usage: tools/accuracy.py A.bin B.bin [--json]

Figures (A is usually the reference, tools/refrender.py; B the renderer under test):
- differ: the share of the 64,000 pixels whose ids differ (0.0 .. 1.0).
- none_a, none_b: the number of kind-0 ("nothing") pixels in each.
- edge_displacement (pixels, 0 .. 320): the largest displacement of an edge between surfaces, in
  any direction. For every pixel where the ids differ, d_a is the distance (Chebyshev: rows and
  columns alike) to the nearest pixel of A that carries B's id there, and d_b the distance to the
  nearest pixel of B that carries A's id; the pixel's displacement is the larger of the two, and
  the figure is the maximum over all differing pixels (0 when the buffers are equal). An edge that
  moved by one pixel, sideways or up and down, gives 1; a surface that exists in only one buffer
  near there (a missing sliver of wall, a hole) gives 320, as does anything displaced by more than
  SEARCH pixels. edge_displacement_p99 is the 99th percentile over the differing pixels, which is
  robust to a few such slivers.
- walls_b_matched: of the pixels where B shows a wall (kind 1), the share where A has the same
  id (walls_a_matched: the same the other way round). This compares a walls-only renderer mode
  against the reference without counting its empty floors and ceilings.
"""
import argparse
import json
import sys

import numpy as np

W, H = 320, 200
CAP = 320


def read_ids(path):
    a = np.fromfile(path, dtype="<u4")
    if a.size != W * H:
        raise ValueError(f"{path}: {a.size * 4} bytes, expected {W * H * 4} (320x200 uint32)")
    return a.reshape(H, W).astype(np.uint32)


def as_ids(x):
    """A path or an array -> (200, 320) uint32 array."""
    if isinstance(x, np.ndarray):
        if x.shape != (H, W):
            x = x.reshape(H, W)
        return x.astype(np.uint32)
    return read_ids(x)


def differ(a, b):
    """Share of pixels whose ids differ."""
    return float(np.mean(as_ids(a) != as_ids(b)))


def none_count(a):
    """Number of kind-0 pixels."""
    return int(np.count_nonzero((as_ids(a) >> 24) == 0))


SEARCH = 32


def _nearest(src, want, ys, xs):
    """Per pixel (ys[i], xs[i]): the Chebyshev distance to the nearest pixel of src whose id is
    want[i], or CAP when there is none within SEARCH. Rings are searched outwards, each only for
    the pixels not yet matched."""
    dist = np.full(ys.size, CAP, np.int64)
    todo = np.nonzero(np.isin(want, src))[0]      # an id src lacks altogether is never found
    for r in range(1, SEARCH + 1):
        if todo.size == 0:
            break
        found = np.zeros(todo.size, bool)
        ring = [(dy, dx) for dy in range(-r, r + 1) for dx in range(-r, r + 1) if max(abs(dy), abs(dx)) == r]
        ty, tx, tw = ys[todo], xs[todo], want[todo]
        for dy, dx in ring:
            y, x = ty + dy, tx + dx
            ok = (y >= 0) & (y < H) & (x >= 0) & (x < W)
            found[ok] |= src[y[ok], x[ok]] == tw[ok]
        dist[todo[found]] = r
        todo = todo[~found]
    return dist


def edge_distances(a, b):
    """The displacement of every pixel whose ids differ (see the header)."""
    a, b = as_ids(a), as_ids(b)
    ys, xs = np.nonzero(a != b)
    if ys.size == 0:
        return np.zeros(0, np.int64)
    d = _nearest(b, a[ys, xs], ys, xs)
    rest = d < CAP                                 # the larger of the two is CAP already elsewhere
    d[rest] = np.maximum(d[rest], _nearest(a, b[ys[rest], xs[rest]], ys[rest], xs[rest]))
    return d


def edge_displacement(a, b):
    """The largest displacement of an edge in pixels (0..320; see the header)."""
    d = edge_distances(a, b)
    return int(d.max()) if d.size else 0


def walls_matched(ref, test):
    """Of the pixels where `test` shows a wall, the share where `ref` has the same id (1.0 when
    `test` has no wall pixel)."""
    ref, test = as_ids(ref), as_ids(test)
    walls = (test >> 24) == 1
    n = int(np.count_nonzero(walls))
    return 1.0 if n == 0 else float(np.count_nonzero(ref[walls] == test[walls])) / n


def compare(a, b):
    """All figures as a dict."""
    a, b = as_ids(a), as_ids(b)
    d = edge_distances(a, b)
    return {
        "pixels": W * H,
        "differ": differ(a, b),
        "differ_pixels": int(np.count_nonzero(a != b)),
        "none_a": none_count(a),
        "none_b": none_count(b),
        "edge_displacement": int(d.max()) if d.size else 0,
        "edge_displacement_p99": float(np.percentile(d, 99)) if d.size else 0.0,
        "walls_b_matched": walls_matched(a, b),
        "walls_a_matched": walls_matched(b, a),
    }


def main(argv=None):
    ap = argparse.ArgumentParser(prog="accuracy.py",
                                 description="Compare two 320x200 uint32 surface-id buffers.")
    ap.add_argument("a", help="id buffer A (e.g. the reference)")
    ap.add_argument("b", help="id buffer B (e.g. build/render --ids)")
    ap.add_argument("--json", action="store_true", help="one JSON object on stdout")
    args = ap.parse_args(argv)
    try:
        r = compare(args.a, args.b)
    except (OSError, ValueError) as e:
        print(f"accuracy: {e}", file=sys.stderr)
        return 1
    if args.json:
        print(json.dumps(r))
    else:
        print(f"differ:            {r['differ']:.4%} ({r['differ_pixels']} of {r['pixels']} pixels)")
        print(f"nothing (kind 0):  A {r['none_a']}, B {r['none_b']}")
        print(f"edge displacement: max {r['edge_displacement']} px, "
              f"p99 {r['edge_displacement_p99']:.1f} px")
        print(f"walls matched:     B's walls in A {r['walls_b_matched']:.4%}, "
              f"A's walls in B {r['walls_a_matched']:.4%}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
