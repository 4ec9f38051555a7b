"""The stiff and extreme scenes of tests/scenes/extreme/: every view of every manifest, in both
render modes, against the reference renderer (tools/refrender.py).

Each NAME.json names a text scene and its views (see test_manifests_are_well_formed for the keys).
A view passes when the sanitized build/render exits cleanly (UBSan halts on the first error, so a
report is a non-zero exit), leaves no pixel empty where the reference sees a surface, writes each
pixel exactly once in mode spans when the reference sees a surface everywhere, and stays within
the view's bounds on the share of differing pixels and on edge displacement (tools/accuracy.py).
Bounds looser than the strict ones carry their reason in the manifest, so a loosened bound is
always an explained one.
"""
import json
import re
import sys

import numpy as np
import pytest

from conftest import RENDER_MODES, ROOT, program, render, run

sys.path.insert(0, str(ROOT / "tools"))
import accuracy  # noqa: E402
import refrender  # noqa: E402

EXTREME = ROOT / "tests" / "scenes" / "extreme"
MANIFESTS = sorted(EXTREME.glob("*.json"))
STRICT_DIFFER, STRICT_EDGE = 0.005, 1
KEYS = {"scene", "about", "doom_failure", "views"}
VIEW_KEYS = {"name", "at", "angle", "look", "max_differ", "max_edge", "why"}
NUMBER = r"-?(\d+(\.\d*)?|\.\d+)"
AT_RE = re.compile(rf"^{NUMBER},{NUMBER}(,{NUMBER})?$")
ANGLE_RE = re.compile(rf"^{NUMBER}$")


def _views():
    """One param per (scene, view). A manifest that does not parse gives no views here:
    test_manifests_are_well_formed reports it, so collection itself never breaks."""
    out = []
    for path in MANIFESTS:
        try:
            m = json.loads(path.read_text())
            views = list(m["views"])
            names = [v["name"] for v in views]
        except (ValueError, KeyError, TypeError):
            continue
        for v, name in zip(views, names):
            out.append(pytest.param(path, m, v, id=f"{path.stem}/{name}"))
    return out


def _problems(path):
    """What is wrong with one manifest, as a list of sentences (empty when it is well formed)."""
    try:
        m = json.loads(path.read_text())
    except ValueError as e:
        return [f"not JSON: {e}"]
    if not isinstance(m, dict):
        return ["not a JSON object"]
    bad = []
    if set(m) != KEYS:
        bad.append(f"keys {sorted(m)}, expected {sorted(KEYS)}")
    scene = m.get("scene")
    if not isinstance(scene, str) or not (EXTREME / scene).is_file():
        bad.append(f"scene {scene!r} is not a file next to the manifest")
    if not isinstance(m.get("about"), str) or not m.get("about", "").strip():
        bad.append("about is empty")
    doom = m.get("doom_failure")
    if doom is not None and (not isinstance(doom, str) or not doom.strip()):
        bad.append(f"doom_failure {doom!r} is neither null nor a name")
    views = m.get("views")
    if not isinstance(views, list) or not views:
        return bad + ["views is not a non-empty list"]
    seen = set()
    for i, v in enumerate(views):
        where = f"view {i} ({v.get('name') if isinstance(v, dict) else v!r})"
        if not isinstance(v, dict):
            bad.append(f"{where}: not an object")
            continue
        if set(v) != VIEW_KEYS:
            bad.append(f"{where}: keys {sorted(v)}, expected {sorted(VIEW_KEYS)}")
            continue
        if not isinstance(v["name"], str) or not v["name"] or v["name"] in seen:
            bad.append(f"{where}: name missing or used twice")
        seen.add(v["name"])
        if not isinstance(v["at"], str) or not AT_RE.match(v["at"]):
            bad.append(f"{where}: at {v['at']!r} is not 'X,Y' or 'X,Y,Z'")
        if not isinstance(v["angle"], str) or not ANGLE_RE.match(v["angle"]):
            bad.append(f"{where}: angle {v['angle']!r} is not a number in a string")
        if not isinstance(v["look"], int) or isinstance(v["look"], bool) or abs(v["look"]) > 100:
            bad.append(f"{where}: look {v['look']!r} is not an integer in -100..100")
        md, me = v["max_differ"], v["max_edge"]
        if not isinstance(md, (int, float)) or isinstance(md, bool) or not 0 <= md <= 1:
            bad.append(f"{where}: max_differ {md!r} is not a share 0..1")
            continue
        if not isinstance(me, int) or isinstance(me, bool) or not 0 <= me <= 320:
            bad.append(f"{where}: max_edge {me!r} is not an integer 0..320")
            continue
        loosened = md > STRICT_DIFFER or me > STRICT_EDGE
        if not isinstance(v["why"], str):
            bad.append(f"{where}: why is not text")
        elif loosened and not v["why"].strip():
            bad.append(f"{where}: bounds {md} / {me} are looser than {STRICT_DIFFER} / "
                       f"{STRICT_EDGE} but why is empty")
    return bad


