#!/usr/bin/python3
"""A USB DFU device emulated with umockdev, answered by the project's own bootloader
state machine (firmware/dfu/dfu_device.c, loaded from build/libdfudev.so), so that
build/flash runs unmodified against it, libusb and all.

    umockdev-wrapper /usr/bin/python3 tests/usbdfu_mock.py SCENARIO [options] -- build/flash ARGS

The emulator sets up a umockdev test bed with one or more USB devices (sysfs attributes,
the `descriptors` attribute libusb reads, a /dev/bus/usb node), attaches an ioctl handler
to each node that answers the usbfs ioctls libusb's Linux backend sends (capabilities,
URB submit/reap/discard, claim/release, reset...), starts the command as a child (it
inherits the emulated /sys and /dev through umockdev's preload), runs the GLib main loop
until the child exits, then prints a JSON summary on its last stdout line (the child's
own stdout and stderr are captured into the summary) and, with --out, writes device 0's
flash region to a file.

The flash region has the display board's application-slot geometry by default
(4,128,768 bytes in 4,096-byte pages, erased 0xFF). Time for the
state machine is the real monotonic clock in milliseconds: build/flash really waits
the bwPollTimeout the device asks for.

Re-enumeration: a USB reset (USBDEVFS_RESET) goes to dfu_dev_bus_reset(); the device
then leaves the bed (Testbed.remove_device) and comes back (add_from_string) with the
descriptors of its new state: run-time mode (interface protocol 1) when the state
machine says appIDLE/appDETACH, DFU mode (protocol 2) otherwise, and a new device
number, as a real device's re-enumeration gives.

Scenarios (faults touch device 0):
  ok          nothing goes wrong
  vanish      the device leaves the bed after the host has seen block --block K
              written (its GETSTATUS reaped); every later ioctl answers ENODEV
  stall       the device's region is small (--region-size, default 64 KiB), so the
              state machine itself stalls the first DNLOAD past its capacity
              (errADDRESS): a real stall, from the device's own check
  errwrite    the flash's program() fails from block K on: the state machine reports
              errWRITE in GETSTATUS
  timeout     from block K on the device stops answering: the URB carrying DNLOAD
              of block K is never completed (libusb times out and discards it)
  denied      the node is chmod 000 and the child runs as root without
              CAP_DAC_OVERRIDE/CAP_DAC_READ_SEARCH, so open() of the node fails with
              EACCES, as for a user without the udev rule
"""
import argparse
import ctypes
import errno
import hashlib
import json
import os
import struct
import subprocess
import sys
import time
from pathlib import Path

import gi

gi.require_version("UMockdev", "1.0")
from gi.repository import GLib, UMockdev  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent

# usbfs ioctls (linux/usbdevice_fs.h, x86-64 sizes)
USBDEVFS = {
    0xC0185500: "CONTROL", 0x80085504: "SETINTERFACE", 0x80045505: "SETCONFIGURATION",
    0x41045508: "GETDRIVER", 0x8038550A: "SUBMITURB", 0x0000550B: "DISCARDURB",
    0x4008550C: "REAPURB", 0x4008550D: "REAPURBNDELAY", 0x8004550F: "CLAIMINTERFACE",
    0x80045510: "RELEASEINTERFACE", 0x40085511: "CONNECTINFO", 0xC0105512: "IOCTL",
    0x00005514: "RESET", 0x80045515: "CLEAR_HALT", 0x00005516: "DISCONNECT",
    0x00005517: "CONNECT", 0x8004551A: "GET_CAPABILITIES", 0x8108551B: "DISCONNECT_CLAIM",
    0x4004551E: "DROP_PRIVILEGES", 0x0000551F: "GET_SPEED",
}
URB_SIZE = 56            # struct usbdevfs_urb on x86-64
URB_TYPE_CONTROL = 2
# what this emulated usbfs offers: zero packets, bulk continuation, no packet size
# limit (not DISCONNECT_CLAIM, so libusb asks GETDRIVER before claiming)
CAPS = 0x01 | 0x02 | 0x04

STATE_NAMES = ["appIDLE", "appDETACH", "dfuIDLE", "dfuDNLOAD-SYNC", "dfuDNBUSY",
               "dfuDNLOAD-IDLE", "dfuMANIFEST-SYNC", "dfuMANIFEST", "dfuMANIFEST-WAIT-RESET",
               "dfuUPLOAD-IDLE", "dfuERROR"]
