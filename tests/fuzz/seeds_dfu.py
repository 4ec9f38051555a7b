#!/usr/bin/env python3
"""seeds_dfu.py OUTDIR - seeds for tests/fuzz/fuzz_dfu.c, in its input format.

Real images: build/flash --add-suffix makes DFU files of a few payloads (the start of
build/arm/firmware.bin when it has been built, and bytes made here) for 1209:0001 and
for any device. File-mode seeds are those files; suffix-mode seeds are their payloads
and ids (also with bLength, bcdDFU or the CRC edited, and cut short); device-mode
seeds are the requests build/flash makes to download such a payload (CLRSTATUS,
DNLOAD and GETSTATUS per block with the waits asked for, the zero-length DNLOAD,
manifestation, UPLOAD, USB reset, DETACH), also with the device not
manifestation-tolerant, a corrupted write, a power cut and an ABORT part way.
Run from the repository root. Standard library only."""
import os
import struct
import subprocess
import sys
import tempfile

FLASH = "build/flash"
FIRMWARE = "build/arm/firmware.bin"
MODE_FILE, MODE_SUFFIX, MODE_DEVICE = 0, 1, 2

# fuzz_dfu.c, run_device(): the configuration bytes and the ops
ATTR_DNLOAD, ATTR_UPLOAD, ATTR_TOLERANT = 0x01, 0x02, 0x04
TRANSFER_256 = 5                      # transfer_sizes[5]
PAGE_256, PAGE_64 = 4, 2              # page_sizes[]
FLASH_BLANK, FLASH_VALID = 0, 1
STAY_IN_DFU = 0x80
DETACH, DNLOAD, UPLOAD, GETSTATUS, CLRSTATUS, GETSTATE, ABORT = range(7)
LEN_0, LEN_STATUS, LEN_1, LEN_TRANSFER, LEN_TRANSFER_1, LEN_BYTE, LEN_16X, LEN_MAX = range(8)
POLL, BUS_RESET, POWER_CYCLE = 0xA0, 0xB0, 0xC0
FAULT_ERASE, FAULT_PROGRAM, FAULT_READ = 0, 1, 2


def req(r, length=LEN_0, v=0, extra=None):
    out = bytes([r | length << 4, v & 0xFF])
    if length in (LEN_BYTE, LEN_16X):
        out += bytes([extra])
    return out


