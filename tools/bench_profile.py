#!/usr/bin/env python3
"""Where a frame's instructions go: per-instruction-address costs grouped into the stages of the
frame, for tools/bench.py (callgrind on x86-64) and tools/qemu_plugin/bench_m3.py (the QEMU
plugin's profile= on the Cortex-M3).

An address is named by its debug information (addr2line -f -i): the chain of functions inlined
there, innermost first. The stage is that of the innermost function that is not one of the
arithmetic helpers inlined everywhere (fixed.h, wide128.h: their instructions count for the
function they were inlined into), so inlining does not move work between stages. Code without
debug information keeps the symbol name callgrind or addr2line gives it.

The stage of a function: STAGE_OF_FILE_FUNCTION by file and name, then STAGE_OF_FUNCTION by name
(for files whose functions belong to different stages), else STAGE_OF_FILE by its source file,
else "other". A function that lands in
"other" without being listed is reported as unclassified by name, so a new file or function shows
up in the figures instead of hiding; add it to the tables below.
"""
import collections
import functools
import re
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

WALK = "tree walk and culling"
XFORM = "transform/clip/project"
COVER = "coverage/occlusion"
SCAN = "edge lists/scan"
FILL = "span fill and counters (hal)"
TEXTURE = "texels and light (texture.c)"
OBJECTS = "objects"
ARITH = "arithmetic helpers (out of line)"
OTHER = "other"
STAGES = [WALK, XFORM, COVER, SCAN, FILL, TEXTURE, OBJECTS, ARITH, OTHER]

STAGE_OF_FILE = {
    "firmware/bsp_walk.c": WALK,
    "firmware/eye.c": WALK,
    "firmware/clip.c": XFORM,
    "firmware/view.c": XFORM,
    "firmware/view.h": XFORM,
    "firmware/surfaces.c": XFORM,
    "firmware/occlusion.c": COVER,
    "firmware/cover.c": COVER,
    "firmware/cover.h": COVER,
    "firmware/direct.c": OBJECTS,    # but for the functions STAGE_OF_FILE_FUNCTION names
    "firmware/raster.c": SCAN,
    "firmware/raster.h": SCAN,
    "firmware/obj_draw.c": OBJECTS,
    "firmware/objects.c": OBJECTS,
    "firmware/fixed.c": ARITH,
    "hal/fb.c": FILL,
    "hal/hal.h": FILL,               # the inline run writers (hal_fill_run, hal_copy_run)
    "firmware/texture.c": TEXTURE,   # a textured span's texels, depths and light tables
    "firmware/texture.h": TEXTURE,
    "hal/perf.c": FILL,
    "hal/ram_target.c": FILL,
    "firmware/engine.c": OTHER,
    "firmware/render.c": OTHER,
    "firmware/camera.c": OTHER,
    "host/render.c": OTHER,
    "hal/null/hal_null.c": OTHER,
}

# Names that more than one file uses (the modes' own visit_leaf, add_polygon).
STAGE_OF_FILE_FUNCTION = {
    # direct.c: the pixel mask (cover.c) does its coverage; the rows are its scan
    ("firmware/direct.c", "visit_leaf"): WALK,
    ("firmware/direct.c", "add_polygon"): SCAN,
    ("firmware/direct.c", "box_hidden"): COVER,
    ("firmware/direct.c", "direct_render"): OTHER,
    ("firmware/direct.c", "direct_work_bytes"): OTHER,
    ("firmware/direct.c", "align8"): OTHER,
    ("firmware/direct.c", "object_count"): OTHER,
    ("firmware/painter.c", "place_objects"): OBJECTS,
}