STATUS_NAMES = ["OK", "errTARGET", "errFILE", "errWRITE", "errERASE", "errCHECK_ERASED",
                "errPROG", "errVERIFY", "errADDRESS", "errNOTDONE", "errFIRMWARE", "errVENDOR",
                "errUSBR", "errPOR", "errUNKNOWN", "errSTALLEDPKT"]
REQ_NAMES = ["DETACH", "DNLOAD", "UPLOAD", "GETSTATUS", "CLRSTATUS", "GETSTATE", "ABORT"]

SLOT_SIZE = 4_128_768    # the display board's application slot (notes: layout)
PAGE_SIZE = 4096
ATTR_DNLOAD, ATTR_UPLOAD, ATTR_TOLERANT = 0x01, 0x02, 0x04

# ---- the state machine through ctypes ------------------------------------------------

ERASE_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_uint32)
PROGRAM_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_uint32, ctypes.c_void_p,
                              ctypes.c_uint32)
READ_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_uint32, ctypes.c_void_p,
                           ctypes.c_uint32)


class DfuConfig(ctypes.Structure):
    _fields_ = [("attributes", ctypes.c_uint8), ("transfer_size", ctypes.c_uint16),
                ("detach_timeout_ms", ctypes.c_uint16), ("program_ms", ctypes.c_uint32),
                ("erase_ms", ctypes.c_uint32), ("manifest_ms", ctypes.c_uint32)]


class DfuFlash(ctypes.Structure):
    _fields_ = [("ctx", ctypes.c_void_p), ("size", ctypes.c_uint32), ("page_size", ctypes.c_uint32),
                ("erase", ERASE_FN), ("program", PROGRAM_FN), ("read", READ_FN)]


class DfuDev(ctypes.Structure):
    _fields_ = [("cfg", DfuConfig), ("flash", DfuFlash), ("state", ctypes.c_uint8),
                ("status", ctypes.c_uint8), ("work", ctypes.c_uint8), ("manifested", ctypes.c_uint8),
                ("invalidated", ctypes.c_uint8), ("detach_pending", ctypes.c_uint8),
                ("next_block", ctypes.c_uint16), ("block_len", ctypes.c_uint16),
                ("busy_until", ctypes.c_uint32), ("poll_ms", ctypes.c_uint32),
                ("received", ctypes.c_uint32), ("erased_end", ctypes.c_uint32),
                ("crc", ctypes.c_uint32), ("upload_pos", ctypes.c_uint32),
                ("upload_len", ctypes.c_uint32), ("block", ctypes.c_uint8 * 4096)]


class AppInfo(ctypes.Structure):
    _fields_ = [("length", ctypes.c_uint32), ("crc", ctypes.c_uint32)]


def load_lib(path):
    lib = ctypes.CDLL(str(path))
    lib.dfu_dev_init.argtypes = [ctypes.POINTER(DfuDev), ctypes.POINTER(DfuConfig),
                                 ctypes.POINTER(DfuFlash), ctypes.c_int, ctypes.c_uint32]
    lib.dfu_dev_request.argtypes = [ctypes.POINTER(DfuDev), ctypes.c_uint32, ctypes.c_uint8,
                                    ctypes.c_uint8, ctypes.c_uint16, ctypes.c_uint16,
                                    ctypes.c_void_p, ctypes.POINTER(ctypes.c_uint16)]
    lib.dfu_dev_poll.argtypes = [ctypes.POINTER(DfuDev), ctypes.c_uint32]
    lib.dfu_dev_bus_reset.argtypes = [ctypes.POINTER(DfuDev), ctypes.c_uint32]
    lib.dfu_app_check.argtypes = [ctypes.POINTER(DfuFlash), ctypes.POINTER(AppInfo)]
    lib.dfu_app_capacity.argtypes = [ctypes.POINTER(DfuFlash)]
    lib.dfu_app_capacity.restype = ctypes.c_uint32
    return lib


def now_ms():
    return int(time.monotonic() * 1000) & 0xFFFFFFFF