def wait(ms):
    """Clock steps of up to 256 ms (((op & 31) + 1) * 8 each)."""
    out = b""
    while ms > 0:
        k = min(32, (ms + 7) // 8)
        out += bytes([0x80 | (k - 1)])
        ms -= k * 8
    return out


def fault(kind, corrupt, after):
    return bytes([0xC8 + kind + 3 * corrupt, after])


def device(attr, transfer, geometry, flash, clock=1000):
    return bytes([MODE_DEVICE, attr, transfer, geometry, flash]) + struct.pack("<I", clock)


def download(n, transfer=256, cut_after=None, extra_after=b"", from_error=True):
    """The requests of a download of n bytes, as build/flash makes them (dfu_host.c)."""
    ops = req(GETSTATUS, LEN_STATUS) + (req(CLRSTATUS) if from_error else b"")
    done, block = 0, 0
    while done < n:
        k = min(transfer, n - done)
        ops += req(DNLOAD, LEN_TRANSFER) if k == transfer else req(DNLOAD, LEN_BYTE, 0, k)
        ops += req(GETSTATUS, LEN_STATUS)  # -> dfuDNBUSY, bwPollTimeout
        ops += wait(5 + 20 * 2)            # program, erase a page and perhaps the valid mark
        ops += req(GETSTATUS, LEN_STATUS)  # -> dfuDNLOAD-IDLE
        done += k
        block += 1
        if cut_after is not None and block == cut_after:
            ops += extra_after
    ops += req(DNLOAD, LEN_0)              # end of the image -> dfuMANIFEST-SYNC
    ops += req(GETSTATUS, LEN_STATUS)      # -> dfuMANIFEST
    ops += wait(100)
    ops += req(GETSTATUS, LEN_STATUS)      # tolerant: -> dfuIDLE
    return ops


def run(*args):
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL)


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    outdir = sys.argv[1]
    os.makedirs(outdir, exist_ok=True)
    if not os.path.exists(FLASH):
        run("make", FLASH)

    payloads = {"byte": b"\x7f", "pattern": bytes((i * 37 + 11) & 0xFF for i in range(300))}
    vectors = bytearray()                 # looks like the start of a Cortex-M image
    for i in range(64):
        vectors += struct.pack("<I", 0x20004000 if i == 0 else 0x00000101 + 4 * i)
    payloads["vectors"] = bytes(vectors) + bytes(range(256)) * 2
    if os.path.exists(FIRMWARE):
        with open(FIRMWARE, "rb") as f:
            payloads["firmware"] = f.read(1500)

    images = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name, data in payloads.items():
            for ids, vid, pid, extra in (("1209-0001", "1209", "0001", []),
                                         ("any", "FFFF", "FFFF", ["--bcd-device", "0102"])):
                src, dst = os.path.join(tmp, name + ".bin"), os.path.join(tmp, name + ids + ".dfu")
                with open(src, "wb") as f:
                    f.write(data)
                run(FLASH, "--add-suffix", src, "--vid", vid, "--pid", pid, *extra, "-o", dst)
                with open(dst, "rb") as f:
                    images[name + "-" + ids] = f.read()

    seeds = {}
    for name, image in images.items():
        seeds["file-" + name] = bytes([MODE_FILE]) + image

    # suffix mode: the payload and ids of a real image; the harness appends the suffix
    def suffix_seed(image, edit=0, edits=(), cut=None):
        payload, s = image[:-16], image[-16:]
        bcd, pid, vid = struct.unpack_from("<HHH", s)
        out = bytes([MODE_SUFFIX]) + struct.pack("<HHHB", vid, pid, bcd, edit | len(edits) | (8 if cut else 0))
        for at, x in edits:
            out += bytes([at, x])
        if cut:
            out += bytes([cut])
        return out + payload

    pat = images["pattern-1209-0001"]
    seeds["suffix-pattern"] = suffix_seed(pat)
    seeds["suffix-vectors-any"] = suffix_seed(images["vectors-any"])
    seeds["suffix-blength-20-recrc"] = suffix_seed(pat, 4, [(4, 16 ^ 20)])      # bLength 20
    seeds["suffix-dfuse-recrc"] = suffix_seed(pat, 4, [(9, 0x1A)])            # bcdDFU 0x011A
    seeds["suffix-crc-flipped"] = suffix_seed(pat, 0, [(0, 0x80)])
    seeds["suffix-cut"] = suffix_seed(pat, 0, [], cut=3)
    seeds["suffix-empty"] = suffix_seed(images["byte-any"][1:])

    # device mode: 8 pages of 256 bytes (1792 bytes of application), 256-byte blocks
    n = min(len(payloads.get("firmware", payloads["vectors"])), 1792)
    geo = PAGE_256 | (8 - 2) << 3
    rw = ATTR_DNLOAD | ATTR_UPLOAD
    after = (req(UPLOAD, LEN_TRANSFER) * ((n + 255) // 256 + 1) + bytes([BUS_RESET]) +
             req(DETACH, LEN_0, 20) + bytes([BUS_RESET]) + req(GETSTATE, LEN_1))
    seeds["device-download"] = device(rw | ATTR_TOLERANT, TRANSFER_256, geo, FLASH_BLANK) + download(n) + after
    seeds["device-not-tolerant"] = (device(rw, TRANSFER_256, geo, FLASH_BLANK) + download(n)[:-2] +
                                    wait(100) + bytes([POLL, BUS_RESET]) + req(GETSTATUS, LEN_STATUS))
    seeds["device-over-valid-app"] = (device(rw | ATTR_TOLERANT, TRANSFER_256, geo, FLASH_VALID | 5 << 3 | STAY_IN_DFU)
                                      + download(300, from_error=False) + bytes([BUS_RESET]))
    seeds["device-corrupt-write"] = (device(rw | ATTR_TOLERANT, TRANSFER_256, geo, FLASH_BLANK) +
                                     fault(FAULT_PROGRAM, 1, 1) + download(n) + bytes([BUS_RESET]))
    seeds["device-power-cut"] = (device(rw | ATTR_TOLERANT, TRANSFER_256, geo, FLASH_VALID | 9 << 3) +
                                 req(DETACH, LEN_0, 50) + bytes([BUS_RESET]) +
                                 download(n, cut_after=2, extra_after=bytes([POWER_CYCLE]) + req(CLRSTATUS), from_error=False) +
                                 bytes([BUS_RESET]))
    seeds["device-abort"] = (device(rw | ATTR_TOLERANT, TRANSFER_256, geo, FLASH_BLANK) +
                             download(n, cut_after=1, extra_after=req(ABORT)) + req(GETSTATUS, LEN_STATUS))
    small = PAGE_64 | (4 - 2) << 3        # 4 pages of 64: 192 bytes of application, 64-byte blocks
    seeds["device-small-pages"] = (device(rw | ATTR_TOLERANT, 3, small, FLASH_BLANK) +
                                   download(150, transfer=64) + req(UPLOAD, LEN_TRANSFER) * 3)
    seeds["device-bad-config"] = device(0x80 | 3 << 4, TRANSFER_256, geo, FLASH_BLANK)

    for name, data in seeds.items():
        with open(os.path.join(outdir, "dfu-" + name + ".bin"), "wb") as f:
            f.write(data)
    print("%d seeds in %s" % (len(seeds), outdir))


if __name__ == "__main__":
    main()