STAGE_OF_FUNCTION = {
    # spans.c: edge lists, the surface stack, span collection and coverage
    "visit_leaf": WALK,
    "covered": COVER, "cover": COVER, "box_covered": COVER, "polygon_rows": COVER,
    "add_polygon": SCAN, "add_surface": SCAN, "insert_sorted": SCAN, "scan": SCAN, "scan_line": SCAN,
    "scan_lines": SCAN, "plan": SCAN, "nearest": SCAN, "overtake": SCAN, "overtakes_at": SCAN,
    "note": SCAN, "raise_surf": SCAN, "may_cross": SCAN, "in_front": SCAN, "mixed_front": SCAN,
    "plane_of": SCAN,
    "emit_span": FILL, "flush_spans": FILL, "push_span": FILL,
    "collect_objects": OBJECTS, "find_objects": OBJECTS, "box_add": OBJECTS, "obj_number": OBJECTS,
    "add_objects": OBJECTS, "any_in_view": OBJECTS, "object_bound": OBJECTS,
    # painter.c
    "number_leaf": WALK, "draw_leaf": WALK,
    "fill_polygon": SCAN,
    "draw_object": OBJECTS, "before": OBJECTS, "sort_far_first": OBJECTS,
    # elsewhere
    "close_columns": COVER,          # surfaces.c: closing the columns a solid wall covers
    "obj_ceil": XFORM,               # objects.h: a sector's ceiling now (doors), read for its walls
    "rast_span": FILL,               # raster.c: one span to the target
    "rast_clear": FILL,
    "scene_node_side": WALK,         # scene.c: the walk's side of a partition
    "scene_model_edges": OBJECTS,    # scene.c: an object model's edges, for the edge bound
    # the set-up of a frame and of a mode, which no stage owns
    "spans_render": OTHER, "painter_render": OTHER, "layout": OTHER, "align8": OTHER,
    "spans_work_bytes": OTHER, "painter_work_bytes": OTHER,
}

# Inlined helpers whose instructions count for the function they were inlined into.
HELPER_FILES = {"firmware/fixed.h", "firmware/wide128.h"}
# Out-of-line arithmetic of the compiler's runtime (libgcc on the Cortex-M3).
ARITH_SYMBOL = re.compile(r"^__(aeabi_[a-z0-9]+|(u?(div|mod|udivmod|divmod)[sdt]i[34])|"
                          r"(ashl|ashr|lshr|mul|neg|clz|ctz|ffs|popcount)[sdt]i[23])$")


def relative(path):
    """A source path as the tables above name it (relative to the tree), or as it was."""
    p = Path(path)
    try:
        return str(p.resolve().relative_to(ROOT)) if p.is_absolute() else str(p).lstrip("./") or str(p)
    except ValueError:
        return str(p)


def symbolize(binary, addrs, addr2line="addr2line"):
    """{address: [(function, file), ...] innermost first} from the binary's debug information."""
    addrs = sorted(set(addrs))
    if not addrs:
        return {}
    text = "".join(f"{a:#x}\n" for a in addrs)
    out = subprocess.run([addr2line, "-e", str(binary), "-f", "-i", "-a"], input=text, capture_output=True,
                         text=True, check=True).stdout.splitlines()
    chains, cur, i = {}, None, 0
    while i < len(out):
        line = out[i]
        if line.startswith("0x"):
            cur = int(line, 16)
            chains[cur] = []
            i += 1
            continue
        func = line.strip()
        loc = out[i + 1] if i + 1 < len(out) else "??:0"
        chains[cur].append((func, relative(loc.rsplit(":", 1)[0].split(" (discriminator")[0])))
        i += 2
    return chains


def function_of(chain, home=None):
    """(function, file) that an address's cost counts for: the innermost non-helper frame. An
    address whose every frame lies in a helper file (an inlined helper the debug information
    gives no inline record for) counts for its outermost function, in the file home says that
    function was seen in elsewhere."""
    for func, path in chain:
        if path not in HELPER_FILES:
            return func, path
    if not chain:
        return "??", "??"
    func, path = chain[-1]
    return func, (home or {}).get(func, path)


def stage_of(func, path):
    base = func.split(".")[0]        # clip_plane.isra.0, wall_part.part.0: the source function
    if (path, base) in STAGE_OF_FILE_FUNCTION:
        return STAGE_OF_FILE_FUNCTION[(path, base)]
    if base in STAGE_OF_FUNCTION:
        return STAGE_OF_FUNCTION[base]
    if path in STAGE_OF_FILE:
        return STAGE_OF_FILE[path]
    if ARITH_SYMBOL.match(base):
        return ARITH
    return OTHER


def known(func, path):
    base = func.split(".")[0]
    return (path, base) in STAGE_OF_FILE_FUNCTION or base in STAGE_OF_FUNCTION or path in STAGE_OF_FILE or \
        ARITH_SYMBOL.match(func)


