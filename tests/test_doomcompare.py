"""tools/doomcompare.py (make compare-doom): the standing-still demo, the 8x8 block figure, and
a run of Chocolate Doom beside build/render on freedoom2 MAP01's player start."""
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


# ---- the figure -----------------------------------------------------------------------------

def noise(seed):
    return np.random.default_rng(seed).integers(0, 200, (H, W, 3), dtype=np.uint8)


def test_identical_frames_agree_everywhere():
    a = noise(1)
    r = dc.block_metric(a, a.copy(), np.zeros((H, W), np.uint32))
    assert (r["share"], r["agree"], r["blocks"], r["object_blocks"]) == (100.0, 1000, 1000, 0)


def test_colours_30_apart_agree_nowhere():
    a = noise(2)
    b = a + np.array([0, 30, 0], np.uint8)
    r = dc.block_metric(a, b, np.zeros((H, W), np.uint32))
    assert (r["share"], r["agree"]) == (0.0, 0)
    # 24 apart is still within
    assert dc.block_metric(a, a + np.uint8(24), np.zeros((H, W), np.uint32))["share"] == 100.0


def test_object_blocks_are_left_out():
    a = noise(3)
    b = a.copy()
    b[:, :160] += np.uint8(30)            # the left half differs
    ids = np.zeros((H, W), np.uint32)
    ids[:, :160] = 1 << 24                # walls there: they count
    ids[5, 3] = 4 << 24 | 7               # one object pixel: its block is left out
    ids[96:104, 200:208] = 4 << 24       # an object over an agreeing block
    ids[50, 50] = 3 << 24                 # a ceiling pixel is no object
    r = dc.block_metric(a, b, ids)
    assert r["object_blocks"] == 2
    assert r["blocks"] == 998
    assert r["agree"] == 499
    assert r["share"] == round(100 * 499 / 998, 2)


def test_weapon_blocks_are_counted_apart_not_left_out():
    a = noise(4)
    mask = np.zeros((H, W), bool)
    mask[190:200, 152:176] = True         # 2 block rows x 3 block columns
    r = dc.block_metric(a, a, np.zeros((H, W), np.uint32), info_mask=mask)
    assert (r["weapon_blocks"], r["weapon_blocks_agree"], r["blocks"]) == (6, 6, 1000)


def test_bigger_window_is_downscaled_exactly():
    a = noise(5)
    assert (dc.to_320x200(a.repeat(2, 0).repeat(2, 1)) == a).all()
    with pytest.raises(RuntimeError):
        dc.to_320x200(np.zeros((240, 320, 3), np.uint8))   # aspect-ratio corrected


def test_weapon_mask_is_the_pistol_at_the_bottom_centre():
    m = dc.weapon_mask(str(FREEDOOM2))
    ys, xs = np.nonzero(m)
    assert len(ys) > 500
    assert ys.max() == H - 1 and ys.min() > H // 2
    assert 120 < xs.mean() < 200


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
    print(f"\nfreedoom2 MAP01: {r['share']}% of 8x8 blocks within 24 of Chocolate Doom "
          f"({r['agree']}/{r['blocks']}, weapon covers {r['weapon_blocks']})")
    assert 0.0 <= r["share"] <= 100.0
    assert r["blocks"] + r["object_blocks"] == 1000
    assert r["chocolate_saved_size"] == [W, H]
    # the frame reached the BMP unscaled: every pixel is a colour of the palette as shown
    assert r["chocolate_in_palette"] == 100.0
    # the last frame came after the melt and the demo's tics
    assert r["chocolate_frames"] >= r["tics"]
    choco = np.asarray(dc.Image.open(out / "freedoom2_MAP01_chocolate.png"))
    ours = np.asarray(dc.Image.open(out / "freedoom2_MAP01_project.png"))
    assert choco.shape == ours.shape == (H, W, 3)
    side = dc.Image.open(r["png"])
    assert side.size == (2 * (2 * W + 4), 2 * H)


def test_chocolate_doom_frame_is_the_game_not_black_or_the_title(map01):
    _, out = map01
    choco = np.asarray(dc.Image.open(out / "freedoom2_MAP01_chocolate.png")).astype(int)
    assert len(np.unique(choco.reshape(-1, 3), axis=0)) >= 40
    assert choco.mean() > 10
    title = title_screen(str(FREEDOOM2))
    assert (np.abs(choco - title).max(axis=2) > 24).mean() > 0.5


@pytest.mark.parametrize("spec", ["freedoom2.wad:MAP33", "freedoom2.wad:E1M1", "freedoom2.wad",
                                  "nowhere.wad:MAP01", "freedoom2.wad:START"])
def test_bad_map_is_refused_with_a_message(spec, tmp_path, capsys):
    assert dc.main(["--render", "/nonexistent/render", "--out", str(tmp_path), spec]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"doomcompare: {spec}: ") and "Traceback" not in err