class RamFlash:
    """The device's flash: a RAM region, erased 0xFF, programming only clears bits.
    fail_program_from: the byte offset from which program() fails (errWRITE)."""

    def __init__(self, size, page_size):
        self.size, self.page_size = size, page_size
        self.mem = bytearray(b"\xff" * size)
        self._cbuf = (ctypes.c_char * size).from_buffer(self.mem)
        self.base = ctypes.addressof(self._cbuf)
        self.fail_program_from = None
        self.erases = self.programs = 0
        self.log = []   # ["erase", offset] and ["program", offset, n], in the order done
        # keep the callbacks alive as long as the flash
        self.cb = (ERASE_FN(self._erase), PROGRAM_FN(self._program), READ_FN(self._read))
        self.desc = DfuFlash(None, size, page_size, *self.cb)

    def _erase(self, _ctx, off):
        if off % self.page_size or off >= self.size:
            return -1
        self.erases += 1
        self.log.append(["erase", off])
        self.mem[off:off + self.page_size] = b"\xff" * self.page_size
        return 0

    def _program(self, _ctx, off, src, n):
        if off > self.size or n > self.size - off:
            return -1
        if self.fail_program_from is not None and off + n > self.fail_program_from:
            return -1
        self.programs += 1
        self.log.append(["program", off, n])
        new = int.from_bytes(ctypes.string_at(src, n), "little")
        old = int.from_bytes(self.mem[off:off + n], "little")
        self.mem[off:off + n] = (old & new).to_bytes(n, "little")
        return 0

    def _read(self, _ctx, off, dst, n):
        if off > self.size or n > self.size - off:
            return -1
        ctypes.memmove(dst, self.base + off, n)
        return 0


# ---- descriptors ------------------------------------------------------------------------

def device_descriptor(vid, pid, bcd_device=0x0100):
    return struct.pack("<BBHBBBBHHHBBBB", 18, 1, 0x0200, 0, 0, 0, 64, vid, pid, bcd_device,
                       1, 2, 3, 1)


def config_descriptor(protocol, attributes, detach_ms, transfer_size):
    """One configuration, one interface: DFU class 0xFE/0x01 in run-time (1) or DFU
    mode (2), with its 9-byte functional descriptor."""
    intf = struct.pack("<BBBBBBBBB", 9, 4, 0, 0, 0, 0xFE, 0x01, protocol, 4)
    func = struct.pack("<BBBHHH", 9, 0x21, attributes, detach_ms, transfer_size, 0x0110)
    total = 9 + len(intf) + len(func)
    return struct.pack("<BBHBBBBB", 9, 2, total, 1, 1, 0, 0x80, 50) + intf + func


def string_descriptor(text):
    raw = text.encode("utf-16-le")
    return bytes([2 + len(raw), 3]) + raw


# ---- one emulated device --------------------------------------------------------------

