"""tools/doomcompare.py (make compare-doom): the standing-still demo that pauses, what Chocolate
Doom is given besides (the PWAD, the DeHackEd patch), the weapon's mask, the three 8x8 block
figures (frame, things, world), and runs of Chocolate Doom: beside build/render on freedoom2
MAP01's player start, its weapon where the mask says, and its things frozen in their spawn frame."""
import struct
import sys

import numpy as np
import pytest

from conftest import ROOT, WADDIR, program

sys.path.insert(0, str(ROOT / "tools"))
import doomcompare as dc  # noqa: E402

H, W = 200, 320
FREEDOOM2 = WADDIR / "freedoom2.wad"


# ---- the demo -----------------------------------------------------------------------------

def test_demo_lump_parses_back():
    d = dc.parse_demo(dc.demo_lump(1, 1, 35))
    assert (d["version"], d["skill"], d["episode"], d["map"]) == (109, 2, 1, 1)
    assert (d["deathmatch"], d["respawn"], d["fast"], d["nomonsters"], d["consoleplayer"]) == (0,) * 5
    assert d["players"] == [1, 0, 0, 0]
    assert d["tics"] == [(0, 0, 0, 0)] * 35


def test_demo_lump_bytes():
    data = dc.demo_lump(3, 7, 2)
    assert data == bytes([109, 2, 3, 7, 0, 0, 0, 0, 0, 1, 0, 0, 0]) + bytes(8) + b"\x80"


def test_demo_lump_pauses_after_the_standing_tics():
    d = dc.parse_demo(dc.demo_lump(2, 5, 3, hold=2))
    assert (d["episode"], d["map"]) == (2, 5)
    assert d["tics"] == [(0, 0, 0, 0)] * 3 + [(0, 0, 0, 0x81)] + [(0, 0, 0, 0)] * 2
    assert dc.parse_demo(dc.demo_lump(1, 1, 1, hold=0))["tics"] == [(0, 0, 0, 0), (0, 0, 0, 0x81)]
    with pytest.raises(ValueError):
        dc.demo_lump(1, 1, 1, hold=-1)


@pytest.mark.parametrize("bad", [b"", bytes([110]) + dc.demo_lump(1, 1, 1)[1:],
                                 dc.demo_lump(1, 1, 2)[:-1], dc.demo_lump(1, 1, 2)[:-2] + b"\x80"])
def test_parse_demo_refuses_what_is_not_a_demo(bad):
    with pytest.raises(ValueError):
        dc.parse_demo(bad)


@pytest.mark.parametrize("args", [(0, 1, 1), (1, 0, 1), (1, 100, 1), (1, 1, 0)])
def test_demo_lump_refuses_bad_numbers(args):
    with pytest.raises(ValueError):
        dc.demo_lump(*args)


def test_map_numbers():
    assert dc.map_numbers("MAP01") == (1, 1)
    assert dc.map_numbers("map32") == (1, 32)
    assert dc.map_numbers("E4M9") == (4, 9)
    for bad in ("E1M", "MAPXX", "E1X1", "START"):
        with pytest.raises(ValueError):
            dc.map_numbers(bad)


# ---- what Chocolate Doom is given besides the demo ----------------------------------------------

def test_frozen_deh_makes_every_state_last_for_ever():
    text = dc.frozen_deh()
    assert text.startswith("Patch File for DeHackEd v3.0\n")
    blocks = text.split("\n\n")[1:-1]
    assert blocks == [f"Frame {i}\nDuration = -1" for i in range(967)]


def test_pwad_reads_back():
    data = dc.pwad([("ONE", b"abc"), ("S_START", b""), ("TWO", b"\x01\x02")])
    assert data[:4] == b"PWAD"
    d = dc.wad_directory(data)
    assert [n for n, _, _ in d] == ["ONE", "S_START", "TWO"]
    assert [data[pos:pos + size] for _, pos, size in d] == [b"abc", b"", b"\x01\x02"]


def test_empty_patch_draws_nothing():
    idx, mask = dc.draw_patch(dc.EMPTY_PATCH, 160, 100)
    assert not mask.any() and not idx.any()


