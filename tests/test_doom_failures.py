"""The known failures of the Doom renderer, each shown not to happen here.

Doom's renderer drew from fixed-point wall scales, 32-bit angles looked up in coarse tables and BSP
split points rounded to whole map units; each of these shows as an artefact the id buffers would
reveal. Every test here renders a sweep of nearby cameras with the sanitized build/render (UBSan
halts on the first error, so undefined behaviour fails the run) and compares each frame with the
reference renderer (tools/refrender.py, double-precision ray casting of the source map, no BSP
tree), measuring what the artefact would disturb. The scenes are those of tests/scenes/extreme/.
"""
import sys

import numpy as np
import pytest

from conftest import RENDER_MODES, ROOT, render

sys.path.insert(0, str(ROOT / "tools"))
import refrender  # noqa: E402

EXTREME = ROOT / "tests" / "scenes" / "extreme"
KIND_WALL, KIND_FLOOR = 1, 2


def wall_id(line, side):
    return KIND_WALL << 24 | (line * 2 + side)


def c_frame(scene, at, angle, tmp_path, mode="spans", look=0):
    """The C ids of one view and the eye height the renderer chose. at and angle are decimal
    strings, rounded to 16.16 alike by both renderers."""
    out = tmp_path / "frame.ids"
    extra = ["--mode", mode, "--ids", out] + (["--look", str(look)] if look else [])
    j = render(str(scene), *extra, at=at, angle=angle)
    return np.frombuffer(out.read_bytes(), dtype="<u4").reshape(200, 320), j["camera"]["z"]


def ref_frame(scene, at, angle, z, look=0):
    x, y = at.split(",")[:2]
    return refrender.render_ids(str(scene), x, y, z, angle, look)


def frame(scene, at, angle, tmp_path, mode="spans", look=0):
    """(C ids, reference ids) of one view; the reference uses the eye height the C renderer chose."""
    ids, z = c_frame(scene, at, angle, tmp_path, mode, look)
    return ids, ref_frame(scene, at, angle, z, look)


def dec(v):
    """A float that is an exact binary fraction, as the shortest decimal string."""
    return repr(float(v))


def edge_rows(ids, target):
    """Per column, the first and last row showing `target` (-1 where the column has none)."""
    hit = ids == target
    seen = hit.any(axis=0)
    top = np.where(seen, hit.argmax(axis=0), -1)
    bottom = np.where(seen, 199 - hit[::-1].argmax(axis=0), -1)
    return top, bottom


def edge_errors(ids, ref, target):
    """Largest row distance of `target`'s top and bottom edges from the reference's over the columns
    where both show it, and the columns where only one shows it with more than a 1-pixel sliver."""
    tc, bc = edge_rows(ids, target)
    tr, br = edge_rows(ref, target)
    both = (tc >= 0) & (tr >= 0)
    worst = int(max(np.abs(tc - tr)[both].max(initial=0), np.abs(bc - br)[both].max(initial=0)))
    tall_c = (tc >= 0) & (bc - tc >= 1)
    tall_r = (tr >= 0) & (br - tr >= 1)
    lone = np.nonzero((tall_c & (tr < 0)) | (tall_r & (tc < 0)))[0]
    return worst, lone, (tc, bc, tr, br)


def near_edge(ref):
    """True where one of the 8 neighbours in the reference has another id."""
    pad = np.pad(ref, 1, mode="edge")
    out = np.zeros(ref.shape, bool)
    for dy in (0, 1, 2):
        for dx in (0, 1, 2):
            out |= pad[dy:dy + 200, dx:dx + 320] != ref
    return out


# ---- long wall error ----------------------------------------------------------------------------