class Device:
    def __init__(self, mock, index, serial, vid, pid, region_size, page_size, tolerant=True):
        self.mock, self.index, self.serial, self.vid, self.pid = mock, index, serial, vid, pid
        self.port = index + 1
        self.devnum = 2 + index
        self.flash = RamFlash(region_size, page_size)
        self.cfg = DfuConfig(ATTR_DNLOAD | ATTR_UPLOAD | (ATTR_TOLERANT if tolerant else 0), 4096, 1000, 5, 20,
                             100)
        self.dev = DfuDev()
        self.lib = mock.lib
        if self.lib.dfu_dev_init(ctypes.byref(self.dev), ctypes.byref(self.cfg),
                                 ctypes.byref(self.flash.desc), 0, now_ms()) != 0:
            raise SystemExit("usbdfu_mock: dfu_dev_init refused the region geometry")
        self.syspath = None
        self.handler = None
        self.present = False
        self.vanished = False
        self.states_seen = []
        self.requests = {name: 0 for name in REQ_NAMES}
        self.stalls = self.resets = self.enumerations = 0
        self.blocks_done = 0         # DNLOAD blocks the host saw written (GETSTATUS -> DNLOAD-IDLE)
        self.getstatus = []          # each GETSTATUS answered: [ms since the first, bState, bwPollTimeout]
        self.t0 = None
        self.note_state()

    # state bookkeeping
    def state(self):
        return self.dev.state

    def note_state(self):
        name = STATE_NAMES[self.dev.state] if self.dev.state < len(STATE_NAMES) else str(self.dev.state)
        if not self.states_seen or self.states_seen[-1] != name:
            self.states_seen.append(name)

    def runtime_mode(self):
        return self.dev.state in (0, 1)

    @property
    def node(self):
        return f"/dev/bus/usb/001/{self.devnum:03d}"

    # enumeration
    def plug(self):
        self.enumerations += 1
        tb = self.mock.testbed
        name = f"1-{self.port}"
        protocol = 1 if self.runtime_mode() else 2
        # the descriptors go in with the record: libusb reads them on the "add" uevent
        # that add_from_string sends, before a later set_attribute could land
        descriptors = device_descriptor(self.vid, self.pid) + config_descriptor(
            protocol, self.cfg.attributes, self.cfg.detach_timeout_ms, self.cfg.transfer_size)
        record = "\n".join([
            f"P: /devices/usb1/{name}",
            f"N: bus/usb/001/{self.devnum:03d}",
            "E: SUBSYSTEM=usb", "E: DEVTYPE=usb_device", f"E: DEVNAME={self.node}",
            "E: BUSNUM=001", f"E: DEVNUM={self.devnum:03d}",
            f"E: PRODUCT={self.vid:x}/{self.pid:x}/100",
            "A: busnum=1", f"A: devnum={self.devnum}",
            f"A: idVendor={self.vid:04x}", f"A: idProduct={self.pid:04x}",
            "A: speed=12", "A: bConfigurationValue=1", "A: bNumConfigurations=1",
            f"A: serial={self.serial}",
            f"A: devpath={self.port}",
            f"A: dev=189:{self.devnum - 1}", f"H: descriptors={descriptors.hex().upper()}", ""])
        tb.add_from_string(record)
        self.syspath = f"/sys/devices/usb1/{name}"
        self.handler = UsbfsHandler(self)
        tb.attach_ioctl(self.node, self.handler)
        self.present = True
        self.mock.log(f"device {self.index} plugged in at {self.node} "
                      f"({'run-time' if protocol == 1 else 'DFU'} mode)")

    def unplug(self):
        if not self.present:
            return
        self.present = False
        if self.handler:
            self.handler.gone = True
        # remove_device() alone sends no uevent: libusb (udev monitor) would keep the
        # old device in its list
        self.mock.testbed.uevent(self.syspath, "remove")
        self.mock.testbed.remove_device(self.syspath)
        self.mock.log(f"device {self.index} unplugged from {self.node}")

    def reenumerate(self):
        """After a reset: leave the bus, come back as the state machine's new self."""
        self.unplug()
        self.devnum += 10
        self.plug()

    # the state machine
    def class_request(self, rtype, req, value, length, data):
        """data: a bytearray of length bytes (OUT: what the host sent; IN: filled)."""
        if req < len(REQ_NAMES):
            self.requests[REQ_NAMES[req]] += 1
        buf = (ctypes.c_uint8 * max(length, 1)).from_buffer_copy(bytes(data) + b"\0")
        actual = ctypes.c_uint16(0)
        res = self.lib.dfu_dev_request(ctypes.byref(self.dev), now_ms(), rtype, req, value, length,
                                       buf, ctypes.byref(actual))
        self.note_state()
        if res != 0:
            self.stalls += 1
            return None
        if req == 3 and actual.value >= 6:
            t = now_ms()
            self.t0 = t if self.t0 is None else self.t0
            reply = bytes(buf)
            self.getstatus.append([(t - self.t0) & 0xFFFFFFFF,
                                   STATE_NAMES[reply[4]] if reply[4] < len(STATE_NAMES) else str(reply[4]),
                                   reply[1] | reply[2] << 8 | reply[3] << 16])
        if rtype & 0x80:
            return bytes(buf)[:actual.value]
        return b""

    def bus_reset(self):
        self.resets += 1
        self.lib.dfu_dev_bus_reset(ctypes.byref(self.dev), now_ms())
        self.note_state()

    def summary(self):
        info = AppInfo()
        valid = self.lib.dfu_app_check(ctypes.byref(self.flash.desc), ctypes.byref(info))
        return {
            "serial": self.serial, "states_seen": self.states_seen,
            "state": STATE_NAMES[self.dev.state], "status": STATUS_NAMES[self.dev.status],
            "requests": self.requests, "stalls": self.stalls, "resets": self.resets,
            "enumerations": self.enumerations, "blocks_written": self.blocks_done,
            "region_size": self.flash.size, "page_size": self.flash.page_size,
            "app_valid": bool(valid), "app_length": info.length, "app_crc": info.crc,
            "region_sha256": hashlib.sha256(self.flash.mem).hexdigest(),
            "erases": self.flash.erases, "programs": self.flash.programs,
            "flash_log": self.flash.log, "getstatus": self.getstatus,
            "manifest_ms": self.cfg.manifest_ms, "manifest_tolerant": bool(self.cfg.attributes & ATTR_TOLERANT),
        }