def test_chocolate_pwad_blanks_the_things_sprites_not_the_weapons():
    wad = str(FREEDOOM2)
    sprites = dc.sprite_lumps(wad)
    assert "POSSA1" in sprites and "PISGA0" in sprites and len(sprites) > 1000

    def lumps(data):
        return {n: data[pos:pos + size] for n, pos, size in dc.wad_directory(data)}

    plain = lumps(dc.chocolate_pwad(wad))
    assert plain == {"M_PAUSE": dc.EMPTY_PATCH}
    bare = lumps(dc.chocolate_pwad(wad, things=False))
    assert bare["M_PAUSE"] == dc.EMPTY_PATCH and "S_START" in bare and "S_END" in bare
    weapons = {n for n in sprites if n[:4] in dc.WEAPON_SPRITES}
    assert "PISGA0" in weapons and "PISFA0" in weapons
    assert set(bare) - {"M_PAUSE", "S_START", "S_END"} == set(sprites) - weapons
    assert all(bare[n] == dc.EMPTY_PATCH for n in set(sprites) - weapons)
    noweapon = lumps(dc.chocolate_pwad(wad, weapon=False))
    assert set(noweapon) - {"M_PAUSE", "S_START", "S_END"} == weapons


def test_still_sectors_takes_the_light_specials_off():
    specials = [0, 1, 2, 3, 4, 5, 7, 8, 9, 12, 13, 16, 17]
    data = b"".join(struct.pack("<hh8s8shhh", 0, 128, b"FLOOR", b"CEIL", 160, sp, 3)
                    for sp in specials)
    out = dc.still_sectors(data)
    assert len(out) == len(data)
    got = [struct.unpack_from("<hh8s8shhh", out, 26 * i) for i in range(len(specials))]
    assert [g[5] for g in got] == [0, 0, 0, 0, 0, 5, 7, 0, 9, 0, 0, 16, 0]
    # everything else is kept: heights, flats, light, tag
    assert all(g[:5] + g[6:] == (0, 128, b"FLOOR\0\0\0", b"CEIL\0\0\0\0", 160, 3) for g in got)


def test_chocolate_pwad_carries_the_map_with_still_lights():
    wad = str(FREEDOOM2)
    lumps = dc.wad_directory(data := dc.chocolate_pwad(wad, mapname="MAP29"))
    assert [n for n, _, _ in lumps] == ["M_PAUSE", "MAP29", *dc.MAP_LUMPS]
    got = {n: data[pos:pos + size] for n, pos, size in lumps}
    orig = dict(dc.map_lumps(wad, "MAP29"))
    assert all(got[n] == orig[n] for n in dc.MAP_LUMPS if n != "SECTORS")
    assert got["SECTORS"] == dc.still_sectors(orig["SECTORS"])
    with pytest.raises(KeyError):
        dc.map_lumps(wad, "E1M1")


# ---- Doom's weapon ------------------------------------------------------------------------------

def test_weapon_place():
    # frozen states: A_Raise ran once at set-up, S_PISTOLUP lasts for ever
    assert [dc.weapon_place(t) for t in (1, 20, 100)] == [(0, 122)] * 3
    # running states: 6 pixels a tic, ready (sx 1, WEAPONTOP) from tic 15 on
    assert dc.weapon_place(1, frozen=False) == (0, 116)
    assert dc.weapon_place(14, frozen=False) == (0, 38)
    assert dc.weapon_place(15, frozen=False) == dc.weapon_place(40, frozen=False) == (1, 32)


def test_weapon_mask_is_the_pistol_at_the_bottom_centre():
    m = dc.weapon_mask(str(FREEDOOM2), 20, frozen=False)
    ys, xs = np.nonzero(m)
    assert len(ys) > 500
    assert ys.max() == H - 1 and ys.min() > H // 2
    assert 120 < xs.mean() < 200
    # the whole pistol is 2,131 pixels: the mask is the sprite's opaque pixels, not its box
    assert m.sum() == 2131 < (xs.max() - xs.min() + 1) * (ys.max() - ys.min() + 1)


