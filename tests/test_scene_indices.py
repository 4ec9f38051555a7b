"""Every index of a compiled scene, out of range, is refused: each field that refers to other records,
in the first and the last record of its type, set one past its range, far past it and to huge values
(negative as signed), the CRC-32 recomputed so that the index check and not the CRC refuses it.
build/render (ASan + UBSan) must exit 1 with one message naming the record and "index out of range",
and render nothing.

The fields come from firmware/scene_format.h itself: the bracketed annotations at the end of the
comments ([index: ...], [child], [range: ...], [count of ...]; the header's opening comment lists
them), the layout from the C compiler (offsetof over the same header). A field added to the format
with an annotation is tested with no change here; test_every_index_field_is_annotated keeps a field
whose comment speaks of an index from going without one.
"""
import re
import subprocess
import zlib

import pytest

from conftest import ROOT, program, run

FORMAT = ROOT / "firmware" / "scene_format.h"
ANNOTATION = re.compile(r"\[(index: [^\]]+|child|range: [^\]]+|count of \w+)\]\s*$")
MEMBER = re.compile(r"^\s*((?:u?int\d+_t)|scn_\w+)\s+([^;]+);\s*(?:/\*(.*?)\*/)?\s*$")


def parse_format(text):
    """(sections, structs, defines): sections [(name, comment)] in SCN_SEC_* order; structs
    {type: [(ctype, name, dims, comment)]}; defines {name: int}."""
    enum = re.search(r"enum scn_section_id \{(.*?)\};", text, re.S).group(1)
    sections = [(m.group(1), m.group(2) or "")
                for m in re.finditer(r"SCN_SEC_(\w+),[ \t]*(?:/\*(.*?)\*/)?", enum) if m.group(1) != "COUNT"]
    structs = {}
    for body, name in re.findall(r"typedef struct \{(.*?)\} (scn_\w+);", text, re.S):
        members = []
        # a declaration a formatter wrapped after its type is one member
        body = re.sub(r"\b((?:u?int\d+_t)|scn_\w+)[ \t]*\n\s*(?=\w)", r"\1 ", body)
        for line in body.splitlines():
            m = MEMBER.match(line)
            if not m:
                # only blank lines and comments may be left unread: a member missed here
                # would drop out of the tests unnoticed
                assert re.fullmatch(r"\s*(/\*.*\*/)?\s*", line), f"{name}: cannot read '{line.strip()}'"
                continue
            for decl in m.group(2).split(","):
                decl = decl.strip()
                members.append((m.group(1), re.match(r"\w+", decl).group(0),
                                [int(d) for d in re.findall(r"\[(\d+)\]", decl)], m.group(3) or ""))
        structs[name] = members
    defines = {n: int(v, 0) for n, v in re.findall(r"#define (SCN_\w+) (0x[0-9A-Fa-f]+|\d+)u?\b", text)}
    return sections, structs, defines


SECTIONS, STRUCTS, DEFINES = parse_format(FORMAT.read_text())
SECTION_NO = {name: i for i, (name, _) in enumerate(SECTIONS)}


def record_sections(struct):
    """The sections whose records are struct (from the enum's comments: "scn_line[]")."""
    return [name for name, comment in SECTIONS if re.match(rf"\s*{struct}\[\d*\]", comment)]


def annotated_fields():
    """[(struct, member, element, annotation)]: every annotated field, array elements one by one."""
    out = []
    for struct, members in STRUCTS.items():
        for ctype, name, dims, comment in members:
            ann = ANNOTATION.search(comment)
            if not ann:
                continue
            assert len(dims) <= 1, (struct, name)
            for k in range(dims[0] if dims else 1):
                out.append((struct, name, k if dims else None, ann.group(1)))
    return out


FIELDS = annotated_fields()


def field_id(f):
    struct, name, k, _ = f
    return f"{struct}.{name}" + (f"[{k}]" if k is not None else "")


def test_every_index_field_is_annotated():
    """A field whose comment speaks of an index, or of where a run of records starts, carries its
    annotation, and every annotated structure is the record of a section (or the header)."""
    for struct, members in STRUCTS.items():
        for ctype, name, dims, comment in members:
            if re.search(r"\bindex\b|\bindices\b", comment) or re.match(r"first_|num_", name):
                assert ANNOTATION.search(comment) or re.search(r"\[count of \w+\]", comment), (struct, name)
    structs = {f[0] for f in FIELDS}
    assert len(FIELDS) >= 30 and {"scn_header", "scn_line", "scn_seg", "scn_node", "scn_leaf"} <= structs
    for struct in structs - {"scn_header"}:
        assert record_sections(struct), struct
    for name, comment in SECTIONS:
        if ANNOTATION.search(comment):
            assert name in SECTION_ELEMENTS, f"no handler for section {name}'s [{comment}]"