class UsbfsHandler(UMockdev.IoctlBase):
    """usbfs as the kernel offers it to libusb, for one device node."""

    def __init__(self, device):
        super().__init__()
        self.d = device
        self.mock = device.mock
        self.done = []          # completed URBs (IoctlData), waiting to be reaped
        self.held = []          # URBs the device never answers (timeout scenario)
        self.gone = False

    def do_handle_ioctl(self, client):
        req = client.get_request()
        name = USBDEVFS.get(req, f"0x{req:08x}")
        self.mock.count_ioctl(name)
        try:
            res, err = self.dispatch(name, client)
        except Exception as exc:        # a bug here must not hang the client
            self.mock.log(f"handler error in {name}: {exc!r}")
            res, err = -1, errno.EIO
        client.complete(res, err)
        return True

    def dispatch(self, name, client):
        d = self.d
        if d.vanished or self.gone and name != "REAPURBNDELAY":
            return -1, errno.ENODEV
        arg = client.get_arg()
        if name == "GET_CAPABILITIES":
            arg.resolve(0, 4).update(0, struct.pack("<I", CAPS))
            return 0, 0
        if name == "GETDRIVER":
            return -1, errno.ENODATA          # no kernel driver bound
        if name in ("CLAIMINTERFACE", "RELEASEINTERFACE", "SETINTERFACE", "CLEAR_HALT",
                    "DISCONNECT_CLAIM", "SETCONFIGURATION", "IOCTL"):
            # IOCTL: libusb's USBDEVFS_CONNECT on release (auto-detach): no kernel
            # driver to give the interface back to
            return 0, 0
        if name == "GET_SPEED":
            return 2, 0                       # USB_SPEED_FULL
        if name == "SUBMITURB":
            return self.submit(arg.resolve(0, URB_SIZE))
        if name in ("REAPURBNDELAY", "REAPURB"):
            return self.reap(arg)
        if name == "DISCARDURB":
            return self.discard(arg)
        if name == "RESET":
            return self.reset()
        self.mock.unhandled.append(name)
        return -1, errno.ENOTTY

    # URBs: control transfers on endpoint 0 only (a DFU device has no other endpoint)
    def submit(self, urb):
        data = bytes(urb.retrieve())
        utype, endpoint = data[0], data[1]
        length = struct.unpack_from("<i", data, 24)[0]
        if utype != URB_TYPE_CONTROL or endpoint not in (0x00, 0x80) or length < 8:
            return -1, errno.EINVAL
        buf = urb.resolve(16, length)
        raw = bytes(buf.retrieve())
        rtype, req, value, index, wlen = struct.unpack_from("<BBHHH", raw, 0)
        if self.mock.hold_request(self.d, rtype, req, value, wlen):
            self.held.append(urb)
            return 0, 0
        out = raw[8:8 + wlen]
        status, reply = self.control(rtype, req, value, index, wlen, out)
        actual = 0
        if status == 0:
            if rtype & 0x80:
                buf.update(8, reply)
                actual = len(reply)
            else:
                actual = wlen
        urb.update(4, struct.pack("<i", status))
        urb.update(28, struct.pack("<i", actual))
        self.done.append(urb)
        return 0, 0

    def control(self, rtype, req, value, index, wlen, out):
        """Returns (URB status, IN data): 0 or -EPIPE (a stall)."""
        d = self.d
        if (rtype & 0x60) == 0x20:                      # class request to the DFU interface
            if (rtype & 0x1F) != 1 or index != 0:
                return -errno.EPIPE, b""
            reply = d.class_request(rtype, req, value, wlen,
                                    bytearray(out) if not rtype & 0x80 else bytearray(wlen))
            if reply is None:
                return -errno.EPIPE, b""
            self.mock.after_request(d, req, reply)
            return 0, reply
        if rtype == 0x80 and req == 6:                  # GET_DESCRIPTOR
            kind, idx = value >> 8, value & 0xFF
            if kind == 1:
                desc = device_descriptor(d.vid, d.pid)
            elif kind == 2:
                desc = config_descriptor(1 if d.runtime_mode() else 2, d.cfg.attributes,
                                         d.cfg.detach_timeout_ms, d.cfg.transfer_size)
            elif kind == 3:
                strings = {0: b"\x04\x03\x09\x04", 1: string_descriptor("bspvga"),
                           2: string_descriptor("display board"), 3: string_descriptor(d.serial),
                           4: string_descriptor("DFU")}
                desc = strings.get(idx)
                if desc is None:
                    return -errno.EPIPE, b""
            else:
                return -errno.EPIPE, b""
            return 0, desc[:wlen]
        if rtype == 0x80 and req == 0:                  # GET_STATUS (device)
            return 0, b"\x00\x00"[:wlen]
        return -errno.EPIPE, b""

    def reap(self, arg):
        if not self.done:
            if self.gone or self.d.vanished:
                return -1, errno.ENODEV
            return -1, errno.EAGAIN
        urb = self.done.pop(0)
        arg.resolve(0, 8).set_ptr(0, urb)
        self.mock.after_reap(self.d)
        return 0, 0

    def discard(self, arg):
        addr = struct.unpack("<Q", bytes(arg.retrieve()))[0]   # _IO: the URB's address itself
        for i, urb in enumerate(self.held):
            if urb.client_addr == addr:
                del self.held[i]
                urb.update(4, struct.pack("<i", -errno.ENOENT))
                urb.update(28, struct.pack("<i", 0))
                self.done.append(urb)
                return 0, 0
        return -1, errno.EINVAL

    def reset(self):
        """USB reset: the state machine decides what it becomes; the device then
        leaves the bus and comes back (re-enumerates) a little later."""
        d = self.d
        d.bus_reset()
        self.gone = True
        GLib.timeout_add(30, lambda: (d.unplug(), False)[1])
        GLib.timeout_add(self.mock.reenum_ms, lambda: (d.reenumerate(), False)[1])
        return 0, 0


