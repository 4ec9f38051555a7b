"""The display board (hal/board) under QEMU's mps2-an385: `make display-board`'s flash image boots
through its DFU bootloader into the board application, which receives the rendering firmware's frame
link over TCP from a second QEMU and shows the frames; the page it shows, read out of its emulated
memory over QMP, is bit-identical to build/render's frame for the camera the link carried. A
damaged application or an erased valid mark is refused by the bootloader, which never jumps.
"""
import random
import re
import shutil
import socket
import struct
import subprocess
import sys
import zlib

import pytest

from conftest import BUILD, ROOT, freedoom, program, run

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
         "--present", PRESENTS[f["present"]], "--time", str(f["time_ms"]), "--raw", raw])
    return raw.read_bytes()


def stream_into_board(image, fw_elf, tmp_path, frames=FRAMES, log_frames=True):
    """Boot image as the board (with --log-frames unless log_frames is false), stream frames in from
    the rendering firmware, stop the board over QMP. Returns (board log, the frames it logged, the
    display-start register, the page it shows, the sender's output)."""
    board_elf = ARM / "display-board.elf"
    board = Board(image, f"--frames {frames}" + (" --log-frames" if log_frames else ""), tmp=tmp_path)
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


@pytest.fixture(scope="module")
def map01_firmware():
    """The rendering firmware built for freedoom2.wad:MAP01: textured, things as sprites."""
    out = BUILD / "arm-board-map01"
    make("firmware", f"SCENE={freedoom('freedoom2.wad')}:MAP01", f"ARM_OUT={out}")
    return out / "firmware.elf", out / "scene.bsc"


def test_textured_frames_from_the_firmware(built, map01_firmware, tmp_path):
    """The firmware's textured frames go as COPY frames (a few KB each where raw ones were 64,000
    bytes): every one shown, none dropped, and the page the board shows, read over QMP, is
    bit-identical to build/render's frame for the camera and time the link carried."""
    fw_elf, scene = map01_firmware
    frames = 6
    text, logged, start, page, sent = stream_into_board(built[1], fw_elf, tmp_path, frames=frames)
    assert [f["frame"] for f in logged] == list(range(frames)), text
    assert f"board: done: {frames} frames shown, 0 dropped, 0 missed, 0 bad messages" in text, text
    last = logged[-1]
    assert start == last["page"]
    assert zlib.crc32(page) == last["crc32"]
    assert page == host_frame(scene, last, tmp_path)
    assert len(set(page)) > 32  # textured: many colours
    nbytes = int(re.search(r"firmware: link: .*?(\d+) bytes", sent).group(1))
    assert nbytes < frames * 40000, sent  # coded, not raw


def test_board_without_log_frames(built, tmp_path):
    """Without --log-frames the board logs no line per frame, only its summary, and still shows every
    frame (the last one on the page it flipped to)."""
    fw_elf, image = built
    frames = 4
    text, logged, start, page, sent = stream_into_board(image, fw_elf, tmp_path, frames=frames, log_frames=False)
    assert logged == [] and "board: frame " not in text, text
    assert f"board: done: {frames} frames shown, 0 dropped, 0 missed, 0 bad messages" in text, text
    assert "so far" not in text  # a line of counters only every 1000 frames
    assert start == (frames % 2)  # page 1 shows frame 0, page 0 frame 1, ...
    assert len(set(page)) > 3


def test_board_takes_a_damaged_stream(built, tmp_path):
    """A stream straight into the board's UART over TCP, with runs of empty segments (more delimiters
    than the receive ring notes: the board finds them by a scan), a damaged message and textured
    frames larger than its receive ring: every frame is shown, and the CRC-32 the board logs for each
    (the sender sent none) is that of the frame encoded."""
    fltool = program("fltool", sanitized=False)
    walk = tmp_path / "walk"
    walk.mkdir()
    frames = 6
    run([fltool, "walk", f"{freedoom('freedoom2.wad')}:MAP01", "--frames", frames, "--out", walk])
    run([fltool, "encode", walk / "frames.raw", "--info", walk / "frames.jsonl", "--palette", walk / "palette.bin",
         "--no-crc", "--out", tmp_path / "stream.bin"])
    msgs = [m + b"\0" for m in (tmp_path / "stream.bin").read_bytes().split(b"\0")[:-1]]
    assert len(msgs) == 2 + frames and max(len(m) for m in msgs) > 8192  # hello, palette, frames
    rng = random.Random(27)
    garbage = bytes(rng.randrange(1, 256) for _ in range(3000)) + b"\0"
    data = (msgs[0] + b"\0" * 100 + msgs[1] + garbage + b"".join(msgs[2:5]) + b"\0" * 40 +
            b"".join(m + b"\0" * 3 for m in msgs[5:]))
    raw = (walk / "frames.raw").read_bytes()
    board = Board(built[1], f"--frames {frames} --log-frames", tmp=tmp_path)
    try:
        with socket.create_connection(("127.0.0.1", board.tcp_port)) as s:
            s.sendall(data)
            board.wait_for(r"board: done:[^\n]*\n", 120)
        start, page = board.shown_page(ARM / "display-board.elf", tmp_path)
        text = board.text
    finally:
        board.kill()
        board.wait()
    shown = frames_of(text)
    assert [f["frame"] for f in shown] == list(range(frames)), text
    assert [f["crc32"] for f in shown] == [zlib.crc32(raw[k * 64000:(k + 1) * 64000]) for k in range(frames)]
    assert f"board: done: {frames} frames shown, 0 dropped, 0 missed, 1 bad messages, 1 resyncs" in text, text
    empty = 100 + 40 + 3 * (frames - 3)  # delimiters of empty segments: the board does not feed them to the decoder
    assert f"{len(data) - empty} bytes, 0 UART overruns" in text, text
    assert start == shown[-1]["page"] and page == raw[-64000:]


def test_board_options(built, tmp_path):
    """A bad option is refused with status 5 and says what the board takes."""
    _, image = built
    board = Board(image, "--log-frame", listen=False, tmp=tmp_path)
    assert board.wait(30) == 5, board.text
    assert "unknown option '--log-frame' (the board takes --frames N and --log-frames)" in board.text


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


@pytest.mark.parametrize("sp, reset, why", [
    (0x12345678, 0x00010101, "its initial stack pointer is not in RAM"),
    (0x20008000, 0x00010100, "its reset vector lacks the Thumb bit"),
    (0x20008000, 0x00011389, "its reset vector points outside the application"),
], ids=["stack", "thumb", "reset"])
def test_bootloader_refuses_an_image_that_is_no_program(built, tmp_path, sp, reset, why):
    """5,000 random bytes in the slot with a valid mark, as a DFU download of them leaves it (board_image):
    the CRC matches, but the vector table cannot be started, so the bootloader refuses with status 7
    and never jumps. (0x00011389 is the first halfword past the 5,000 bytes at 0x00010000.)"""
    rng = random.Random(28)
    app = struct.pack("<II", sp, reset) + bytes(rng.randrange(256) for _ in range(5000 - 8))
    app_bin, img = tmp_path / "app.bin", tmp_path / "img.bin"
    app_bin.write_bytes(app)
    run([program("board_image", sanitized=False), ARM / "board-boot.app.bin", app_bin, img])
    board = Board(img, listen=False, tmp=tmp_path)
    rc = board.wait(30)
    assert rc == EXIT_NO_APP, board.text
    assert f"cannot be started: {why}" in board.text and "staying in DFU mode" in board.text, board.text
    assert "board:" not in board.text and "application valid" not in board.text
