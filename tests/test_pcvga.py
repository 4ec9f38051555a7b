"""The PC kernel (hal/pcvga) under qemu-system-i386: it boots from multiboot, puts the VGA in
mode 13h (unchained for page flipping) through its registers, and the screen QEMU shows - taken
with QMP's screendump, turned back from QEMU's 6-to-8-bit DAC expansion - is build/render's
frame for the same scene and camera, pixel for pixel, in every present mode; its write counters
are the host's in the copy modes; it reports exceptions, bad options, a damaged scene and too
little memory with a message on COM1 and an exit status through isa-debug-exit.

Builds go through make (mk/pcvga.mk); variants go to their own PC_OUT folders under build/.
"""
import shutil
import subprocess
import sys

import numpy as np
import pytest

from conftest import BUILD, ROOT

sys.path.insert(0, str(ROOT / "tools"))
import pcvga  # noqa: E402

pytestmark = pytest.mark.skipif(shutil.which(pcvga.QEMU) is None, reason="qemu-system-i386 missing: run make deps")

EXIT_OK, EXIT_SCENE, EXIT_FAULT, EXIT_WORK, EXIT_ARGS = 0, 2, 3, 4, 5
VIEW = "--at 700.5,120 --angle 33.25 --look -20"
PRESENTS = ("copy8", "copy16", "copy32", "flip")