# ---- the test bed and the child ----------------------------------------------------------

class Mock:
    def __init__(self, args):
        self.args = args
        self.lib = load_lib(args.lib)
        self.testbed = UMockdev.Testbed.new()
        self.ioctls = {}
        self.unhandled = []
        self.events = []
        self.reenum_ms = args.reenum_ms
        self.t0 = time.monotonic()
        serials = args.serials.split(",")
        region = args.region_size or (64 * 1024 if args.scenario == "stall" else SLOT_SIZE)
        self.devices = [Device(self, i, sn, args.vid, args.pid, region, PAGE_SIZE, not args.not_tolerant)
                        for i, sn in enumerate(serials)]
        self.target = self.devices[0]
        if args.scenario == "errwrite":
            self.target.flash.fail_program_from = args.block * 4096
        for d in self.devices:
            d.plug()

    def log(self, text):
        self.events.append(f"{time.monotonic() - self.t0:7.3f} {text}")

    def count_ioctl(self, name):
        self.ioctls[name] = self.ioctls.get(name, 0) + 1

    def hold_request(self, d, rtype, req, value, wlen):
        """timeout: from DNLOAD block K on, the device does not answer at all."""
        if self.args.scenario != "timeout" or d is not self.target:
            return False
        if getattr(self, "hung", False):
            return True
        if rtype == 0x21 and req == 1 and wlen and value >= self.args.block:
            self.hung = True
            self.log(f"device {d.index} stops answering at DNLOAD block {value}")
            return True
        return False

    def after_request(self, d, req, reply):
        if req == 3 and len(reply) >= 5 and reply[4] == 5 and d.requests["DNLOAD"]:
            d.blocks_done = d.requests["DNLOAD"]   # block written, host sees dfuDNLOAD-IDLE

    def after_reap(self, d):
        if (self.args.scenario == "vanish" and d is self.target and not d.vanished
                and d.blocks_done >= self.args.block):
            d.vanished = True
            self.log(f"device {d.index} vanishes after block {d.blocks_done}")
            d.unplug()

    def child_preexec(self):
        if self.args.scenario == "denied":
            # root passes file permission checks by CAP_DAC_OVERRIDE: without it (and
            # without CAP_DAC_READ_SEARCH) the 000 node cannot be opened, as for a user
            # without the udev rule. PR_CAPBSET_DROP = 24; CAP_DAC_OVERRIDE 1, _READ_SEARCH 2.
            libc = ctypes.CDLL(None, use_errno=True)
            for cap in (1, 2):
                libc.prctl(24, cap, 0, 0, 0)

    def run(self, cmd):
        if self.args.scenario == "denied":
            for d in self.devices:
                os.chmod(os.path.join(self.testbed.get_root_dir(), d.node.lstrip("/")), 0)
        # the test bed set UMOCKDEV_DIR in the C environment, which os.environ, read at
        # start-up, does not see
        env = dict(os.environ, UMOCKDEV_DIR=self.testbed.get_root_dir())
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env,
                                preexec_fn=self.child_preexec)
        out_chunks, err_chunks = [], []
        ctx = GLib.MainContext.default()
        os.set_blocking(proc.stdout.fileno(), False)
        os.set_blocking(proc.stderr.fileno(), False)

        def drain():
            for f, chunks in ((proc.stdout, out_chunks), (proc.stderr, err_chunks)):
                try:
                    b = f.read()
                except (BlockingIOError, TypeError):
                    b = None
                if b:
                    chunks.append(b)

        deadline = time.monotonic() + self.args.limit
        while proc.poll() is None:
            while ctx.pending():
                ctx.iteration(False)
            drain()
            if time.monotonic() > deadline:
                proc.kill()
                self.log("child killed: over the time limit")
                break
            time.sleep(0.0005)
        proc.wait()
        while ctx.pending():
            ctx.iteration(False)
        drain()
        return proc.returncode, b"".join(out_chunks).decode(errors="replace"), \
            b"".join(err_chunks).decode(errors="replace")


