# ram_need.awk - the RAM of a Cortex-M3 firmware image and its parts, from
# arm-none-eabi-nm's listing of it (symbols of hal/mps2/mps2.ld); mk/mps2.mk.
#
#   arm-none-eabi-nm firmware.elf | awk -v have=BYTES -v scene=SPEC -f tools/ram_need.awk
#       the refusal of a build that does not fit, one line:
#       "firmware: SPEC needs N bytes of RAM (...); the board has BYTES (RAM_BYTES)"
#   ... -v report=1: "mps2: RAM N of BYTES bytes (...)"

function commas(n,    s) {
    s = sprintf("%d", n)
    while (s ~ /[0-9][0-9][0-9][0-9]/) sub(/[0-9][0-9][0-9]([,]|$)/, ",&", s)
    return s
}

# the parts: stack, display (pages, palette, display start), .data + .bss (with
# the alignment before them), .work
function parts() {
    return sprintf("stack %s, VRAM pages and palette %s, data and bss %s, work area %s",
                   commas(v["__stack_top"] - v["__stack_limit"]), commas(v["__display_end"] - v["mps2_vram0"]),
                   commas(v["__work_start"] - v["__display_end"]), commas(v["__work_end"] - v["__work_start"]))
}

# nm's addresses are hex; mawk has no strtonum
function hex(h,    i, n) {
    n = 0
    h = tolower(h)
    for (i = 1; i <= length(h); i++) n = n * 16 + index("0123456789abcdef", substr(h, i, 1)) - 1
    return n
}

NF == 3 { v[$3] = hex($1) }

END {
    need = v["__ram_need"]
    if (report)
        printf "mps2: RAM %s of %s bytes (%s)\n", commas(need), commas(have), parts()
    else
        printf "firmware: %s needs %s bytes of RAM (%s); the board has %s (RAM_BYTES)\n", scene, commas(need),
               parts(), commas(have)
}