def test_weapon_mask_is_empty_while_the_pistol_is_below_the_screen():
    wad = str(FREEDOOM2)
    assert not dc.weapon_mask(wad).any()                       # the default: frozen, tic 1
    assert not dc.weapon_mask(wad, 4, frozen=False).any()
    rising = dc.weapon_mask(wad, 5, frozen=False)             # sy 92: its top rows show
    assert 0 < rising.sum() < 100 and np.nonzero(rising)[0].min() >= H - 8


# ---- the figures ------------------------------------------------------------------------------

def noise(seed):
    return np.random.default_rng(seed).integers(0, 200, (H, W, 3), dtype=np.uint8)


NO_IDS = np.zeros((H, W), np.uint32)


def test_identical_frames_agree_everywhere():
    a = noise(1)
    r = dc.block_metric(a, a.copy(), NO_IDS)
    assert r["frame"] == r["world"] == {"share": 100.0, "agree": 1000, "blocks": 1000}
    assert r["things"] == {"share": None, "agree": 0, "blocks": 0}
    assert (r["our_thing_blocks"], r["doom_thing_blocks"], r["weapon_pixels"]) == (0, 0, 0)


def test_colours_30_apart_agree_nowhere():
    a = noise(2)
    b = a + np.array([0, 30, 0], np.uint8)
    r = dc.block_metric(a, b, NO_IDS)
    assert r["frame"] == {"share": 0.0, "agree": 0, "blocks": 1000}
    # 24 apart is still within
    assert dc.block_metric(a, a + np.uint8(24), NO_IDS)["frame"]["share"] == 100.0


def test_thing_blocks_are_ours_and_dooms():
    a = noise(3)
    b = a.copy()
    b[:, :160] += np.uint8(30)            # the left half differs: 500 blocks
    ids = np.zeros((H, W), np.uint32)
    ids[:, :160] = 1 << 24                # walls there: no things
    ids[5, 3] = 4 << 24 | 7               # one object pixel: block (0, 0), differing
    ids[96:104, 200:208] = 4 << 24       # an object over an agreeing block: (12, 25)
    ids[50, 50] = 3 << 24                 # a ceiling pixel is no object
    ids[120, 300] = 4 << 24               # ours and Doom's: block (15, 37), agreeing
    doom = np.zeros((H, W), bool)
    doom[120, 301] = True
    doom[60:70, 100] = True               # Doom's alone, over 2 differing blocks: (7, 12), (8, 12)
    doom[199, 319] = True                 # Doom's alone, agreeing: (24, 39)
    r = dc.block_metric(a, b, ids, ref_things=doom)
    assert r["frame"] == {"share": 50.0, "agree": 500, "blocks": 1000}
    assert (r["our_thing_blocks"], r["doom_thing_blocks"]) == (3, 4)
    assert r["things"] == {"share": 50.0, "agree": 3, "blocks": 6}
    assert r["world"] == {"share": round(100 * 497 / 994, 2), "agree": 497, "blocks": 994}
    # without Doom's things only ours count
    r = dc.block_metric(a, b, ids)
    assert r["things"] == {"share": round(100 * 2 / 3, 2), "agree": 2, "blocks": 3}


def test_weapon_pixels_are_left_out_of_the_block_means():
    a = noise(4)
    b = a.copy()
    weapon = np.zeros((H, W), bool)
    weapon[192:200, 160:168] = True       # covers block (24, 20) wholly: left out
    weapon[188:192, 168:176] = True       # half of block (23, 21), whose other half agrees
    b[188:192, 168:176] = 255 - a[188:192, 168:176]
    b[192:200, 160:168] = 255 - a[192:200, 160:168]
    ids = np.zeros((H, W), np.uint32)
    ids[195, 163] = 4 << 24               # an object under the weapon is not a thing block
    r = dc.block_metric(a, b, ids, weapon=weapon)
    assert r["frame"] == {"share": 100.0, "agree": 999, "blocks": 999}
    assert (r["weapon_pixels"], r["weapon_blocks"], r["weapon_blocks_left_out"]) == (96, 2, 1)
    assert r["our_thing_blocks"] == 0 and r["things"]["blocks"] == 0
    # without the mask both blocks differ
    r = dc.block_metric(a, b, ids)
    assert r["frame"] == {"share": 99.8, "agree": 998, "blocks": 1000}
    assert r["our_thing_blocks"] == 1


