"""The Python tools run the way the README writes them: bin/NAME, from any folder, with the
project's venv (tools/pytool.sh), and a clear message when the venv is missing."""
import os
import re
import shutil
import subprocess

import pytest

from conftest import ROOT

README = (ROOT / "README.md").read_text()
# every `bin/NAME ...` the README shows, as a newcomer would type it
DOCUMENTED = sorted(set(re.findall(r"`bin/([a-z]+)[ `]", README)))


def test_readme_shows_the_tools_through_bin():
    assert {"refrender", "accuracy", "texcompare", "capture", "pcvga"} <= set(DOCUMENTED)
    assert "python3 tools/" not in README and "./tools/" not in README


@pytest.mark.parametrize("name", DOCUMENTED)
def test_documented_tool_answers_help(name, tmp_path):
    # run from another folder: the wrapper finds the tree and its venv itself
    proc = subprocess.run([str(ROOT / "bin" / name), "--help"], cwd=tmp_path, capture_output=True,
                          text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert f"usage: {name}.py" in proc.stdout


def test_every_wrapper_runs_its_tool():
    for wrapper in sorted((ROOT / "bin").iterdir()):
        assert os.access(wrapper, os.X_OK), wrapper
        assert (ROOT / "tools" / f"{wrapper.name}.py").is_file(), wrapper


def test_missing_venv_says_make_deps(tmp_path):
    # a fresh clone before `make deps`: no build/venv
    (tmp_path / "bin").mkdir()
    (tmp_path / "tools").mkdir()
    shutil.copy2(ROOT / "bin" / "accuracy", tmp_path / "bin" / "accuracy")
    shutil.copy2(ROOT / "tools" / "pytool.sh", tmp_path / "tools" / "pytool.sh")
    proc = subprocess.run([str(tmp_path / "bin" / "accuracy"), "--help"], capture_output=True, text=True,
                          timeout=60)
    assert proc.returncode == 127
    assert "make deps" in proc.stderr and proc.stdout == ""


def test_readme_reads_in_five_minutes():
    assert len(README.splitlines()) < 200