def _long_wall_sweep(cameras, tmp_path):
    """Render the long wall from each (at, angle) in turn; along the sweep every column's top edge
    must only move down and its bottom edge only up (the wall recedes), as they do in the reference,
    by no more per frame than the reference's move plus one pixel, and stay within a pixel of it."""
    scene = EXTREME / "long_wall.scene"
    target = wall_id(0, 0)
    prev = None
    for at, angle in cameras:
        ids, ref = frame(scene, at, angle, tmp_path)
        worst, lone, (tc, bc, tr, br) = edge_errors(ids, ref, target)
        where = f"long_wall.scene --at {at} --angle {angle}"
        assert int(np.count_nonzero(tr >= 0)) > 100, f"{where}: the wall spans too few columns"
        assert worst <= 1, f"{where}: the wall's edge is {worst} rows off the reference's"
        assert lone.size == 0, f"{where}: the wall is in only one of C/reference in columns {lone}"
        if prev is not None:
            ptc, pbc, ptr, pbr = prev
            cols = (tc >= 0) & (ptc >= 0) & (tr >= 0) & (ptr >= 0)
            assert not np.any(((tr < ptr) | (br > pbr)) & cols), f"{where}: reference not monotone"
            back = np.nonzero(((tc < ptc) | (bc > pbc)) & cols)[0]
            assert back.size == 0, f"{where}: the wall's edge moved back in columns {back}"
            jump = np.maximum((tc - ptc) - (tr - ptr), (pbc - bc) - (pbr - br))
            assert jump[cols].max(initial=0) <= 1, \
                f"{where}: the wall's edge jumped {jump[cols].max()} rows more than the reference's"
        prev = (tc, bc, tr, br)


def test_long_wall_error_moving_away(tmp_path):
    """Long wall error. Doom computed a wall's scale (its projected height) at its two ends from
    angles looked up in coarse tables, and stepped it linearly across the columns with a
    fixed-point increment; on a long wall seen at a grazing angle the coarse angles and the
    increment's rounding, multiplied by hundreds of columns, made the top and bottom edges wobble
    and jump as the player moved.
    Here the 30,000-unit single-seg wall of long_wall.scene is seen 2 degrees off its line while the
    eye steps away from it 1/16 unit at a time, from 1 to 4 units off: in each frame the top and
    bottom edge rows of every column are within one row of the reference's, and from frame to frame
    they only move as the receding wall does (monotonically, never a row more than the reference)."""
    _long_wall_sweep([(f"-14990,{dec(1 + k / 16)}", "-2") for k in range(48)], tmp_path)


def test_long_wall_error_turning(tmp_path):
    """Long wall error, turning: the eye 1 unit off the long wall turns from 2 to 1.5 degrees off its
    line in steps of 0.01 degree, so every column's ray meets the wall ever farther away. The same
    checks: within one row of the reference in each frame, and monotone, smooth edges along the
    sweep (Doom's angle tables of 8,192 fine angles make such a turn move the edges in jerks)."""
    _long_wall_sweep([("-14990,1", f"{-2 + k / 100:.2f}") for k in range(51)], tmp_path)


# ---- wall wiggle ---------------------------------------------------------------------------------

LEDGE_LOW_SIDE = wall_id(0, 1)   # ledge.scene: the diagonal step seen from the low floor


def _ledge_eye(off, along, z):
    """A point `off` units from ledge.scene's diagonal step line (on the low side), `along` units
    along it from (256, 256), at height z; the line runs (64,0) -> (448,512), direction (3,4)/5."""
    x = 256 - 0.8 * off + 0.6 * along
    y = 256 + 0.6 * off + 0.8 * along
    return f"{x:.6f},{y:.6f},{z}"


def dilate(mask):
    """mask grown by one pixel in all 8 directions."""
    pad = np.pad(mask, 1)
    out = np.zeros(mask.shape, bool)
    for dy in (0, 1, 2):
        for dx in (0, 1, 2):
            out |= pad[dy:dy + 200, dx:dx + 320]
    return out


def _ledge_sweep(cameras, tmp_path):
    """Every pixel showing the step in either frame is within one pixel (8-neighbour) of a pixel
    showing it in the other: a distance that holds for the steep and the shallow parts of its
    edges alike, where a row or column count would overstate a near-vertical edge's error."""
    scene = EXTREME / "ledge.scene"
    widest = 0
    for at, angle in cameras:
        ids, ref = frame(scene, at, angle, tmp_path)
        where = f"ledge.scene --at {at} --angle {angle}"
        c_step, r_step = ids == LEDGE_LOW_SIDE, ref == LEDGE_LOW_SIDE
        assert r_step.any(), f"{where}: the step is out of sight"
        widest = max(widest, int(np.count_nonzero(r_step.any(axis=0))))
        stray = (c_step & ~dilate(r_step)) | (r_step & ~dilate(c_step))
        if stray.any():
            ys, xs = np.nonzero(stray)
            raise AssertionError(f"{where}: {ys.size} pixels of the step are more than one pixel "
                                 f"from the reference's step, e.g. row {ys[0]} column {xs[0]}")
        holes = int(np.count_nonzero(((ids >> 24) == 0) & ((ref >> 24) != 0)))
        assert holes == 0, f"{where}: {holes} empty pixels"
    assert widest >= 100, f"the step spans at most {widest} columns over the sweep"