@pytest.fixture(scope="module")
def layout(tmp_path_factory):
    """{(struct, member): (offset, element bytes)} and {struct: size}, from the C compiler."""
    d = tmp_path_factory.mktemp("layout")
    lines = ['#include <stddef.h>', '#include <stdio.h>', '#include "scene_format.h"', "int main(void) {"]
    for struct, members in STRUCTS.items():
        lines.append(f'printf("S {struct} %zu\\n", sizeof({struct}));')
        for ctype, name, dims, _ in members:
            elem = f"(({struct} *)0)->{name}" + "[0]" * len(dims)
            lines.append(f'printf("F {struct} {name} %zu %zu\\n", offsetof({struct}, {name}), sizeof({elem}));')
    lines.append("return 0; }")
    (d / "layout.c").write_text("\n".join(lines) + "\n")
    subprocess.run(["cc", "-I", str(ROOT / "firmware"), "-o", str(d / "layout"), str(d / "layout.c")], check=True)
    out = subprocess.run([str(d / "layout")], check=True, capture_output=True, text=True).stdout
    fields, sizes = {}, {}
    for line in out.splitlines():
        p = line.split()
        if p[0] == "S":
            sizes[p[1]] = int(p[2])
        else:
            fields[(p[1], p[2])] = (int(p[3]), int(p[4]))
    return fields, sizes


@pytest.fixture(scope="module")
def blob(tmp_path_factory):
    """A scene with records in every section: Freedoom's MAP01, textured, with its things as objects."""
    out = tmp_path_factory.mktemp("bsc") / "map01.bsc"
    run([program("bspc"), "freedoom2.wad:MAP01", "-o", out])
    data = out.read_bytes()
    for name, _ in SECTIONS:
        assert section(data, name)[1] > 0, f"the test scene has no {name}"
    return data


def section(data, name):
    """(offset, count) of section name."""
    i = SECTION_NO[name]
    return int.from_bytes(data[44 + 8 * i:48 + 8 * i], "little"), int.from_bytes(data[48 + 8 * i:52 + 8 * i], "little")


class Scene:
    """Reads and patches fields of a blob by the compiler's layout."""

    def __init__(self, data, layout):
        self.data, (self.fields, self.sizes) = bytearray(data), layout

    def where(self, struct, sec, rec, name, k=None):
        off, size = self.fields[(struct, name)]
        base = 0 if sec is None else section(self.data, sec)[0] + self.sizes[struct] * rec
        return base + off + (k or 0) * size, size

    def get(self, struct, sec, rec, name, k=None):
        at, size = self.where(struct, sec, rec, name, k)
        return int.from_bytes(self.data[at:at + size], "little")

    def put(self, struct, sec, rec, name, value, k=None):
        at, size = self.where(struct, sec, rec, name, k)
        assert 0 <= value < 1 << (8 * size), (name, value)
        self.data[at:at + size] = value.to_bytes(size, "little")
        total = int.from_bytes(self.data[8:12], "little")
        self.data[12:16] = (zlib.crc32(bytes(self.data[16:total])) & 0xFFFFFFFF).to_bytes(4, "little")

    def record(self, struct, sec, rec):
        return {name: self.get(struct, sec, rec, name) for _, name, dims, _ in STRUCTS[struct] if not dims}


def out_of_range(bound, bits, none=None, far=True):
    """Values of a bits-wide field outside [0, bound) (and not none): one past, far past, huge."""
    top = 1 << bits
    vals = [bound] + ([bound + 1000, top >> 1, top - 2, top - 1] if far else [])
    return sorted({v for v in vals if bound <= v < top and v != none})


