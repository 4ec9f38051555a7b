"""No floating point in firmware/ and hal/: adding a float to any of their files breaks the build."""
import shutil
import subprocess

import pytest

from conftest import ROOT

FILES = ["firmware/raster.c", "firmware/scene.c", "hal/fb.c", "hal/null/hal_null.c", "hal/sdl/hal_sdl.c",
         "hal/pcvga/vga.c"]


def nofloat(*extra):
    return subprocess.run(["make", "-s", "--no-print-directory", "nofloat", f"EXTRA_NOFLOAT={' '.join(extra)}"],
                          cwd=ROOT, capture_output=True, text=True)


def test_tree_is_clean():
    proc = nofloat()
    assert proc.returncode == 0, proc.stdout + proc.stderr


@pytest.mark.parametrize("src", FILES)
@pytest.mark.parametrize("snippet", [
    "static float probe_scale = 1.5f;\n",
    "int probe(int a) { double x = a; (void)x; return a; }\n",
])
def test_float_in_a_file_fails(tmp_path, src, snippet):
    # A copy of a real file with a float added, checked with the tree's include
    # paths; it lives outside the tree so no concurrent build picks it up.
    copy = tmp_path / src.replace("/", "_").replace(".c", "_floatprobe.c")
    shutil.copy(ROOT / src, copy)
    with open(copy, "a") as f:
        f.write(snippet)
    proc = nofloat(str(copy))
    assert proc.returncode != 0
    assert "floating point" in proc.stdout


def test_host_flags_reject_float_arithmetic(tmp_path):
    # the host compile of firmware/ and hal/ uses -mgeneral-regs-only
    src = tmp_path / "f.c"
    src.write_text("int f(int a) { float x = (float)a; return (int)(x * 1.5f); }\n")
    proc = subprocess.run(["gcc", "-c", "-O2", "-ffreestanding", "-mgeneral-regs-only", str(src), "-o",
                           str(tmp_path / "f.o")], capture_output=True, text=True)
    assert proc.returncode != 0


def test_arm_link_check_catches_soft_float_helpers(tmp_path):
    # float arithmetic hidden behind a macro still shows up as an __aeabi_ helper
    src = tmp_path / "zz_floatprobe.c"
    src.write_text("#define REAL float\nint probe(int a) { REAL x = (REAL)a; return (int)(x * 3); }\n")
    proc = nofloat(str(src))
    assert proc.returncode != 0
    assert "__aeabi_" in proc.stdout or "floating point" in proc.stdout