def test_summary_of_several_starts():
    def res(name, frame, things):
        return {"map": name, "frame": {"share": frame}, "world": {"share": frame},
                "things": {"share": things}}
    lines = dc.summary([res("a", 99.0, None), res("b", 96.5, 90.0), res("c", 98.0, 80.0)])
    assert lines[0] == "frame: 3 starts, lowest 96.5% (b), median 98.0%, 2 of 3 at least 97%"
    assert lines[1] == "things: 2 starts, lowest 80.0% (c), median 85.0%, 1 of 2 at least 85%"
    assert lines[2] == "world: 3 starts, lowest 96.5% (b), median 98.0%"


def test_all_starts_are_the_measured_freedoom_maps():
    assert len(dc.ALL_STARTS) == len(set(dc.ALL_STARTS)) == 43
    assert dc.ALL_STARTS[:2] == ("freedoom2.wad:MAP01", "freedoom2.wad:MAP02")
    assert "freedoom1.wad:E1M1" in dc.ALL_STARTS and "freedoom1.wad:E4M9" in dc.ALL_STARTS
    for wadname in ("freedoom1.wad", "freedoom2.wad"):
        names = {n for n, _, _ in dc.wad_directory((WADDIR / wadname).read_bytes())}
        maps = [s.split(":")[1] for s in dc.ALL_STARTS if s.startswith(wadname)]
        assert maps and set(maps) <= names


def test_bigger_window_is_downscaled_exactly():
    a = noise(5)
    assert (dc.to_320x200(a.repeat(2, 0).repeat(2, 1)) == a).all()
    with pytest.raises(RuntimeError):
        dc.to_320x200(np.zeros((240, 320, 3), np.uint8))   # aspect-ratio corrected


# ---- Chocolate Doom beside build/render -------------------------------------------------------

@pytest.fixture(scope="module")
def map01(tmp_path_factory):
    try:
        dc.find_chocolate()
    except FileNotFoundError:
        pytest.fail("chocolate-doom is missing: run make deps")
    out = tmp_path_factory.mktemp("compare")
    return dc.compare("freedoom2.wad:MAP01", program("render"), out), out


def title_screen(wad):
    idx, _ = dc.draw_patch(dc.wad_lump(wad, "TITLEPIC"), 0, 0)
    return dc.chocolate_palette(dc.palette(wad))[idx]


def test_chocolate_doom_beside_the_project_on_map01(map01):
    r, out = map01
    print(f"\nfreedoom2 MAP01: {dc.line(r)}")
    assert r["frame"]["share"] is not None and 0.0 <= r["frame"]["share"] <= 100.0
    # frozen at tic 1 the pistol is below the screen: every block counts
    assert (r["frozen"], r["tics"], r["weapon_pixels"], r["frame"]["blocks"]) == (True, 1, 0, 1000)
    assert r["things"]["blocks"] + r["world"]["blocks"] == 1000
    assert r["things"]["agree"] + r["world"]["agree"] == r["frame"]["agree"]
    assert r["things"]["blocks"] <= r["our_thing_blocks"] + r["doom_thing_blocks"]
    assert r["chocolate_saved_size"] == [W, H]
    # the frame reached the BMP unscaled: every pixel is a colour of the palette as shown
    assert r["chocolate_in_palette"] == 100.0
    # the last frame came after the melt and the demo's tics (1 standing, the pause, 3 paused)
    assert r["chocolate_frames"] >= 5
    choco = np.asarray(dc.Image.open(out / "freedoom2_MAP01_chocolate.png"))
    bare = np.asarray(dc.Image.open(out / "freedoom2_MAP01_chocolate_nothings.png"))
    ours = np.asarray(dc.Image.open(out / "freedoom2_MAP01_project.png"))
    assert choco.shape == bare.shape == ours.shape == (H, W, 3)
    assert r["doom_thing_pixels"] == int((choco != bare).any(axis=2).sum())
    side = dc.Image.open(r["png"])
    assert side.size == (2 * (2 * W + 4), 2 * H)


