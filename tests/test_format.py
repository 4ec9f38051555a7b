"""make format-check: fails on a misformatted file and names it, passes on a formatted one, and covers
every C file of the project's own folders (mk/format.mk)."""
import pathlib
import shutil
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent
pytestmark = pytest.mark.skipif(shutil.which("clang-format") is None, reason="clang-format not installed")


def make(*args):
    return subprocess.run(["make", "-s", "--no-print-directory", "-C", str(ROOT), *args],
                          capture_output=True, text=True)


def test_format_check_names_a_misformatted_file(tmp_path):
    good = tmp_path / "good.c"
    bad = tmp_path / "bad.c"
    good.write_text("int f(int x)\n{\n    if (x < 0) return 0;\n    return x;\n}\n")
    bad.write_text("int f(int x) {\n  if (x < 0)\n    return 0;\n  return x; }\n")
    ok = make("format-check", f"FORMAT_SRC={good}")
    assert ok.returncode == 0, ok.stdout + ok.stderr
    r = make("format-check", f"FORMAT_SRC={good} {bad}")
    assert r.returncode != 0
    assert str(bad) in r.stdout and str(good) not in r.stdout
    assert bad.read_text().startswith("int f(int x) {\n  if"), "format-check must not rewrite files"


def test_format_covers_every_c_file():
    r = make("--eval", "print-format-src: ; @echo $(FORMAT_SRC)", "print-format-src")
    listed = set(r.stdout.split())
    present = {str(p.relative_to(ROOT)) for d in ("firmware", "hal", "host", "tools", "tests/unit", "tests/fuzz")
               for p in (ROOT / d).rglob("*.[ch]")}
    assert present - listed == set(), "add the folder to FORMAT_DIRS in mk/format.mk"
