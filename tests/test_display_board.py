"""The display board (hal/board) under QEMU's mps2-an385: `make display-board`'s flash image boots
through its DFU bootloader into the board application, which receives the rendering firmware's frame
link over TCP from a second QEMU and shows the frames; the page it shows, read out of its emulated
memory over QMP, is bit-identical to build/render's frame for the camera the link carried. A
damaged application or an erased valid mark is refused by the bootloader, which never jumps.
"""
import re
import shutil
import struct
import subprocess
import sys
import zlib

import pytest

from conftest import BUILD, ROOT, program, run

sys.path.insert(0, str(ROOT / "tools"))
from boardrig import ARM, Board, Sender, frames_of  # noqa: E402
from capture import MODES, PRESENTS  # noqa: E402
from fxtext import fx_text  # noqa: E402

pytestmark = pytest.mark.skipif(shutil.which("qemu-system-arm") is None, reason="qemu-system-arm missing")

SLOT, SLOT_BYTES, PAGE = 0x10000, 4128768, 4096
MARK = SLOT + SLOT_BYTES - PAGE
EXIT_NO_APP = 7
FRAMES = 12


def make(*args):
    proc = subprocess.run(["make", "-s", "-j2", "--no-print-directory", *args], cwd=ROOT, capture_output=True,
                          text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    return proc.stdout


@pytest.fixture(scope="module")
def built():
    """The rendering firmware as `make firmware` builds it (default scene) and the display board."""
    make("firmware", "display-board")
    return ARM / "firmware.elf", ARM / "display-board.bin"


def host_frame(scene, f, tmp_path):
    raw = tmp_path / f"host_{f['frame']}.raw"
    run([program("render", sanitized=False), scene, "--at", f"{fx_text(f['x'])},{fx_text(f['y'])},{fx_text(f['z'])}",
         "--angle", fx_text(f["angle"]), "--look", str(f["look"]), "--mode", MODES[f["mode"]],
         "--present", PRESENTS[f["present"]], "--raw", raw])
    return raw.read_bytes()


def stream_into_board(image, fw_elf, tmp_path, frames=FRAMES):
    """Boot image as the board, stream frames in from the rendering firmware, stop the board over QMP.
    Returns (board log, the frames it logged, the display-start register, the page it shows, the
    sender's output)."""
    board_elf = ARM / "display-board.elf"
    board = Board(image, f"--frames {frames}", tmp=tmp_path)
    snd = None
    try:
        snd = Sender(fw_elf, board.tcp_port, f"--frames {frames} --acks on", tmp=tmp_path)
        sent = snd.finish(frames)
        board.wait_for(r"board: done:[^\n]*\n", 120)
        start, page = board.shown_page(board_elf, tmp_path)
        text = board.text
    finally:
        if snd:
            snd.kill()
        board.kill()
        board.wait()
    return text, frames_of(text), start, page, sent


def test_rendering_firmware_streams_into_the_board(built, tmp_path):
    """Two QEMUs over TCP; the page the board shows is build/render's frame for the camera it logged."""
    fw_elf, image = built
    text, frames, start, page, sent = stream_into_board(image, fw_elf, tmp_path)
    assert "bootloader: application valid" in text
    # the board's acks reached the sender: it kept sending within its window of 4 frames
    acks = int(re.search(r"firmware: link: .*?; (\d+) acks", sent).group(1))
    assert acks >= FRAMES - 4, sent
    assert [f["frame"] for f in frames] == list(range(FRAMES)), text
    assert f"board: done: {FRAMES} frames shown, 0 dropped, 0 missed, 0 bad messages" in text, text
    # every frame flips to the other page: the one rebuilt while the old one stayed on screen
    assert [f["page"] for f in frames] == [(i + 1) % 2 for i in range(FRAMES)]
    last = frames[-1]
    assert start == last["page"]
    assert zlib.crc32(page) == last["crc32"]
    assert page == host_frame(ARM / "scene.bsc", last, tmp_path)
    assert len(set(page)) > 3


def test_flash_image_layout(built):
    """display-board.bin is the layout's 4 MiB: the bootloader at 0, the application at the slot, and
    the valid mark at the slot's last page as dfu_device.c writes it; the .dfu carries the same
    application bytes with the suffix 1209:0001."""
    _, image = built
    flash = image.read_bytes()
    assert len(flash) == 4 * 1024 * 1024
    dfu = (ARM / "display-board.dfu").read_bytes()
    app, suffix = dfu[:-16], dfu[-16:]
    bcd, pid, vid, bcd_dfu, sig, length, crc = struct.unpack("<HHHH3sBI", suffix)
    assert (vid, pid, sig[::-1], length) == (0x1209, 0x0001, b"DFU", 16)
    assert flash[SLOT:SLOT + len(app)] == app
    assert set(flash[SLOT + len(app):MARK]) == {0xFF}
    magic, n, app_crc, check = struct.unpack("<IIII", flash[MARK:MARK + 16])
    assert (magic, n, app_crc) == (0x50415642, len(app), zlib.crc32(app))
    assert check == zlib.crc32(flash[MARK:MARK + 12])
    assert set(flash[MARK + 16:]) == {0xFF}
    # the application's vector table: its stack top in RAM, its reset handler in the slot (Thumb)
    sp, reset = struct.unpack("<II", flash[SLOT:SLOT + 8])
    assert 0x20000000 < sp <= 0x20400000 and SLOT < reset < SLOT + len(app) and reset & 1


@pytest.mark.parametrize("damage", ["flipped byte", "erased mark"])
def test_bootloader_refuses_a_bad_slot(built, tmp_path, damage):
    _, image = built
    flash = bytearray(image.read_bytes())
    if damage == "flipped byte":
        flash[SLOT + 0x200] ^= 0x01
        why = "does not match the mark's"
    else:
        flash[MARK:MARK + PAGE] = b"\xff" * PAGE
        why = "the mark page at 0x003ff000 is erased"
    bad = tmp_path / "bad.bin"
    bad.write_bytes(bytes(flash))
    board = Board(bad, listen=False, tmp=tmp_path)
    rc = board.wait(30)
    assert rc == EXIT_NO_APP, board.text
    assert "bootloader: no valid application in the slot (" in board.text and why in board.text
    assert "staying in DFU mode" in board.text
    assert "board:" not in board.text  # the application never ran
