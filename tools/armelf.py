"""The Cortex-M firmware's ELF files read with the Arm binutils (arm-none-eabi-nm, -size):
symbol addresses and sizes, section sizes. Used by the benches and the tests."""
import subprocess


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