def damages(scene, struct, name, k, ann, sec, rec, far):
    """[(value, field patched)] that put field name (element k) of record rec out of range."""
    bits = 8 * scene.where(struct, sec, rec, name, k)[1]
    count = lambda s: section(scene.data, s)[1]  # noqa: E731
    r = scene.record(struct, sec, rec)
    if ann == "child":
        nodes, leaves, leaf = count("NODES"), count("LEAVES"), DEFINES["SCN_LEAF_BIT"]
        vals = [nodes] + ([nodes + 1000, leaf - 1, leaf | leaves, leaf | (leaves + 1000), 0xFFFFFFFF] if far
                          else [leaf | leaves])
        return [(v, name) for v in vals]
    kind, _, arg = ann.partition(": ")
    if kind == "index":
        target, _, none = arg.partition(" or ")
        bound = int(target) if target.isdigit() else count(target)
        return [(v, name) for v in out_of_range(bound, bits, DEFINES[none] if none else None, far)]
    if kind == "range":
        target, _, expr = arg.partition(", ")
        c = count(target)
        if expr:  # first only: the run's length is the expression
            span = eval(expr, {}, r)
            return [(v, name) for v in out_of_range(c - span + 1, bits, far=far)]
        first, num = [m[1] for m in STRUCTS[struct] if re.search(rf"\[range: {target}\]", m[3])]
        f, n = r[first], r[num]
        if name == num:  # the second field of the line is the count
            return [(v, num) for v in out_of_range(min(c - f + 1, (1 << bits) - 1), bits, far=far)]
        return [(v, first) for v in out_of_range(c - n + 1, bits, far=far)]
    if kind.startswith("count of "):
        first = kind[len("count of "):]
        fcomment = next(m[3] for m in STRUCTS[struct] if m[1] == first)
        target = re.search(r"\[range: (\w+)", fcomment).group(1)
        c = count(target)
        return [(v, name) for v in out_of_range(min(c - r[first] + 1, (1 << bits) - 1), bits, far=far)]
    raise AssertionError(f"unknown annotation [{ann}]")


def render_refuses(tmp_path, data, *needles):
    bad = tmp_path / "bad.bsc"
    bad.write_bytes(bytes(data))
    out = tmp_path / "out.png"
    proc = run([program("render"), bad, "-o", out], check=False)
    err = proc.stderr
    assert "Sanitizer" not in err and "runtime error" not in err, err
    assert proc.returncode == 1 and err.count("\n") == 1, (proc.returncode, err)
    for needle in ("compiled scene rejected", *needles):
        assert needle in err, (needle, err)
    assert not out.exists() and proc.stdout == "", "rendered"
    return err


@pytest.mark.parametrize("field", FIELDS, ids=[field_id(f) for f in FIELDS])
def test_index_out_of_range_is_refused(blob, layout, tmp_path, field):
    struct, name, k, ann = field
    secs = [None] if struct == "scn_header" else record_sections(struct)
    tried = 0
    for sec in secs:
        n = 1 if sec is None else section(blob, sec)[1]
        for rec, far in sorted({(0, True), (n - 1, n == 1)}):
            for value, patched in damages(Scene(blob, layout), struct, name, k, ann, sec, rec, far):
                scene = Scene(blob, layout)
                scene.put(struct, sec, rec, patched, value, k)
                if sec is None:
                    needles = [f"header: {patched}", "out of range"]
                else:
                    needles = [f"record {rec}:", "index out of range"]
                render_refuses(tmp_path, scene.data, *needles)
                tried += 1
    if not tried:  # an index no value of its type can put out of range (a byte into the 256 colours)
        bits = 8 * layout[0][(struct, name)][1]
        target = ann.partition(": ")[2]
        assert ann.startswith("index: ") and section(blob, target)[1] >= 1 << bits, field


def findex_damage(scene, rec):
    """A face index of model rec (its last face's last) equal to the model's vertex count."""
    m = scene.record("scn_model", "MODELS", rec)
    face = m["first_face"] + m["num_faces"] - 1
    f = scene.record("scn_face", "FACES", face)
    return f["first_index"] + f["num_index"] - 1, m["num_verts"], f"models record {rec}:"


# sections of bare indices (uint32_t[]): their annotation's meaning
SECTION_ELEMENTS = {"FINDEX": findex_damage}


@pytest.mark.parametrize("name", [n for n, c in SECTIONS if ANNOTATION.search(c)])
def test_section_of_indices_out_of_range_is_refused(blob, layout, tmp_path, name):
    owners = section(blob, "MODELS")[1]
    for rec in (0, owners - 1):
        scene = Scene(blob, layout)
        i, bound, needle = SECTION_ELEMENTS[name](scene, rec)
        off = section(scene.data, name)[0] + 4 * i
        for value in out_of_range(bound, 32, far=rec == 0):
            data = bytearray(scene.data)
            data[off:off + 4] = value.to_bytes(4, "little")
            total = int.from_bytes(data[8:12], "little")
            data[12:16] = (zlib.crc32(bytes(data[16:total])) & 0xFFFFFFFF).to_bytes(4, "little")
            render_refuses(tmp_path, data, needle, "index out of range")


def test_the_undamaged_scene_renders(blob, layout, tmp_path):
    """The damage is all that is wrong: the same blob, patched with its own values, renders."""
    scene = Scene(blob, layout)
    scene.put("scn_line", "LINES", 0, "v2", scene.get("scn_line", "LINES", 0, "v2"))
    good = tmp_path / "good.bsc"
    good.write_bytes(bytes(scene.data))
    run([program("render"), good, "-o", tmp_path / "f.png"])
    assert (tmp_path / "f.png").exists()