def test_chocolate_doom_frame_is_the_game_not_black_or_the_title(map01):
    _, out = map01
    choco = np.asarray(dc.Image.open(out / "freedoom2_MAP01_chocolate.png")).astype(int)
    assert len(np.unique(choco.reshape(-1, 3), axis=0)) >= 40
    assert choco.mean() > 10
    title = title_screen(str(FREEDOOM2))
    assert (np.abs(choco - title).max(axis=2) > 24).mean() > 0.5


def test_chocolate_doom_frame_has_no_pause_picture(map01):
    _, out = map01
    choco = np.asarray(dc.Image.open(out / "freedoom2_MAP01_chocolate.png")).astype(int)
    # Doom draws PAUSE (M_PAUSE) at the top centre while paused: its red letters are not there
    wad = str(FREEDOOM2)
    idx, mask = dc.draw_patch(dc.wad_lump(wad, "M_PAUSE"), (W - 68) // 2, 4)
    pause = dc.chocolate_palette(dc.palette(wad))[idx]
    assert mask.sum() > 200
    assert (np.abs(choco - pause).max(axis=2) <= 8)[mask].mean() < 0.2


@pytest.fixture(scope="module")
def chocolate():
    try:
        return dc.find_chocolate()
    except FileNotFoundError:
        pytest.fail("chocolate-doom is missing: run make deps")


@pytest.mark.parametrize("tics,frozen", [(20, False), (1, True)])
def test_chocolate_doom_draws_its_weapon_where_the_mask_says(chocolate, tics, frozen):
    """The pixels that change when Doom's weapon sprites are empty pictures are the mask's."""
    wad = str(FREEDOOM2)
    shot, bare = [dc.chocolate_frame(wad, "MAP01", tics, frozen=frozen, weapon=w)[0]
                  for w in (True, False)]
    drawn = (shot != bare).any(axis=2)
    mask = dc.weapon_mask(wad, tics, frozen)
    assert not (drawn & ~mask).any()
    # where the pistol's colour happens to be the floor's the frames agree: a few pixels
    assert drawn.sum() >= 0.97 * mask.sum()
    assert (mask.sum() > 2000) == (not frozen)


def test_chocolate_doom_things_stay_in_their_spawn_frame(chocolate):
    """freedoom2 MAP29's start sees four animated torches and a barrel: frozen, Doom's things
    are the same at tic 1 and tic 30; running their states, they are not (the test would see a
    thaw)."""
    wad = str(FREEDOOM2)
    first, _, things, _ = dc.chocolate_frames(wad, "MAP29", 1)
    later = dc.chocolate_frame(wad, "MAP29", 30)[0]
    running = dc.chocolate_frame(wad, "MAP29", 30, frozen=False)[0]
    assert things.sum() > 5000
    assert (first[things] == later[things]).all()
    assert (first[things] != running[things]).any(axis=1).sum() > 500


def test_chocolate_doom_lights_stay_at_their_sectors_levels(chocolate):
    """freedoom1 E4M2's start sees glowing sectors (special 8), which Doom dims by 8 levels a
    tic: held, its whole frame is the same at tic 1 and tic 30; live, tic 1 already differs."""
    wad = dc.find_wad("freedoom1.wad")
    first = dc.chocolate_frame(wad, "E4M2", 1)[0]
    later = dc.chocolate_frame(wad, "E4M2", 30)[0]
    live = dc.chocolate_frame(wad, "E4M2", 1, frozen=False)[0]
    assert (first == later).all()
    assert (first != live).any(axis=2).sum() > 5000


@pytest.mark.parametrize("spec", ["freedoom2.wad:MAP33", "freedoom2.wad:E1M1", "freedoom2.wad",
                                  "nowhere.wad:MAP01", "freedoom2.wad:START"])
def test_bad_map_is_refused_with_a_message(spec, tmp_path, capsys):
    assert dc.main(["--render", "/nonexistent/render", "--out", str(tmp_path), spec]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"doomcompare: {spec}: ") and "Traceback" not in err