def test_wall_wiggle_approaching_a_ledge(tmp_path):
    """Wall wiggle. Doom projected a wall's ends with angles from a coarse arctangent table and its
    scale with limited precision, so a wall passing close to the eye, whose ends project far off
    screen and whose depth changes fastest across the columns, visibly wiggled as the player moved
    by fractions of a unit. Here the eye, 1 unit above the top of ledge.scene's diagonal 24-unit
    step (a two-sided line; its lower wall seen from the low floor), walks straight at the step's
    line from 1 unit off to 1/64 unit in steps of 1/64 unit, looking along the line and 5 degrees
    toward it: in every frame each pixel of the step in the C frame is within one pixel of the
    reference's step and vice versa, and no pixel is empty."""
    cams = [(_ledge_eye(1 - k / 64, 0, 25), angle) for k in range(0, 64, 2) for angle in ("53.13", "48")]
    _ledge_sweep(cams, tmp_path)


def test_wall_wiggle_passing_a_ledge(tmp_path):
    """Wall wiggle, passing: the eye 0.5 unit off the same step's line and 0.5 unit above its top
    slides along it by 1/8 unit steps over 6 units, looking 3 degrees toward it; the same checks
    in every frame."""
    _ledge_sweep([(_ledge_eye(0.5, -3 + k / 8, 24.5), "50") for k in range(49)], tmp_path)


# ---- slime trails --------------------------------------------------------------------------------

def _slime_cameras():
    """Views along the lines that cut slime_trails.scene's walls and floor polygons off the unit
    grid: the pit's east side extended (it cuts the band at (619.101, 348.315)), x = 340 (the square
    pillar's east face; it cuts the band at (340, 308.571)), y = 500 (the pit's south wall; it cuts a
    floor polygon at (478.571, 500)), and the band's 2:7 edge, each from the line and from points
    a fraction of a unit either side of it."""
    cams = []
    for d in (-0.5, -0.125, 0, 0.125, 0.5):
        # perpendicular of the pit side's direction (-70, -245) is (245, -70) / 254.8
        cams.append((f"{905 + d * 0.9615:.6f},{867.5 - d * 0.2747:.6f}", "254.0546", -60))
        cams.append((f"{340 + d},150", "90", -20))
        cams.append((f"950,{500 + d}", "180", -30))
        cams.append((f"{65 - d * 0.2747:.6f},{230 + d * 0.9615:.6f}", "15.9454", -30))
    for a in ("89.9", "90.1", "179.95", "180.05"):
        cams.append(("340,150" if a.startswith("9") else "950,500", a, -20))
    return cams


@pytest.mark.parametrize("mode", RENDER_MODES)
def test_no_slime_trails(mode, tmp_path):
    """Slime trails. Doom's node builders stored the points where a partition cut a wall rounded to
    whole map units, so the pieces of a cut wall were bent by up to half a unit and no longer met
    the floors beside them; along such cuts the renderer's clipping left gaps, and what lay behind
    (usually a far floor) smeared through as coloured trails. bspc keeps split points at 1/65536
    and both sides of every cut share one vertex. Over views looking along the cutting lines of
    slime_trails.scene (walls of slope 1:3, 2:7 and 7:2 cut off the grid), every pixel where the
    reference sees a floor shows that same floor in the C frame, unless it is within one pixel of
    an edge of the reference (where a pixel-centre decision may go either way); and no pixel is
    empty."""
    scene = EXTREME / "slime_trails.scene"
    for at, angle, look in _slime_cameras():
        ids, ref = frame(scene, at, angle, tmp_path, mode=mode, look=look)
        where = f"slime_trails.scene --at {at} --angle {angle} --look {look} --mode {mode}"
        floor = (ref >> 24) == KIND_FLOOR
        leak = floor & (ids != ref) & ~near_edge(ref)
        if leak.any():
            ys, xs = np.nonzero(leak)
            raise AssertionError(f"{where}: {ys.size} floor pixels away from any edge show another "
                                 f"surface, e.g. row {ys[0]} column {xs[0]}: "
                                 f"{int(ids[ys[0], xs[0]]):#x} instead of {int(ref[ys[0], xs[0]]):#x}")
        holes = int(np.count_nonzero(((ids >> 24) == 0) & ((ref >> 24) != 0)))
        assert holes == 0, f"{where}: {holes} empty pixels"


# ---- the eye exactly on a vertex, a partition line or a wall line -------------------------------

ANGLES8 = [str(a) for a in range(0, 360, 45)]


