"""The Cortex-M firmware's ELF files read with the Arm binutils (arm-none-eabi-nm, -size):
symbol addresses and sizes, section sizes. Used by the benches and the tests."""
import struct
import subprocess
import zlib


def symbols(elf):
    """{name: (address, size)} of the ELF's defined symbols (size 0 where nm gives none)."""
    out = subprocess.run(["arm-none-eabi-nm", "-S", str(elf)], capture_output=True, text=True, check=True).stdout
    syms = {}
    for line in out.splitlines():
        parts = line.split()
        if len(parts) == 4:
            syms[parts[3]] = (int(parts[0], 16), int(parts[1], 16))
        elif len(parts) == 3:
            syms[parts[2]] = (int(parts[0], 16), 0)
    return syms


def symbol(elf, name):
    """The address of name in elf; LookupError naming both when it is not there."""
    syms = symbols(elf)
    if name not in syms:
        raise LookupError(f"{name} not in {elf}")
    return syms[name][0]


def sections(elf):
    """{section name: size in bytes}, as arm-none-eabi-size -A lists them."""
    out = subprocess.run(["arm-none-eabi-size", "-A", str(elf)], capture_output=True, text=True, check=True).stdout
    return {l.split()[0]: int(l.split()[1]) for l in out.splitlines() if l.startswith(".")}


def read(elf, address, size):
    """size bytes of elf's loaded image at address (from the PT_LOAD segment holding them): what the
    firmware finds there at start, for data in flash (constants)."""
    data = open(elf, "rb").read()
    if data[:4] != b"\x7fELF" or data[4] != 1 or data[5] != 1:
        raise ValueError(f"{elf}: not a 32-bit little-endian ELF file")
    phoff, = struct.unpack_from("<I", data, 28)
    phentsize, phnum = struct.unpack_from("<HH", data, 42)
    for i in range(phnum):
        ptype, offset, vaddr, _paddr, filesz = struct.unpack_from("<5I", data, phoff + i * phentsize)
        if ptype == 1 and vaddr <= address and address + size <= vaddr + filesz:
            return data[offset + address - vaddr:offset + address - vaddr + size]
    raise LookupError(f"{elf}: nothing loaded at {address:#x}+{size}")


def built_in_scene(elf):
    """(name, blob CRC-32) of the scene built into a firmware ELF (mk/mps2.mk's fw_scene_name and
    fw_scene, the blob read in place from flash)."""
    syms = symbols(elf)
    name_at, name_size = syms["fw_scene_name"]
    blob_at = syms["fw_scene"][0]
    blob_size, = struct.unpack("<I", read(elf, syms["fw_scene_len"][0], 4))
    name = read(elf, name_at, name_size).split(b"\0", 1)[0].decode("utf-8", "replace")
    return name, zlib.crc32(read(elf, blob_at, blob_size))
