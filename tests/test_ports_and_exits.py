"""The PORT argument (host/port.c), one parser for build/render --link, build/emu --link and
build/display: a socket:// port is a decimal number in 1..65535 and nothing else (getaddrinfo
alone cut 99999 to 16 bits and connected to 34463), checked at both ends of the range; and a FIFO
is refused, since opened both ways it hands a program its own bytes back."""
import os
import socket
import subprocess

import pytest

from conftest import program, run
from test_hostlink import DEFAULT

# The programs that take a PORT, each with the arguments that bring it to opening it, and the
# status a PORT that does not open ends it with (--link's bad option: 2; display: 1).
PROGRAMS = {
    "render": ([DEFAULT, "--link"], True, 2),
    "emu": ([DEFAULT, "--headless", "--frames", "2", "--link"], False, 2),
    "display": (["--idle-timeout", "2", "--json"], True, 1),
}


def open_port(name, port, tmp_path):
    args, sanitized, _ = PROGRAMS[name]
    if name == "display":
        args = [port, "--png", tmp_path / "png", *args]
    else:
        args = [*args, port]
    return run([program(name, sanitized), *args], check=False, timeout=60, cwd=tmp_path)


INVALID = ["65536", "0", "99999", "", "80x", "x80", "abc", "-1", "+80", " 80", "8 0", "4294967297",
           "99999999999999999999999"]


@pytest.mark.parametrize("name", PROGRAMS)
@pytest.mark.parametrize("num", INVALID)
def test_a_port_number_outside_1_to_65535_is_refused_by_name(name, num, tmp_path):
    url = f"socket://127.0.0.1:{num}"
    proc = open_port(name, url, tmp_path)
    assert proc.returncode == PROGRAMS[name][2], proc.stderr
    line = f"{url}: invalid port '{num}' (expected a number in 1..65535)"
    assert proc.stderr.count(line) == 1, proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1, proc.stderr


@pytest.mark.parametrize("name", PROGRAMS)
@pytest.mark.parametrize("num", ["65535", "1"])
def test_the_ends_of_the_range_are_port_numbers(name, num, tmp_path):
    """65535 and 1 pass the parser: what may follow is a failed connection, not a refusal."""
    url = f"socket://127.0.0.1:{num}"
    proc = open_port(name, url, tmp_path)
    assert "invalid port" not in proc.stderr, proc.stderr
    if "cannot connect" in proc.stderr:  # nothing listens there (the usual case)
        assert proc.returncode == PROGRAMS[name][2]
        assert f"{url}: cannot connect: " in proc.stderr, proc.stderr


def test_a_port_past_65535_does_not_reach_its_16_bit_remainder(tmp_path):
    """The fault itself: socket://127.0.0.1:99999 connected to 34463 (99999 - 65536)."""
    srv = socket.socket()
    srv.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        srv.bind(("127.0.0.1", 99999 - 65536))
    except OSError as e:
        srv.close()
        pytest.skip(f"port 34463 is taken here: {e}")
    srv.listen(1)
    srv.setblocking(False)
    try:
        proc = open_port("render", "socket://127.0.0.1:99999", tmp_path)
        with pytest.raises(BlockingIOError):
            srv.accept()
    finally:
        srv.close()
    assert proc.returncode == 2 and "invalid port '99999'" in proc.stderr, proc.stderr


@pytest.mark.parametrize("name", PROGRAMS)
def test_a_fifo_is_refused_by_name(name, tmp_path):
    """Before: display read its own acks back from the FIFO; render and emu their own frames."""
    fifo = tmp_path / "link.fifo"
    os.mkfifo(fifo)
    proc = open_port(name, str(fifo), tmp_path)
    assert proc.returncode == PROGRAMS[name][2], proc.stderr
    assert f"{fifo}: a FIFO (named pipe) cannot carry the link both ways" in proc.stderr, proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1, proc.stderr

