#!/usr/bin/env python3
"""accuracy.py - compare two surface-id buffers (320x200 little-endian uint32, kind << 24 | index).

usage: tools/accuracy.py A.bin B.bin [--json]

Figures (A is usually the reference, tools/refrender.py; B the renderer under test):
- differ: the share of the 64,000 pixels whose ids differ (0.0 .. 1.0).
- none_a, none_b: the number of kind-0 ("nothing") pixels in each.
- edge_displacement (pixels, 0 .. 320): the largest horizontal displacement of an edge.
  An edge is a place in a row between two neighbouring pixels x-1 and x whose ids differ; it is
  at position x (1..319) and is labelled by the ordered pair (id left, id right). For every edge
  of A, its distance is |x - x'| to the nearest edge x' with the same label in the same row of
  B, or 320 when that row of B has no such edge; likewise for every edge of B against A. The
  figure is the maximum over all edges of both (0 when neither has an edge, or the buffers are
  equal). A wall edge that moved by one pixel gives 1; an edge that exists in only one buffer
  (a missing sliver of wall) gives 320. edge_displacement_p99 is the 99th percentile of the same
  distances, which is robust to a few such slivers.
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


def _edges(ids):
    """Per row: dict (left id, right id) -> sorted array of edge positions x (1..319)."""
    out = []
    for row in ids:
        xs = np.nonzero(row[1:] != row[:-1])[0] + 1
        d = {}
        for x in xs:
            d.setdefault((int(row[x - 1]), int(row[x])), []).append(int(x))
        out.append({k: np.array(v) for k, v in d.items()})
    return out


def _distances(ea, eb):
    """Distances of every edge of ea to the nearest same-label edge in eb (same row), capped."""
    dist = []
    for ra, rb in zip(ea, eb):
        for label, xs in ra.items():
            other = rb.get(label)
            if other is None:
                dist.extend([CAP] * len(xs))
                continue
            j = np.clip(np.searchsorted(other, xs), 1, len(other)) - 1
            d = np.abs(other[j] - xs)
            j2 = np.clip(j + 1, 0, len(other) - 1)
            d = np.minimum(d, np.abs(other[j2] - xs))
            dist.extend(np.minimum(d, CAP).tolist())
    return dist


def edge_distances(a, b):
    """All edge distances, A against B and B against A (see the header)."""
    ea, eb = _edges(as_ids(a)), _edges(as_ids(b))
    return np.array(_distances(ea, eb) + _distances(eb, ea), dtype=np.int64)


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