class Profile:
    """Instructions per function ((function, file) -> count) and per stage, of one frame."""

    def __init__(self, per_function=None):
        self.functions = collections.Counter(per_function or {})

    def stages(self):
        out = collections.Counter()
        for (func, path), n in self.functions.items():
            out[stage_of(func, path)] += n
        return out

    def total(self):
        return sum(self.functions.values())

    def unclassified(self):
        return {k: n for k, n in self.functions.items() if stage_of(*k) == OTHER and not known(*k)}


def from_addresses(binary, costs, named=None, addr2line="addr2line"):
    """A Profile from {address: instructions} in binary (and {symbol: instructions} of code the
    binary does not hold, e.g. the C library's, which counts as its own function)."""
    chains = symbolize(binary, costs, addr2line)
    home = {f: p for chain in chains.values() for f, p in chain if p not in HELPER_FILES}
    funcs = collections.Counter()
    for a, n in costs.items():
        func, path = function_of(chains.get(a, []), home)
        funcs[(func, path)] += n
    for name, n in (named or {}).items():
        funcs[(name, "(library)")] += n
    return Profile(funcs)


# ---- callgrind -------------------------------------------------------------------------------

def _compressed(value, table):
    """callgrind's name compression: '(id) name' defines, '(id)' refers."""
    m = re.match(r"\((\d+)\)(?:\s+(.*))?$", value)
    if not m:
        return value
    if m.group(2) is not None:
        table[m.group(1)] = m.group(2)
    return table.get(m.group(1), value)


def read_callgrind(path, binary):
    """(total Ir, {address in binary's file: Ir}, {function outside binary: Ir}) from a callgrind
    output written with --dump-instr=yes. Addresses are as loaded; see load_offset."""
    objs, files, fns = {}, {}, {}
    ob = fn = None
    total = None
    in_bin = {}
    other = collections.Counter()
    fn_entry = {}                    # function in binary -> lowest address seen (its entry)
    binary = str(Path(binary).resolve())
    skip_next = False
    last = [0, 0]
    with open(path) as f:
        for line in f:
            c = line[0] if line else ""
            if c.isdigit() or c in "+-*":
                parts = line.split()
                pos = []
                for k in range(2):
                    t = parts[k]
                    if t == "*":
                        v = last[k]
                    elif t[0] in "+-":
                        v = last[k] + int(t, 0)
                    else:
                        v = int(t, 0)
                    pos.append(v)
                last = pos
                if skip_next:        # the inclusive cost of a call: counted where it is spent
                    skip_next = False
                    continue
                ir = int(parts[2]) if len(parts) > 2 else 0
                if ob == binary:
                    in_bin[pos[0]] = in_bin.get(pos[0], 0) + ir
                    if fn is not None and (fn not in fn_entry or pos[0] < fn_entry[fn]):
                        fn_entry[fn] = pos[0]
                else:
                    other[fn] += ir
                continue
            key, _, val = line.rstrip("\n").partition("=")
            if key == "ob":
                ob = _compressed(val, objs)
            elif key == "cob":
                _compressed(val, objs)
            elif key in ("fl", "fi", "fe", "cfi", "cfl"):
                _compressed(val, files)
            elif key == "fn":
                fn = _compressed(val, fns)
            elif key == "cfn":
                _compressed(val, fns)
            elif key == "calls":
                skip_next = True
            elif key in ("summary", "totals") or line.startswith(("summary:", "totals:")):
                m = re.match(r"^(?:summary|totals):\s*(\d+)", line)
                if m:
                    total = int(m.group(1))
    if total is None:
        raise RuntimeError(f"{path}: no callgrind summary")
    return total, in_bin, other, fn_entry


@functools.lru_cache(maxsize=None)
def _symbols(binary):
    syms = {}
    for line in subprocess.run(["nm", binary], capture_output=True, text=True, check=True).stdout.splitlines():
        p = line.split()
        if len(p) == 3 and p[1] in "tT":
            syms[p[2]] = int(p[0], 16)
    return syms


def load_offset(binary, fn_entry):
    """Where callgrind saw the binary loaded (a PIE is placed by valgrind): the difference, most
    common over the functions seen, between a function's lowest address and its symbol's."""
    syms = _symbols(str(binary))
    deltas = collections.Counter(a - syms[f] for f, a in fn_entry.items() if f in syms)
    return deltas.most_common(1)[0][0] if deltas else 0