def main(argv):
    if "--" not in argv:
        raise SystemExit("usage: usbdfu_mock.py SCENARIO [options] -- COMMAND ARGS")
    cut = argv.index("--")
    ap = argparse.ArgumentParser(prog="usbdfu_mock.py")
    ap.add_argument("scenario", choices=["ok", "vanish", "stall", "errwrite", "timeout", "denied"])
    ap.add_argument("--block", type=int, default=3, help="K for vanish/errwrite/timeout")
    ap.add_argument("--serials", default="BSPVGA-0001", help="one device per serial, comma-separated")
    ap.add_argument("--vid", type=lambda s: int(s, 16), default=0x1209)
    ap.add_argument("--pid", type=lambda s: int(s, 16), default=0x0001)
    ap.add_argument("--region-size", type=int, default=0)
    ap.add_argument("--not-tolerant", action="store_true",
                    help="the devices are not manifestation-tolerant (bmAttributes bit 2 clear)")
    ap.add_argument("--reenum-ms", type=int, default=300, help="how long a re-enumeration takes")
    ap.add_argument("--out", help="write device 0's flash region here")
    ap.add_argument("--lib", default=str(ROOT / "build" / "libdfudev.so"))
    ap.add_argument("--limit", type=float, default=120, help="seconds before the child is killed")
    args = ap.parse_args(argv[:cut])
    cmd = argv[cut + 1:]
    if not os.environ.get("LD_PRELOAD", "").count("umockdev"):
        raise SystemExit("usbdfu_mock.py: run me under umockdev-wrapper")
    mock = Mock(args)
    rc, out, err = mock.run(cmd)
    if args.out:
        Path(args.out).write_bytes(mock.devices[0].flash.mem)
    summary = {"scenario": args.scenario, "command": cmd, "exit": rc, "stdout": out, "stderr": err,
               "devices": [d.summary() for d in mock.devices], "ioctls": mock.ioctls,
               "unhandled_ioctls": sorted(set(mock.unhandled)), "events": mock.events}
    print(json.dumps(summary))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
