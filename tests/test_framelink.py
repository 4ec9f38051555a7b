"""The frame link's Python twin (tools/framelink.py) against the C encoder and decoder.

Streams come from build/fltool (host/fltool.c): a fly-through of freedoom2.wad:MAP01 rendered
by the firmware on the null target, encoded by the C encoder. The codec's tests use the walk in
flat colours, whose frames take every path of the codec (runs, deltas, keyframes); textured frames
are mostly raw (make bench-link), and one test sends them through too. The C decoder (build/san/fltool
decode, under ASan + UBSan) and the Python decoder must report the same events in the same
order and the same counters for the same bytes - clean, in any chunking, and with faults
injected (bit flips, dropped and inserted bytes, truncations) - and neither may ever show a
frame that differs from the frame sent with its number.
"""
import json
import random
import shutil
import subprocess
import sys
import zlib
from pathlib import Path

import pytest

from conftest import ROOT, program, render, run

sys.path.insert(0, str(ROOT / "tools"))
import framelink  # noqa: E402

FRAMES = 48


def make_walk(tmp_path_factory, *extra):
    """A fly-through of MAP01: frames.raw, frames.jsonl, palette.bin."""
    out = tmp_path_factory.mktemp("walk")
    run([program("fltool", sanitized=False), "walk", "freedoom2.wad:MAP01", "--frames", FRAMES, "--out", out,
         *extra])
    raw = (out / "frames.raw").read_bytes()
    assert len(raw) == FRAMES * framelink.FRAME_BYTES
    lines = [json.loads(l) for l in (out / "frames.jsonl").read_text().splitlines()]
    return out, raw, lines


@pytest.fixture(scope="module")
def walk(tmp_path_factory):
    return make_walk(tmp_path_factory, "--flat")


@pytest.fixture(scope="module")
def walk_textured(tmp_path_factory):
    return make_walk(tmp_path_factory)


def encode(walk, tmp_path, *extra):
    out, _, _ = walk
    stream = tmp_path / "stream.bin"
    run([program("fltool", sanitized=False), "encode", out / "frames.raw", "--info", out / "frames.jsonl",
         "--palette", out / "palette.bin", "--out", stream, *extra])
    return stream.read_bytes()


def c_decode(data, tmp_path, chunk=4096):
    path = tmp_path / "in.bin"
    path.write_bytes(data)
    proc = run([program("fltool"), "decode", path, "--chunk", chunk])
    lines = [json.loads(l) for l in proc.stdout.splitlines()]
    return lines[:-1], lines[-1]


def py_decode(data, chunk=4096):
    dec = framelink.Decoder()
    events, crcs = [], []
    for off in range(0, len(data), chunk):
        for ev in dec.feed(data[off:off + chunk]):
            ev.pop("palette", None)
            pixels = ev.pop("pixels", None)
            events.append(ev)
            if ev["event"] == "frame":
                crcs.append((ev["frame"], zlib.crc32(pixels)))
    return events, {"counters": dec.counters, "back_bytes": dec.back_bytes}, crcs


def sent_crcs(walk):
    return {l["frame"]: int(l["crc32"], 16) for l in walk[2]}


