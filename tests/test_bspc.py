"""build/bspc: every Freedoom map compiles with every strategy; the stats contract; clear errors."""
import json

import pytest

from conftest import ROOT, freedoom, program, run

MAPS = [f"freedoom1.wad:E{e}M{m}" for e in range(1, 5) for m in range(1, 10)] + \
       [f"freedoom2.wad:MAP{m:02d}" for m in range(1, 33)]


def stats(spec, *extra, sanitized=False):
    proc = run([program("bspc", sanitized), spec, "--stats", "-o", "/dev/null", *extra])
    assert proc.stdout.count("\n") == 1
    return json.loads(proc.stdout)


def test_68_maps():
    assert len(MAPS) == 68


@pytest.mark.parametrize("split", ["fewest", "balanced", "mixed"])
def test_all_freedoom_maps_compile(split):
    freedoom("freedoom1.wad"), freedoom("freedoom2.wad")
    for spec in MAPS:
        s = stats(spec, "--split", split)
        for key in ("input_walls", "segs", "splits", "leaves", "nodes", "max_depth", "mean_depth", "build_ms"):
            assert key in s, (spec, key)
        assert s["leaves"] == s["nodes"] + 1, spec
        assert s["segs"] >= s["input_walls"], spec
        assert 1 <= s["max_depth"] <= 255, spec


def test_sanitized_compile_of_a_large_map():
    s = stats("freedoom2.wad:MAP01", sanitized=True)
    assert s["leaves"] > 100


def test_help():
    proc = run([program("bspc"), "--help"])
    for flag in ("--split", "--stats", "-o"):
        assert flag in proc.stdout


def test_missing_lump_and_map(tmp_path):
    proc = run([program("bspc"), "freedoom2.wad:MAP99", "-o", tmp_path / "x.bsc"], check=False)
    assert proc.returncode != 0 and "MAP99" in proc.stderr
    proc = run([program("bspc"), tmp_path / "none.wad:MAP01"], check=False)
    assert proc.returncode != 0 and "none.wad" in proc.stderr
