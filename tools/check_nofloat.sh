#!/usr/bin/env bash
# check_nofloat.sh FILE... - fail if any firmware/HAL source can use floating point.
# NOFLOAT_INC: more -I options for the Cortex-M3 compile (a target's headers).
#  1. no 'float' or 'double' token in the code (comments removed by the preprocessor);
#  2. (the host build compiles these files with -mgeneral-regs-only, which rejects
#     floating-point arithmetic that survives optimisation);
#  3. a Cortex-M3 soft-float compile of every freestanding file, linked together,
#     may not need any soft-float helper (__aeabi_f*, __aeabi_d*, conversions);
#     the PC kernel's own files (hal/pcvga, x86 port I/O) instead compile for
#     i386 with -mgeneral-regs-only (any x87/SSE use is an error) and may not
#     need libgcc's float helpers either.
set -uo pipefail
cd "$(dirname "$0")/.."
fail=0
arm_srcs=()
x86_srcs=()
FLOAT_HELPERS='^__(add|sub|mul|div|neg|fix|fixuns|float|floatun|extend|trunc|cmp|eq|ne|lt|le|gt|ge|unord|pow|powi)[sdtx]f[0-9]?$'
for f in "$@"; do
  [ -f "$f" ] || continue
  hits=$(gcc -fpreprocessed -dD -E -P "$f" 2>/dev/null | grep -nwE 'float|double|_Float[0-9]+x?|__float128')
  if [ -n "$hits" ]; then
    echo "nofloat: $f uses floating point:"; echo "$hits" | sed 's/^/    /'
    fail=1
  fi
  case "$f" in hal/sdl/*) ;; hal/pcvga/*|*hal_pcvga_*) x86_srcs+=("$f") ;; *) arm_srcs+=("$f") ;; esac
done
if command -v arm-none-eabi-gcc >/dev/null; then
  tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
  objs=()
  for f in "${arm_srcs[@]}"; do
    o="$tmp/$(echo "$f" | tr '/' '_').o"
    if ! arm-none-eabi-gcc -std=c11 -O2 -mcpu=cortex-m3 -mthumb -mfloat-abi=soft -ffreestanding \
         -fno-strict-aliasing -fno-tree-loop-distribute-patterns -Ifirmware -Ihal -Ihal/null -Ihal/bare ${NOFLOAT_INC:-} -c "$f" -o "$o"; then
      echo "nofloat: $f does not compile for Cortex-M3"; fail=1; continue
    fi
    objs+=("$o")
  done
  if [ ${#objs[@]} -gt 0 ]; then
    arm-none-eabi-ld -r -o "$tmp/all.o" "${objs[@]}" || fail=1
    helpers=$(arm-none-eabi-nm -u "$tmp/all.o" | awk '{print $2}' |
      grep -E '^__aeabi_([fd]|[a-z]*2[fd]$)|'"$FLOAT_HELPERS")
    if [ -n "$helpers" ]; then
      echo "nofloat: the Cortex-M3 soft-float link needs floating-point helpers:"; echo "$helpers" | sed 's/^/    /'
      fail=1
    fi
  fi
else
  echo "nofloat: arm-none-eabi-gcc missing (run make deps)"; fail=1
fi
if [ ${#x86_srcs[@]} -gt 0 ]; then
  tmp86=$(mktemp -d)
  objs86=()
  for f in "${x86_srcs[@]}"; do
    o="$tmp86/$(echo "$f" | tr '/' '_').o"
    if ! gcc -std=c11 -O2 -m32 -ffreestanding -mgeneral-regs-only -fno-pic -fno-strict-aliasing \
         -fno-tree-loop-distribute-patterns -Ifirmware -Ihal -Ihal/bare -Ihal/pcvga -c "$f" -o "$o"; then
      echo "nofloat: $f does not compile for i386 without floating-point registers"; fail=1; continue
    fi
    objs86+=("$o")
  done
  if [ ${#objs86[@]} -gt 0 ]; then
    helpers=$(ld -m elf_i386 -r -o "$tmp86/all.o" "${objs86[@]}" && nm -u "$tmp86/all.o" | awk '{print $2}' | grep -E "$FLOAT_HELPERS")
    if [ -n "$helpers" ]; then
      echo "nofloat: the i386 link needs floating-point helpers:"; echo "$helpers" | sed 's/^/    /'
      fail=1
    fi
  fi
  rm -rf "$tmp86"
fi
[ $fail -eq 0 ] && echo "nofloat: ok (${#arm_srcs[@]} freestanding files, Cortex-M3 soft-float link clean${x86_srcs:+; ${#x86_srcs[@]} i386 files without float registers or helpers})"
exit $fail
