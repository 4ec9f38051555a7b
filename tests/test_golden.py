"""Golden frames: the CRC-32 of views recorded in tests/golden/frames.json after their PNGs were
looked at. Any change to what the renderer draws shows up here; re-record only after looking."""
import json

import pytest

from conftest import ROOT, render

GOLDEN = json.loads((ROOT / "tests/golden/frames.json").read_text())["frames"]


@pytest.mark.parametrize("view", GOLDEN, ids=[f"{v['scene'].split('/')[-1]}@{v['at']},{v['angle']}" for v in GOLDEN])
@pytest.mark.parametrize("mode,present", [("direct", "flip"), ("direct", "copy16"), ("spans", "flip"),
                                          ("spans", "copy32"), ("painter", "copy8"), ("columns", "flip"),
                                          ("columns", "copy32")])
def test_golden_frame(view, mode, present):
    scene = view["scene"] if ".wad:" in view["scene"] else str(ROOT / view["scene"])
    j = render(scene, "--mode", mode, "--present", present, at=view["at"], angle=view["angle"])
    assert j["crc32"] == view.get(f"{mode}_crc32", view["crc32"])
    assert j["overdraw"] == (view["painter_overdraw"] if mode == "painter" else 1.0)