def test_walk_is_reproducible_by_render(walk_textured):
    """The camera and time fltool walk writes are those used: build/render redraws the frame (its
    animated textures at the walk's time, its doors where the walk left them)."""
    _, raw, lines = walk_textured
    for l in (lines[0], lines[FRAMES // 2], lines[-1]):
        c = l["camera"]
        doors = [a for s, h in l["ceilings"].items() for a in ("--door", f"{s}={h}")]
        got = render("freedoom2.wad:MAP01", "--look", str(c["look"]), "--time", str(l["t_ms"]), *doors,
                     at=f"{c['x']},{c['y']},{c['z']}", angle=str(c["angle"]), sanitized=False)
        assert got["crc32"] == l["crc32"]
        k = l["frame"]
        assert zlib.crc32(raw[k * 64000:(k + 1) * 64000]) == int(l["crc32"], 16)


def test_flat_walk_has_the_same_cameras(walk_textured, tmp_path):
    """fltool walk --flat (make bench-link's flat frames): the textured walk's cameras, each frame
    the one build/render --flat draws, and not the textured frame."""
    _, _, lines = walk_textured
    n = 12
    run([program("fltool", sanitized=False), "walk", "freedoom2.wad:MAP01", "--frames", n, "--out", tmp_path,
         "--flat"])
    flat = [json.loads(l) for l in (tmp_path / "frames.jsonl").read_text().splitlines()]
    assert [l["raw"] for l in flat] == [l["raw"] for l in lines[:n]]
    for l in (flat[0], flat[-1]):
        c = l["camera"]
        got = render("freedoom2.wad:MAP01", "--look", str(c["look"]), "--flat",
                     at=f"{c['x']},{c['y']},{c['z']}", angle=str(c["angle"]), sanitized=False)
        assert got["crc32"] == l["crc32"] and got["textured"] == 0
        assert l["crc32"] != lines[l["frame"]]["crc32"]


def test_textured_walk_clean(walk_textured, tmp_path):
    """Textured frames (most of them sent raw) arrive whole: every frame shown, as sent."""
    data = encode(walk_textured, tmp_path)
    c_events, c_tail = c_decode(data, tmp_path)
    p_events, p_tail, crcs = py_decode(data)
    assert p_events == c_events and p_tail == c_tail
    assert p_tail["counters"]["frames_shown"] == FRAMES and p_tail["counters"]["msgs_bad"] == 0
    sent = sent_crcs(walk_textured)
    assert [k for k, _ in crcs] == list(range(FRAMES)) and all(sent[k] == crc for k, crc in crcs)


@pytest.mark.parametrize("extra", [[], ["--key-interval", "1"], ["--key-interval", "0"], ["--no-crc"],
                                   ["--scratch", "300"]])
def test_same_events_clean(walk, tmp_path, extra):
    data = encode(walk, tmp_path, *extra)
    c_events, c_tail = c_decode(data, tmp_path)
    p_events, p_tail, crcs = py_decode(data)
    assert p_events == c_events
    assert p_tail == c_tail
    counters = p_tail["counters"]
    assert counters["frames_shown"] == FRAMES
    assert counters["msgs_bad"] == 0
    assert counters["bytes"] == len(data)
    sent = sent_crcs(walk)
    assert [k for k, _ in crcs] == list(range(FRAMES))
    assert all(sent[k] == crc for k, crc in crcs)
    # the frame information arrives as sent, and the receiver knows the pixel CRC either way
    frames = [e for e in p_events if e["event"] == "frame"]
    for e, l in zip(frames, walk[2]):
        assert [e["info"][k] for k in ("x", "y", "z", "angle", "look")] == l["raw"]
        assert e["info"]["crc32"] == l["crc32"]
        assert e["info"]["no_crc"] == (1 if "--no-crc" in extra else 0)
    if "--scratch" not in extra:
        assert len(data) / FRAMES < 570


def test_python_decoder_frames_bit_exact(walk, tmp_path):
    data = encode(walk, tmp_path, "--key-interval", "16")
    _, raw, _ = walk
    dec = framelink.Decoder()
    got = []
    for ev in dec.feed(data):
        if ev["event"] == "frame":
            got.append(ev["frame"])
            k = ev["frame"]
            assert ev["pixels"] == raw[k * 64000:(k + 1) * 64000]
            assert framelink.frame_check(ev["pixels"]) == framelink.frame_check(raw[k * 64000:(k + 1) * 64000])
    assert dec.frame == raw[-64000:]
    assert got == list(range(FRAMES))
    assert dec.palette == (walk[0] / "palette.bin").read_bytes()


@pytest.mark.parametrize("chunk", [1, 3, 250, 100000])
def test_any_chunking(walk, tmp_path, chunk):
    data = encode(walk, tmp_path)
    ref, ref_tail, _ = py_decode(data, 4096)
    p_events, p_tail, _ = py_decode(data, chunk)
    assert p_events == ref and p_tail == ref_tail
    c_events, c_tail = c_decode(data, tmp_path, chunk=min(chunk, 65536))
    assert c_events == ref and c_tail == ref_tail


def damage(data, rate, kind, seed):
    """Bit flips, dropped bytes, inserted bytes, truncated runs, or all of them, at `rate` per byte."""
    rng = random.Random(seed)
    out = bytearray()
    i = 0
    while i < len(data):
        b = data[i]
        if rng.random() < rate:
            k = rng.randrange(4) if kind == "mixed" else kind
            if k in ("flip", 0):
                out.append(b ^ (1 << rng.randrange(8)))
            elif k in ("drop", 1):
                pass
            elif k in ("insert", 2):
                out.append(rng.randrange(256))
                out.append(b)
            else:
                i += rng.randrange(40)
        else:
            out.append(b)
        i += 1
    return bytes(out)


@pytest.mark.parametrize("rate", [1e-5, 1e-4, 1e-3, 1e-2])
@pytest.mark.parametrize("kind", ["flip", "drop", "insert", "truncate", "mixed"])
def test_same_events_with_faults(walk, tmp_path, rate, kind):
    clean = encode(walk, tmp_path, "--key-interval", "8")
    # several passes over the walk: hundreds of frames
    data = damage(clean * 3, rate, kind, seed=zlib.crc32(f"{rate} {kind}".encode()))
    c_events, c_tail = c_decode(data, tmp_path)
    p_events, p_tail, crcs = py_decode(data)
    assert p_events == c_events
    assert p_tail == c_tail
    c = p_tail["counters"]
    # never a frame that differs from the frame sent with its number
    sent = sent_crcs(walk)
    assert all(sent[k] == crc for k, crc in crcs)
    assert c["frames_shown"] == len(crcs)
    assert c["bytes"] == len(data)
    assert c["frames_dropped"] == sum(e["event"] == "drop" for e in p_events)
    assert c["msgs_bad"] == sum(e["event"] == "bad" for e in p_events)
    assert c["keyreqs_sent"] == sum(e["event"] == "keyreq" for e in p_events)
    if rate >= 1e-3:
        assert c["msgs_bad"] > 0 and c["resyncs"] > 0
    if rate <= 1e-3:
        assert c["frames_shown"] > 0  # keyframes every 8 frames get through again


def test_garbage_and_other_versions(tmp_path):
    rng = random.Random(5)
    garbage = bytes(rng.randrange(256) for _ in range(100000))
    hello = framelink.encode_message(framelink.MSG_HELLO, 0, bytes([1, 64, 1, 200, 0, 8, 16, 0, 4, 3]))
    other = framelink.encode_message(framelink.MSG_HELLO, 0, bytes([1, 64, 1, 200, 0, 8, 16, 0, 4, 3]), version=framelink.VERSION + 1)
    short = framelink.encode_message(framelink.MSG_PALETTE, 0, bytes(10))
    data = garbage + b"\x00" + other + short + hello + b"\x00\x00"
    c_events, c_tail = c_decode(data, tmp_path)
    p_events, p_tail, _ = py_decode(data)
    assert p_events == c_events and p_tail == c_tail
    kinds = [e["event"] for e in p_events]
    assert kinds[-1] == "hello"
    assert p_events[-2] == {"event": "bad", "reason": "payload"}
    assert p_events[-3] == {"event": "bad", "reason": "version"}
    assert p_tail["counters"]["hellos"] == 1 and p_tail["counters"]["frames_shown"] == 0


def test_back_channel_messages():
    """Acks and keyframe requests the Python decoder sends are well-formed messages."""
    sent = []
    dec = framelink.Decoder(back=sent.append)
    delta_without_base = framelink.encode_message(framelink.MSG_DELTA, 7, bytes(framelink.FRAME_PRE) + bytes(
        [0, 0, 0, 0, framelink.METHOD_EDGE]))
    evs = dec.feed(delta_without_base)
    assert [e["event"] for e in evs] == ["drop", "keyreq"]
    assert evs[0]["reason"] == "no_base"
    assert len(sent) == 2
    r = framelink._Reader(framelink.MSG_MAX)
    types = []
    for msg in sent:
        res = [r.byte(b) for b in msg]
        assert res[-1] == 1
        why, m = framelink.check_message(r.buf)
        assert why is None
        types.append((m[0], m[1], m[2][0]))
    assert types == [(framelink.MSG_ACK, 7, 1), (framelink.MSG_KEYREQ, 7, 1 | 2)]


def bound_patterns(n):
    """n bytes: no zero, all zeros, a zero every third byte, one zero at the end."""
    return [bytes(i % 255 + 1 for i in range(n)), bytes(n), bytes(0 if i % 3 == 0 else i & 255 or 1 for i in range(n)),
            bytes([7]) * (n - 1) + bytes(1) if n else b""]


@pytest.mark.parametrize("cap", [1, 2, 3, 253, 254, 255, 256, 508, 509, 1000])
def test_reader_bound(cap):
    """The Python reader (fl_reader's twin) with messages of cap - 1, cap and cap + 1 bytes: the
    first two arrive whole, the third is refused as too long, and the next message is read."""
    for n in (cap - 1, cap, cap + 1):
        for data in bound_patterns(n):
            r = framelink._Reader(cap)
            fits = data[:cap - 1]
            stream = framelink.cobs_encode(data) + b"\x00" + framelink.cobs_encode(fits) + b"\x00"
            results = []
            for b in stream:
                res = r.byte(b)
                if res:
                    results.append((res, bytes(r.buf)))
                assert len(r.buf) <= cap
            if n <= cap:
                assert results[0] == (1, data), (cap, n)
            else:
                assert results[0][0] == -framelink.R_LONG, (cap, n)
            assert results[1:] == [(1, fits)], (cap, n)


@pytest.mark.parametrize("extra", [-1, 0, 1])
def test_decoder_message_bound(extra):
    """The Python decoder's message buffer (MSG_MAX): a keyframe of MSG_MAX + 1 bytes is refused as
    too long; one of MSG_MAX or MSG_MAX - 1 bytes is read whole and judged by what it holds."""
    payload = bound_patterns(framelink.PAYLOAD_MAX + extra)[2]
    dec = framelink.Decoder(send_acks=False)
    evs = dec.feed(framelink.encode_message(framelink.MSG_KEYFRAME, 7, payload))
    assert len(evs) >= 1
    if extra > 0:
        assert evs == [{"event": "bad", "reason": "long"}]
    else:
        assert evs[0]["event"] in ("bad", "drop") and evs[0]["reason"] not in ("long", "framing"), evs[0]


def test_cobs_bounded_overhead():
    for n in (0, 1, 253, 254, 255, 508, 1000):
        for payload in (bytes(n), bytes([7]) * n, bytes(range(256)) * (n // 256) + bytes(n % 256)):
            enc = framelink.encode_message(framelink.MSG_PALETTE, 1, payload)
            assert b"\x00" not in enc[:-1] and enc[-1] == 0
            body = n + framelink.HEADER_BYTES + framelink.CRC_BYTES
            assert len(enc) <= body + 2 + body // 254


def test_training_makes_valid_tables(walk, tmp_path):
    """--train turns the symbol counts of streams into valid cumulative tables (every symbol
    possible, 4096 in all), in fl_tables.inc's format."""
    data = encode(walk, tmp_path)
    tables = framelink.train([data])
    assert sum(len(t) for t in tables) == framelink.T_END
    for t in tables:
        assert t[0] == 0 and t[-1] == 4096 and all(b > a for a, b in zip(t, t[1:]))
    text = framelink.format_tables(tables)
    assert text.count("\n") == len(tables) + 2


def test_cortex_m3_codes_the_same_bytes(walk, tmp_path):
    """The encoder built for the Cortex-M3 (word scan in assembly) codes the same bytes as on the
    host: tools/flbench_m3 under QEMU against fltool pictures."""
    if not shutil.which("qemu-system-arm") or not shutil.which("arm-none-eabi-gcc"):
        pytest.skip("qemu-system-arm or arm-none-eabi-gcc missing")
    _, raw, _ = walk
    bench = ROOT / "build" / "flbench-test"
    bench.mkdir(parents=True, exist_ok=True)
    (bench / "frames.raw").write_bytes(raw[:6 * 64000])
    subprocess.run(["make", "-s", "--no-print-directory", f"FLBENCH={bench.relative_to(ROOT)}",
                    str((bench / "m3.elf").relative_to(ROOT))], cwd=ROOT, check=True)
    proc = subprocess.run(["qemu-system-arm", "-M", "mps2-an385", "-nographic", "-monitor", "none", "-serial", "null",
                           "-semihosting-config", "enable=on,target=native", "-kernel", str(bench / "m3.elf")],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    host = run([program("fltool", sanitized=False), "digest", bench / "frames.raw"]).stdout
    said = [l for l in (proc.stdout + proc.stderr).splitlines() if l.startswith("stream bytes")]
    assert said == [host.strip()]