def make(*args):
    proc = subprocess.run(["make", "-s", "-j2", "--no-print-directory", *args], cwd=ROOT, capture_output=True,
                          text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    return proc


@pytest.fixture(scope="module")
def kernel():
    """What `make pcvga` builds (build/pcvga/kernel.elf, the default scene built in)."""
    make("pcvga")
    return BUILD / "pcvga" / "kernel.elf"


def shot(kernel, args, tmp_path):
    """The kernel's screen after its last frame, compared with build/render's frame."""
    summary = pcvga.shot(kernel, args, BUILD / "pcvga" / "scene.bsc", png=tmp_path / "shot.png")
    assert summary["kernel_status"] == EXIT_OK, summary
    assert summary["screendump"] == "640x400"
    return summary


@pytest.mark.parametrize("present", PRESENTS)
def test_screendump_is_the_host_frame(kernel, present, tmp_path):
    """A fixed view in each present mode: the screen QEMU shows is build/render's frame, bit for bit."""
    s = shot(kernel, f"{VIEW} --frames 3 --present {present}", tmp_path)
    assert s["dac_pixels_differing"] == 0, s
    # the default scene's palette tells every colour apart at 6 bits: the indices are exact too
    assert s["pixels_ambiguous_at_6_bits"] == 0 and s["pixels_of_no_palette_colour"] == 0, s
    assert s["index_pixels_differing"] == 0, s
    assert s["frames"] == 3 and s["last_frame"]["crc"] == s["render_crc32"], s


def test_copy_present_write_counts(kernel, tmp_path):
    """The copy modes count exactly the host's writes, and the copy itself is 64,000 bytes in
    64,000, 32,000 or 16,000 transactions into VGA memory."""
    for present, width in (("copy8", 1), ("copy16", 2), ("copy32", 4)):
        s = shot(kernel, f"{VIEW} --frames 1 --present {present}", tmp_path)
        got, want = s["last_frame"], s["render_counters"]
        assert {k: got[k] for k in pcvga.COUNTERS} == want, (present, got, want)
        assert got["copy_writes"] == 64000 // width and got["vram_writes"] == 64000 // width
        assert got["writes" + str(8 * width)] >= 64000 // width


def test_flip_fills_four_pixels_a_byte(kernel, tmp_path):
    """Page flipping on the unchained layout: nothing is copied, every write lands in VRAM,
    and a byte written with every plane enabled covers four pixels, so the frame costs a
    quarter of the bytes or so and far fewer transactions than the host's linear page."""
    s = shot(kernel, f"{VIEW} --frames 2 --present flip", tmp_path)
    got, linear = s["last_frame"], s["render_counters"]
    assert got["copy_writes"] == 0 and got["sysmem_writes"] == 0 and got["vram_writes"] == got["writes"]
    assert got["pixels"] == linear["pixels"] == 64000
    assert linear["bytes"] == 64000 and 16000 <= got["bytes"] < 64000 // 3
    assert got["writes"] < linear["writes"] // 2
    assert got["bytes"] == got["writes8"] + 2 * got["writes16"] + 4 * got["writes32"]


def test_camera_path_frames_match_the_host(kernel, tmp_path):
    """The scripted path in flip mode: each frame's CRC-32 (read back from VGA memory) is
    build/render's from the camera the kernel reports, and the last frame is on the screen."""
    s = shot(kernel, "--present flip", tmp_path)
    assert s["frames"] == 204 and s["dac_pixels_differing"] == 0 and s["index_pixels_differing"] == 0, s
    status, log = pcvga.run(kernel, "--present copy16 --frames 120")
    assert pcvga.exit_status(status) == EXIT_OK, log
    frames = pcvga.frame_lines(log)
    assert [f["frame"] for f in frames] == list(range(120))
    assert len({f["crc"] for f in frames}) > 100  # the camera moves
    for f in frames[::17]:
        _, _, ref = pcvga.render_reference(BUILD / "pcvga" / "scene.bsc", f, "--present copy16")
        assert ref["crc32"] == f["crc"], f
    assert "pcvga: done, 120 frames in" in log


def test_make_run_pcvga(kernel):
    """make run-pcvga boots it (headless here) and passes the kernel's exit status through."""
    proc = subprocess.run(["make", "-s", "--no-print-directory", "run-pcvga", "PC_DISPLAY=none",
                           "RUN_ARGS=--frames 5 --present copy32"], cwd=ROOT, capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "pcvga: done, 5 frames in" in proc.stdout and "kernel status 0" in proc.stdout


def test_dac_expansion_is_undone_exactly():
    """QEMU widens each 6-bit DAC value v to v << 2 | (v & 1) * 3; dac_frame undoes it and
    refuses anything else (a screen that is not the VGA's 256-colour mode)."""
    v = np.arange(64, dtype=np.uint8)
    shot8 = np.zeros((400, 640, 3), dtype=np.uint8)
    shot8[:, :, 0] = np.tile(np.repeat((v << 2) | ((v & 1) * 3), 2), 5)[:640]
    dac = pcvga.dac_frame(shot8)
    assert dac.shape == (200, 320, 3) and list(dac[0, :64, 0]) == list(range(64))
    shot8[0, 0, 0] ^= 1
    with pytest.raises(ValueError):
        pcvga.dac_frame(shot8)
    with pytest.raises(ValueError):
        pcvga.dac_frame(np.zeros((480, 640, 3), dtype=np.uint8))


def test_bad_option_is_refused(kernel):
    status, log = pcvga.run(kernel, "--frames many")
    assert pcvga.exit_status(status) == EXIT_ARGS and "pcvga: --frames 'many': expected a count" in log, log
    status, log = pcvga.run(kernel, "--acks on")
    assert pcvga.exit_status(status) == EXIT_ARGS and "option '--acks' is not available on this target" in log


def test_fault_is_reported(kernel):
    status, log = pcvga.run(kernel, "--fault")
    assert pcvga.exit_status(status) == EXIT_FAULT, log
    assert "pcvga: fault: #UD invalid opcode (vector 6) at eip 0x" in log, log


def test_too_little_memory_is_refused(kernel):
    with pcvga.Kernel(kernel, "--frames 1", mem_mb="1.4M") as k:
        out, _ = k.proc.communicate(timeout=60)
    log = out.decode(errors="replace")
    assert pcvga.exit_status(k.proc.returncode) == EXIT_WORK, log
    assert "bytes of work memory;" in log and "are free above the kernel (give QEMU more with -m)" in log, log
    assert "frame 0" not in log


def test_damaged_scene_is_refused():
    work = BUILD / "pcvga-test"
    work.mkdir(parents=True, exist_ok=True)
    blob = bytearray((BUILD / "default.bsc").read_bytes())
    blob[len(blob) // 2] ^= 0x5A
    (work / "damaged.bsc").write_bytes(bytes(blob))
    make("pcvga", f"SCENE={work / 'damaged.bsc'}", f"PC_OUT={work / 'damaged'}")
    status, log = pcvga.run(work / "damaged" / "kernel.elf", "--frames 1")
    assert pcvga.exit_status(status) == EXIT_SCENE, log
    assert "is invalid: bad CRC-32; refusing to run" in log and "frame 0" not in log, log


@pytest.fixture(scope="module")
def kernel_map01():
    """The kernel built for freedoom2.wad:MAP01 with its textures (build/pcvga-map01)."""
    make("pcvga", "SCENE=freedoom2.wad:MAP01", "CAMPATH=map01", f"PC_OUT={BUILD / 'pcvga-map01'}")
    return BUILD / "pcvga-map01" / "kernel.elf"


@pytest.mark.parametrize("present", ("flip", "copy32"))
def test_textured_screendump_is_the_host_frame(kernel_map01, present, tmp_path):
    """Textured frames on the bare PC: in flip mode each textured span is written plane by plane
    into the unchained page (hal_put_span), in copy32 through the system-memory buffer; either way
    the screen is build/render's frame (the palette is PLAYPAL's, whose 6-bit DAC values do not
    tell every index apart, so the DAC values are compared, and the frame's CRC)."""
    s = pcvga.shot(kernel_map01, f"--at -100,-160 --angle 20 --frames 2 --present {present}",
                   BUILD / "pcvga-map01" / "scene.bsc", png=tmp_path / "shot.png")
    assert s["kernel_status"] == EXIT_OK, s
    assert s["dac_pixels_differing"] == 0 and s["pixels_of_no_palette_colour"] == 0, s
    assert s["last_frame"]["crc"] == s["render_crc32"], s
    assert s["index_pixels_differing"] == 0, s
