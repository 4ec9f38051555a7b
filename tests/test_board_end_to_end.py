"""The display board end to end: flashed over USB, booted, fed by the host.

- Flash, boot, show: build/flash downloads build/arm/display-board.dfu through real libusb into the
  umockdev-emulated DFU device (tests/usbdfu_mock.py, the project's device state machine over a
  flash region with the board's application-slot geometry). Exactly the bytes that device holds
  afterwards, behind the bootloader, are booted as the display board under QEMU; the rendering
  firmware (a second QEMU) streams frames into it over TCP, and the page it shows, read over QMP,
  is build/render's frame for the camera the link carried.
- The host's serial present: build/emu --link sends its frames into the display board.
"""
import re
import select
import shutil
import socket
import subprocess
import sys
import threading

import pytest

from conftest import ROOT, program
from test_display_board import EXIT_NO_APP, SLOT, built, host_frame, stream_into_board  # noqa: F401 (built: a fixture)
from test_flash_usb import SLOT_SIZE, have_gi, run_mock

sys.path.insert(0, str(ROOT / "tools"))
from boardrig import ARM, Board, frames_of  # noqa: E402

pytestmark = pytest.mark.skipif(shutil.which("qemu-system-arm") is None, reason="qemu-system-arm missing")

FRAMES = 8


def flashed_image(tmp_path):
    """Download display-board.dfu into the emulated device; the board's flash as it then stands:
    the bootloader's 64 KiB (the board's own, not part of a download) and the device's slot."""
    region = tmp_path / "slot.bin"
    s = run_mock("ok", [ARM / "display-board.dfu", "--device", "1209:0001"], out=region)
    assert s["exit"] == 0, s["stdout"] + s["stderr"]
    assert "re-enumerated" in s["stdout"], s["stdout"]
    slot = region.read_bytes()
    assert len(slot) == SLOT_SIZE
    boot = (ARM / "display-board.bin").read_bytes()[:SLOT]
    image = tmp_path / "flashed.bin"
    image.write_bytes(boot + slot)
    return image, slot


@pytest.mark.skipif(shutil.which("umockdev-wrapper") is None or not have_gi(),
                    reason="umockdev or its GObject bindings missing (tools/deps.sh installs them)")
def test_flash_boot_and_show_frames(built, tmp_path):
    fw_elf, image = built
    flashed, slot = flashed_image(tmp_path)
    # what the download left is what make display-board lays out: the application and its mark
    assert slot == image.read_bytes()[SLOT:]
    text, frames, start, page, _ = stream_into_board(flashed, fw_elf, tmp_path, frames=FRAMES)
    assert "bootloader: application valid" in text, text
    assert [f["frame"] for f in frames] == list(range(FRAMES)), text
    last = frames[-1]
    assert start == last["page"]
    assert page == host_frame(ARM / "scene.bsc", last, tmp_path)


@pytest.mark.skipif(shutil.which("umockdev-wrapper") is None or not have_gi(),
                    reason="umockdev or its GObject bindings missing (tools/deps.sh installs them)")
def test_interrupted_flash_does_not_boot(built, tmp_path):
    """A download cut after its third block leaves a slot the bootloader refuses."""
    region = tmp_path / "slot.bin"
    s = run_mock("vanish", [ARM / "display-board.dfu", "--device", "1209:0001"], "--block", 2, out=region)
    assert s["exit"] == 4, s["stdout"] + s["stderr"]
    flashed = tmp_path / "flashed.bin"
    flashed.write_bytes((ARM / "display-board.bin").read_bytes()[:SLOT] + region.read_bytes())
    board = Board(flashed, "--frames 1", listen=False, tmp=tmp_path)
    status = board.wait(timeout=60)
    assert status == EXIT_NO_APP, board.text
    assert "no valid application in the slot" in board.text


class Relay:
    """Listens for one sender and forwards both ways to the board's TCP port. When the sender hangs
    up, the board's side stays open until close(): QEMU drops what its guest has not read yet when
    its peer closes, and a host sender is done long before the board has shown everything."""

    def __init__(self, board_port):
        self.srv = socket.socket()
        self.srv.bind(("127.0.0.1", 0))
        self.srv.listen(1)
        self.url = f"socket://127.0.0.1:{self.srv.getsockname()[1]}"
        self.board = socket.create_connection(("127.0.0.1", board_port))
        self.stop = False
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self):
        src, _ = self.srv.accept()
        peers = {src: self.board, self.board: src}
        live = [src, self.board]
        while not self.stop and live:
            ready, _, _ = select.select(live, [], [], 0.2)
            for s in ready:
                data = s.recv(65536)
                if not data:
                    live.remove(s)
                    continue
                if peers[s] in live:
                    peers[s].sendall(data)
        src.close()

    def close(self):
        self.stop = True
        self.thread.join(5)
        self.board.close()
        self.srv.close()


@pytest.mark.parametrize("scene", ["tests/scenes/default.scene", "freedoom2.wad:MAP01"], ids=["default", "map01"])
def test_emu_link_into_the_board(built, tmp_path, scene):
    """build/emu --headless --link: the board shows every frame emu sent, in order, ending with the
    last frame emu drew, bit-identical to build/render's frame for the camera the link carried.
    emu never waits for the board: a frame drawn while the board is behind (textured frames, at the
    fly-through's 12 a second) is skipped, and the last one is sent at the end (host/link_send.h)."""
    board_elf = ARM / "display-board.elf"  # its symbols; the flash image boots it
    board = Board(built[1], "--log-frames", tmp=tmp_path)  # no --frames: how many come depends on the board's pace
    relay = None
    try:
        relay = Relay(board.tcp_port)
        emu = subprocess.run([program("emu", sanitized=False), scene, "--headless", "--frames", str(FRAMES),
                              "--out", tmp_path / "emu", "--link", relay.url],
                             cwd=ROOT, capture_output=True, text=True, timeout=300)
        assert emu.returncode == 0, emu.stderr
        board.wait_for(rf"board: frame {FRAMES - 1} [^\n]*\n", 300)
        start, page = board.shown_page(board_elf, tmp_path)
        text = board.text
    finally:
        if relay:
            relay.close()
        board.kill()
        board.wait()
    sent = {k: int(v) for k, v in re.findall(r"link_(frames|skipped)=(\d+)", emu.stdout)}
    assert sent["frames"] + sent["skipped"] == FRAMES, emu.stdout
    if scene.endswith(".scene"):
        assert sent["skipped"] == 0, emu.stdout  # flat frames: the board keeps up
    frames = frames_of(text)
    shown = [f["frame"] for f in frames]
    assert len(shown) == sent["frames"] and shown == sorted(set(shown)) and shown[0] == 0, text
    last = frames[-1]
    assert last["frame"] == FRAMES - 1 and start == last["page"]
    # the view as emu drew it (the link's camera, and emu's clock for the things on their paths)
    m = re.search(r"frame (\d+) as build/render draws it: (.*)", emu.stdout + emu.stderr)
    assert m and int(m.group(1)) == FRAMES - 1, emu.stdout + emu.stderr
    raw = tmp_path / "host.raw"
    subprocess.run([program("render", sanitized=False), scene, *m.group(2).split(), "--raw", raw],
                   cwd=ROOT, check=True, capture_output=True)
    assert page == raw.read_bytes()