def _eye_points(m):
    """(x, y, angles): every vertex of the map at the 8 angles 0, 45, ..., 315; every wall's
    midpoint (on its line, off its ends) and the whole-unit points inside the map 8 units beyond
    each end of a wall along its line (on the partition line the wall gives), looking along the
    line both ways and across it both ways."""
    out = {}
    for x1, y1, x2, y2 in zip(m.x1, m.y1, m.x2, m.y2):
        out[(float(x1), float(y1))] = ANGLES8
    for x1, y1, x2, y2 in zip(m.x1, m.y1, m.x2, m.y2):
        along = float(np.degrees(np.arctan2(y2 - y1, x2 - x1)))
        angles = [f"{(along + d) % 360:.6f}" for d in (0, 90, 180, 270)]
        length = float(np.hypot(x2 - x1, y2 - y1))
        ux, uy = (x2 - x1) / length, (y2 - y1) / length
        pts = [(float(x1 + x2) / 2, float(y1 + y2) / 2)]
        for px, py in ((x1 - 8 * ux, y1 - 8 * uy), (x2 + 8 * ux, y2 + 8 * uy)):
            if px == round(px) and py == round(py) and refrender.sector_at(m, px, py) is not None:
                pts.append((float(px), float(py)))
        for p in pts:
            out.setdefault(p, angles)
    return sorted((x, y, a) for (x, y), a in out.items())


def _eye_z(m, x, y):
    """An eye height inside every sector that meets at (x, y): the highest of their floors + 41,
    or halfway up where their common height range is lower than that (None when they have none).
    The default height (the floor + 41 of one of them) could put the eye inside the solid face of
    a step: on the line of a window whose sill is higher than the eye, rays into the sill's sector
    start below its floor, where the reference draws what lies beyond the solid and the renderer,
    whose one-sided walls close their columns, draws nothing; no player can stand there."""
    cross = (m.x2 - m.x1) * (y - m.y1) - (m.y2 - m.y1) * (x - m.x1)
    along = (x - m.x1) * (m.x2 - m.x1) + (y - m.y1) * (m.y2 - m.y1)
    on = (cross == 0) & (along >= 0) & (along <= (m.x2 - m.x1) ** 2 + (m.y2 - m.y1) ** 2)
    secs = set(m.front[on].tolist()) | set(m.back[on][m.back[on] >= 0].tolist())
    if not secs:
        secs = {refrender.sector_at(m, x, y)}
    lo = max(float(m.floor[s]) for s in secs)
    hi = min(float(m.ceil[s]) for s in secs)
    if hi <= lo:
        return None
    return min(lo + 41, (lo + hi) / 2)


@pytest.mark.parametrize("name", ["slime_trails", "angles"])
def test_eye_on_vertices_and_lines(name, tmp_path):
    """The eye exactly on a vertex, a partition line or a wall line. Doom's R_PointOnSide and
    R_PointToAngle took such points to one side or the other and its clipping then met zero-length
    and zero-depth segs; ports added special cases after crashes and missing columns there. Every
    vertex of the scene at 8 angles, every wall's midpoint and the whole-unit points on the walls'
    lines 8 units beyond their ends at 4 (see _eye_points) are used as the eye, at a height inside
    every sector meeting there (_eye_z), in mode spans with the sanitized build: the run exits
    cleanly (no crash, no undefined behaviour) and no pixel is empty where the reference sees a
    surface (rays that leave the map at an eye on its outer edge, or enter a pillar from its wall,
    see nothing in both)."""
    scene = EXTREME / f"{name}.scene"
    m = refrender.load(str(scene))
    points = _eye_points(m)
    assert len(points) >= 40
    bad = []
    for x, y, angles in points:
        z = _eye_z(m, x, y)
        if z is None:
            continue
        at = f"{dec(x)},{dec(y)},{dec(z)}"
        for angle in angles:
            ids, _ = c_frame(scene, at, angle, tmp_path)
            empty = (ids >> 24) == 0
            if not empty.any():
                continue     # nothing empty, no hole: the reference is not needed
            ref = ref_frame(scene, at, angle, z)
            hole = empty & ((ref >> 24) != 0)
            if hole.any():
                cols = np.nonzero(hole.any(axis=0))[0]
                bad.append(f"--at {at} --angle {angle}: {int(hole.sum())} empty pixels in columns "
                           f"{cols.min()}..{cols.max()}")
    assert not bad, f"{name}.scene:\n" + "\n".join(bad)