def test_manifests_are_well_formed(tmp_path):
    assert MANIFESTS, f"no manifest in {EXTREME}"
    problems = [f"{p.name}: {s}" for p in MANIFESTS for s in _problems(p)]
    assert not problems, "\n".join(problems)
    # every scene is a closed, valid map
    for p in MANIFESTS:
        scene = EXTREME / json.loads(p.read_text())["scene"]
        run([program("bspc"), scene, "-o", tmp_path / "out.bsc"])


def _c_ids(scene, view, mode, tmp_path):
    out = tmp_path / f"{mode}.ids"
    extra = ["--mode", mode, "--ids", out]
    if view["look"]:
        extra += ["--look", str(view["look"])]
    j = render(scene, *extra, at=view["at"], angle=view["angle"])
    return j, np.frombuffer(out.read_bytes(), dtype="<u4").reshape(200, 320)


@pytest.mark.parametrize("manifest,m,view", _views())
def test_extreme_view(manifest, m, view, tmp_path):
    scene = str(EXTREME / m["scene"])
    label = f"{m['scene']} view {view['name']} (--at {view['at']} --angle {view['angle']}" + \
        (f" --look {view['look']})" if view["look"] else ")")
    runs = {mode: _c_ids(scene, view, mode, tmp_path) for mode in RENDER_MODES}
    cams = {mode: j["camera"] for mode, (j, _) in runs.items()}
    assert all(c == cams["spans"] for c in cams.values()), f"{label}: the modes used different cameras: {cams}"
    x, y = (float(c) for c in view["at"].split(",")[:2])
    z = float(cams["spans"]["z"])  # the eye height the C renderer used (its floor + 41 by default)
    ref = refrender.render_ids(scene, x, y, z, float(view["angle"]), view["look"])
    ref_surface = (ref >> 24) != 0
    ref_none = int(np.count_nonzero(~ref_surface))

    failures = []
    for mode, (j, ids) in runs.items():
        tag = f"{label} mode {mode}"
        holes = int(np.count_nonzero(((ids >> 24) == 0) & ref_surface))
        if holes:
            rows, cols = np.nonzero(((ids >> 24) == 0) & ref_surface)
            failures.append(f"{tag}: {holes} empty pixels where the reference has a surface "
                            f"(rows {rows.min()}..{rows.max()}, columns {cols.min()}..{cols.max()})")
        if mode != "painter" and ref_none == 0 and (j["overdraw"] != 1.0 or j["pixels_written"] != 64000):
            failures.append(f"{tag}: overdraw {j['overdraw']}, pixels_written {j['pixels_written']} "
                            f"(expected 1.0 and 64000)")
        share = accuracy.differ(ref, ids)
        edge = accuracy.edge_displacement(ref, ids)
        if share > view["max_differ"] or edge > view["max_edge"]:
            failures.append(f"{tag}: differ {share:.5f} ({int(np.count_nonzero(ref != ids))} px, "
                            f"bound {view['max_differ']}), edge displacement {edge} px "
                            f"(bound {view['max_edge']}); reference empty pixels {ref_none}")
    assert not failures, "\n".join(failures)

