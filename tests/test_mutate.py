"""tools/mutate.py (make mutate) end to end on one mutant: an obviously wrong CRC-32 is caught by the
golden frames, and the working tree's source is left as it was (the mutant lives in a scratch copy)."""
import json
import subprocess
import sys

from conftest import ROOT


def test_mutate_kills_a_broken_crc_and_leaves_the_tree_alone(tmp_path):
    src = ROOT / "firmware/crc32.c"
    before = (src.read_bytes(), src.stat().st_mtime_ns)
    # the c rules' "comment the statement out" mutant of the line that mixes each byte in
    proc = subprocess.run([sys.executable, str(ROOT / "tools/mutate.py"), "--files", "firmware/crc32.c",
                           "--match", r"^\s*/\*crc \^= \*p\+\+;\*/", "--tests", "golden", "--sample", "1",
                           "--out", str(tmp_path), "--no-doc"], cwd=ROOT, capture_output=True, text=True,
                          timeout=900)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    out = json.loads((tmp_path / "results.json").read_text())
    assert [(r["status"], r["by"], r["mutant"].strip()) for r in out["results"]] == \
        [("killed", "golden", "/*crc ^= *p++;*/")]
    assert out["score"] == 1.0
    assert out["score_excluding_equivalents"] == 1.0
    assert "firmware/crc32.c | 1 | 1 | 0 | 0 | 0" in (tmp_path / "report.md").read_text()
    assert (src.read_bytes(), src.stat().st_mtime_ns) == before
    # the scratch copy holds the original again once the mutant has run
    assert (tmp_path / "tree/firmware/crc32.c").read_bytes() == before[0]


def test_mutate_reports_a_known_equivalent_apart(tmp_path):
    """A mutant in tools/mutate.py's EQUIVALENT is not run: it is reported with its reason, counted in
    the raw score's denominator and left out of the other."""
    proc = subprocess.run([sys.executable, str(ROOT / "tools/mutate.py"), "--files", "firmware/collide_sight.c",
                           "--match", r"^\s*/\*\(void\)state;\*/", "--tests", "golden", "--sample", "1",
                           "--out", str(tmp_path), "--no-doc"], cwd=ROOT, capture_output=True, text=True,
                          timeout=900)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    out = json.loads((tmp_path / "results.json").read_text())
    [r] = out["results"]
    assert (r["status"], r["by"], r["seconds"]) == ("equivalent", None, 0)
    assert "unused-parameter" in r["reason"]
    assert out["counts"]["equivalent"] == 1 and out["score"] == 0.0
    report = (tmp_path / "report.md").read_text()
    assert "firmware/collide_sight.c | 1 | 0 | 0 | 1 | 0" in report
    assert "## Equivalent mutants (not run)\n\nfirmware/collide_sight.c:" in report


def test_mutate_help_names_the_sample_knob():
    proc = subprocess.run([sys.executable, str(ROOT / "tools/mutate.py"), "--help"], capture_output=True,
                          text=True, check=True)
    assert "MUTATE_SAMPLE" in proc.stdout and "--files" in proc.stdout
