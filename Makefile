# One entry point. `make help` lists the targets.
SHELL   := /bin/bash
CC      ?= gcc
BUILD   := build
GEN     := $(BUILD)/gen
VENV    := $(BUILD)/venv
PY      := $(VENV)/bin/python
ARMCC   := arm-none-eabi-gcc

SDL_CFLAGS := $(shell sdl2-config --cflags 2>/dev/null)
SDL_LIBS   := $(shell sdl2-config --libs 2>/dev/null)
# host/png.c, linked into every program that takes HOST_LIB or host/png.c
PNG_LIBS   := $(shell pkg-config --libs libpng 2>/dev/null || echo -lpng)
# zlib's crc32, bspc's checksum of its blobs (tools/bspc/crc_fast.c)
ZLIB_LIBS  := $(shell pkg-config --libs zlib 2>/dev/null || echo -lz)

WARN     := -Wall -Wextra -Wshadow -Wstrict-prototypes -Wno-missing-field-initializers
INC      := -Ifirmware -Ihal -Ihal/null -Ihal/sdl -Ihal/serial -Itools/bspc -Ihost
# Firmware and HAL: freestanding, integer-only (any float or double is an error on
# the host: -mgeneral-regs-only), no libc calls synthesised from loops.
FW_FLAGS := -ffreestanding -mgeneral-regs-only -fno-strict-aliasing -fno-tree-loop-distribute-patterns
BASE     := -std=c11 -g $(WARN) $(INC) -D_DEFAULT_SOURCE
REL      := -O2
SAN      := -O1 -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=all

# ---- sources -----------------------------------------------------------------
FW_SRC    := $(sort $(wildcard firmware/*.c)) $(GEN)/fx_tables.c
HAL_SRC   := hal/fb.c hal/perf.c
NULL_SRC  := hal/ram_target.c hal/null/hal_null.c
SDL_SRC   := hal/ram_target.c hal/sdl/hal_sdl.c
BSPC_LIB  := $(filter-out tools/bspc/main.c tools/bspc/crc_fast.c,$(sort $(wildcard tools/bspc/*.c)))
# The host programs' shared files; the frame link's sender (host/link_send.c,
# build/render and build/emu --link) brings the link's sources along.
HOST_LIB   = host/png.c host/port.c host/link_send.c $(sort $(LINK_SRC))
# Starting a scene in the engine (host/scene_start.c) reads build_config.h, so it
# is compiled with the firmware of each build, not shared between builds.
HOST_ENG  := host/scene_start.c
FLOATFREE := firmware/% hal/fb.c hal/perf.c hal/ram_target.c hal/null/% hal/serial/% hal/mps2/% hal/bare/% hal/pcvga/% $(GEN)/%

# Each subsystem with rules of its own keeps them in mk/NAME.mk. They may add
# sources to LINK_SRC (the frame link, linked into host programs and unit tests),
# UNIT_EXTRA (more sources for the unit tests) and EXTRA_NOFLOAT_SRC.
LINK_SRC   := $(wildcard hal/serial/*.c)
# Shared by the bare-metal targets (hal/mps2, hal/pcvga): camera paths, options, printf, memory functions.
BARE_SRC   := $(sort $(wildcard hal/bare/*.c))
UNIT_EXTRA := tests/unit/scene_fixture.c hal/board/boot_vectors.c
EXTRA_NOFLOAT_SRC :=
# The float checks (tools/check_nofloat.sh) take seconds, so each set of files is
# checked again only when a file of it, a header it can include, the script or the
# list of files changes: a stamp per set under build/nofloat/, next to the list it
# was made for (nofloat_list rewrites that list only when it differs, so adding or
# dropping a file, EXTRA_NOFLOAT=... included, reruns the check).
NOFLOAT_DIR  := $(BUILD)/nofloat
NOFLOAT_DEPS  = tools/check_nofloat.sh $(GEN)/fx_tables.c \
                $(wildcard firmware/*.h firmware/*/*.h hal/*.h hal/*/*.h)
nofloat_list  = $(shell mkdir -p $(NOFLOAT_DIR); f=$(NOFLOAT_DIR)/$(1).list; \
                printf '%s\n' '$(2)' | cmp -s - $$f || printf '%s\n' '$(2)' > $$f; echo $$f)
-include $(sort $(wildcard mk/*.mk))

objs = $(patsubst %.c,$(1)/%.o,$(2))
fwflags = $(if $(filter $(FLOATFREE),$(1)),$(FW_FLAGS))

# ---- variants: build/ (optimised) and build/san/ (ASan + UBSan, used by the tests)
define variant
$(1)/obj/%.o: %.c $(GEN)/fx_tables.c
	@mkdir -p $$(@D)
	$$(CC) $$(BASE) $(2) $$(call fwflags,$$<) $$(if $$(filter hal/sdl/% host/emu.c host/display.c,$$<),$$(SDL_CFLAGS)) -MMD -MP -c $$< -o $$@
$(1)/obj/$(GEN)/%.o: $(GEN)/%.c
	@mkdir -p $$(@D)
	$$(CC) $$(BASE) $(2) $$(FW_FLAGS) -c $$< -o $$@

$(1)/bspc: $(call objs,$(1)/obj,tools/bspc/main.c $(BSPC_LIB) tools/bspc/crc_fast.c firmware/scene.c)
	$$(CC) $(2) $$^ -o $$@ $$(ZLIB_LIBS) -lm -pthread
$(1)/render: $(call objs,$(1)/obj,host/render.c $(HOST_ENG) $(HOST_LIB) $(BSPC_LIB) $(FW_SRC) $(HAL_SRC) $(NULL_SRC))
	$$(CC) $(2) $$^ -o $$@ $$(PNG_LIBS) -lm
$(1)/emu: $(call objs,$(1)/obj,host/emu.c $(HOST_ENG) $(GEN)/default_scene.c $(HOST_LIB) $(BSPC_LIB) $(FW_SRC) $(HAL_SRC) $(SDL_SRC))
	$$(CC) $(2) $$^ -o $$@ $$(SDL_LIBS) $$(PNG_LIBS) -lm
$(1)/display: $(call objs,$(1)/obj,host/display.c host/png.c host/port.c firmware/crc32.c $(HAL_SRC) $(SDL_SRC) $(sort $(LINK_SRC)))
	$$(CC) $(2) $$^ -o $$@ $$(SDL_LIBS) $$(PNG_LIBS)
# test_planar brings its own fake VGA target (hal_target_*): only fb.c and perf.c beside it
$(1)/test_planar: $(call objs,$(1)/obj,tests/unit/test_planar.c $(HAL_SRC))
	$$(CC) $(2) $$^ -o $$@ -lcmocka
# test_copybuf too (a linear target with no system-memory buffer of its own)
$(1)/test_copybuf: $(call objs,$(1)/obj,tests/unit/test_copybuf.c $(HAL_SRC))
	$$(CC) $(2) $$^ -o $$@ -lcmocka
# test_copycoding includes fl_copy.c (to write streams token by token): the rest of the link beside it
$(1)/test_copycoding: $(call objs,$(1)/obj,tests/unit/test_copycoding.c firmware/crc32.c $(filter-out hal/serial/fl_copy.c,$(sort $(LINK_SRC))))
	$$(CC) $(2) $$^ -o $$@ -lcmocka
$(1)/test_%: $(call objs,$(1)/obj,tests/unit/test_%.c) $(call objs,$(1)/obj,$(BSPC_LIB) $(FW_SRC) $(HAL_SRC) $(NULL_SRC) $(sort $(LINK_SRC) $(UNIT_EXTRA)))
	$$(CC) $(2) $$^ -o $$@ -lcmocka -lm
endef
$(eval $(call variant,$(BUILD),$(REL)))
$(eval $(call variant,$(BUILD)/san,$(SAN)))
# Mode spans with pools of a few polygons, so that nearly every frame is drawn in
# many batches, and mode direct with room for the faces of one object or so, so
# that the others are worked out again where needed (tests/test_span_batches.py
# compares its frames with build/render's).
$(eval $(call variant,$(BUILD)/tinypools,$(REL) -DSPANS_POOL_EDGES=72u -DSPANS_POOL_SURFACES=6u -DCFG_DIRECT_FACES=1u -DCFG_DIRECT_EDGES=12u \
                                          -DCFG_COLS_PLANES=4u))
$(BUILD)/tinypools/obj/tools/bspc/wad.o: $(THINGS_H)
$(BUILD)/tinypools/obj/tools/bspc/wad.o: BASE += -I$(GEN)
# A build without the texture code (CFG_FLAT=1): every scene in its flat colours
# (tests/test_textures_flat.py checks its id buffers against build/render's).
$(eval $(call variant,$(BUILD)/flat,$(REL) -DCFG_FLAT=1))
$(BUILD)/flat/obj/tools/bspc/wad.o: $(THINGS_H)
$(BUILD)/flat/obj/tools/bspc/wad.o: BASE += -I$(GEN)

UNIT_TESTS := $(patsubst tests/unit/%.c,%,$(wildcard tests/unit/test_*.c))
PROGRAMS   := $(BUILD)/bspc $(BUILD)/render $(BUILD)/emu $(BUILD)/display
SAN_PROGS  := $(BUILD)/san/bspc $(BUILD)/san/render $(BUILD)/san/display $(addprefix $(BUILD)/san/,$(UNIT_TESTS))

# ---- generated sources ----------------------------------------------------------
$(BUILD)/gen_tables: tools/gen_tables.c
	@mkdir -p $(@D)
	$(CC) -O2 $< -o $@ -lm
$(GEN)/fx_tables.c: $(BUILD)/gen_tables
	@mkdir -p $(@D)
	$< > $@
$(BUILD)/bin2c: tools/bin2c.c
	@mkdir -p $(@D)
	$(CC) -O2 $(BASE) $< -o $@
$(BUILD)/default.bsc: tests/scenes/default.scene $(BUILD)/bspc
	$(BUILD)/bspc $< -o $@
$(GEN)/default_scene.c: $(BUILD)/default.bsc $(BUILD)/bin2c
	$(BUILD)/bin2c default_scene $< > $@

# ---- top-level targets ------------------------------------------------------------
.PHONY: all deps run test unit pytest nofloat bench bench-faults bench-bsp bench-doom clean help
.DEFAULT_GOAL := all

all: $(PROGRAMS) nofloat

help:
	@echo "make deps       install missing Debian packages and the Python venv (idempotent)"
	@echo "make            build build/bspc, build/render, build/emu (and check: no floating point)"
	@echo "make run        walk freedoom2.wad:MAP01 in a window (the built-in scene without the WAD;"
	@echo "                SCENE=... for another; headless: fly-through PNGs)"
	@echo "make test       deps, build, unit tests and pytest, with ASan and UBSan"
	@echo "make bench      instructions per frame (callgrind, x86-64) per render mode, world alone and with"
	@echo "                things (textured), and world alone textured against --flat: median, p95, max and the"
	@echo "                stages of the frame over the bench and open views"
	@echo "                (tests/bench_views.json), overdraw, VRAM writes, bus cycles -> build/bench.md and"
	@echo "                docs/benchmarks.md; the same on the Cortex-M3 (bench-m3); link faults (bench-faults);"
	@echo "                the PC kernel's write counters per present mode (bench-pcvga);"
	@echo "                firmware flash and RAM of four scenes against the board's 200,000 bytes (bench-size)"
	@echo "make scene-host SCENE=...  build/scene/NAME/render, emu built for one scene (docs/needs.md)"
	@echo "make fuzz       each libFuzzer harness (tests/fuzz) for FUZZ_TIME seconds (default 60), FUZZ=names;"
	@echo "                make fuzz-smoke (part of make test): seeds and kept crashes once, 3 s each"
	@echo "make bench-link the frame link's bytes per frame and encoder cost"
	@echo "make compare-doom  a Doom map's player start beside Chocolate Doom's frame, and the share"
	@echo "                of 8x8 blocks within 24 in mean colour: whole frame (Doom's weapon left"
	@echo "                out), blocks with things, the others (MAP=FILE.wad:MAP or all; default"
	@echo "                freedoom2.wad:MAP01 freedoom1.wad:E1M1) -> build/compare/*.png"
	@echo "make firmware   build/arm/firmware.elf for QEMU mps2-an385, built for its scene (SCENE=, FULL=1,"
	@echo "                CAMPATH=, FW_MODES=direct,...); all its RAM within RAM_BYTES=200000 or refused;"
	@echo "                make run-firmware"
	@echo "make display-board  the display board (hal/board): build/arm/display-board.bin (DFU bootloader +"
	@echo "                application + valid mark, 4 MiB flash) and .dfu; make run-board; make bench-board"
	@echo "make pcvga      build/pcvga/kernel.elf: the bare PC kernel (multiboot, VGA mode 13h) for"
	@echo "                qemu-system-i386 (SCENE=, FULL=1, CAMPATH=, PC_MODES=); make run-pcvga [RUN_ARGS=...];"
	@echo "                make bench-pcvga (write counters per present mode)"
	@echo "make flash      IMAGE=x.dfu DEVICE=VID:PID (or LOOPBACK=1): USB DFU download"
	@echo "make bench-textures  bytes of each Freedoom map's textures, flats and light tables (docs/textures-bytes.md)"
	@echo "make mutate     mutation testing of firmware/, firmware/dfu/, hal/serial/ (MUTATE_SAMPLE=N mutants)"
	@echo "                -> build/mutate/report.md and docs/benchmarks.md; not part of make test"
	@echo "make bench-bsp  bspc over all 68 Freedoom maps per strategy, beside zdbsp and glbsp"
	@echo "make bench-doom Chocolate Doom's instructions per frame beside build/render's at 25 player starts"
	@echo "                (callgrind) -> build/bench-doom.md and docs/benchmarks.md"
	@echo "make report     error against the reference vs instructions per frame, per render mode and"
	@echo "                precision-knob configuration (mk/report.mk) -> build/report/report.md and plots;"
	@echo "                REPORT_CONFIGS=\"default subpix0\" for a few, REPORT_ARGS=\"--views 4\", V=1 shows the compiles"
	@echo "make format     rewrite the project's C files with clang-format (.clang-format, HACKING.md);"
	@echo "                make format-check (first step of make test) lists the files that differ"
	@echo "make clean      remove build/"

deps:
	@tools/deps.sh

# make run walks freedoom2.wad:MAP01, textured, when the WAD is installed (make deps
# installs Debian's freedoom), else the built-in scene; SCENE=... on the command
# line walks that scene.
RUN_SCENE = $(if $(filter command line environment,$(origin SCENE)),$(SCENE))
run: deps all
	@scene="$(RUN_SCENE)"; \
	if [ -z "$$scene" ]; then \
	  for d in $(DOOMWADDIR) /usr/share/games/doom; do \
	    if [ -f "$$d/freedoom2.wad" ]; then scene=freedoom2.wad:MAP01; break; fi; \
	  done; \
	fi; \
	echo "make run: $${scene:-the built-in scene} (SCENE=... for another)"; \
	$(BUILD)/emu $$scene

# No floating point in firmware/ and hal/ targets, three ways: no float/double token
# in the code (comments stripped), the host compile with -mgeneral-regs-only above,
# and a Cortex-M soft-float compile whose objects may not need any float helper.
NOFLOAT_SRC = $(sort $(FW_SRC) $(HAL_SRC) $(NULL_SRC) $(SDL_SRC) $(LINK_SRC) $(EXTRA_NOFLOAT_SRC)) $(EXTRA_NOFLOAT)
nofloat: $(NOFLOAT_DIR)/core.ok
$(NOFLOAT_DIR)/core.ok: $(NOFLOAT_SRC) $(NOFLOAT_DEPS) $(call nofloat_list,core,$(NOFLOAT_SRC))
	@tools/check_nofloat.sh $(NOFLOAT_SRC)
	@touch $@

unit: $(addprefix $(BUILD)/san/,$(UNIT_TESTS))
	@set -e; for t in $^; do echo "== $$t"; $$t; done

pytest: $(PROGRAMS) $(SAN_PROGS)
	$(PY) -m pytest -q tests

test: deps
	@$(MAKE) --no-print-directory format-check
	@$(MAKE) --no-print-directory all unit fuzz-smoke
	@$(MAKE) --no-print-directory pytest

bench-bsp: deps $(BUILD)/bspc
	$(PY) tools/bench_bsp.py

# BENCH_DOOM_ARGS: e.g. --mode spans, --map freedoom2.wad:MAP01 (a quick look), -j 1
BENCH_DOOM_ARGS ?=
bench-doom: deps $(BUILD)/bspc $(BUILD)/render
	$(PY) tools/bench_doom.py $(BENCH_DOOM_ARGS)

# BENCH_ARGS: e.g. --frames 10 (the N of (repeat N+1 - repeat 1)/N), -j 1, --views K
BENCH_ARGS ?=
bench: deps $(BUILD)/bspc $(BUILD)/render
	$(PY) tools/bench.py $(BENCH_ARGS)

bench: bench-faults bench-size
bench-faults: deps firmware
	$(PY) tools/bench_faults.py

# flash and RAM of the firmware, full build against builds for one scene (docs/needs.md)
bench-size: deps $(BUILD)/bspc $(BUILD)/render
	$(PY) tools/size_table.py

.PHONY: bench-size

# bytes of each Freedoom map's textures, flats and light tables (docs/textures-bytes.md)
bench-textures: deps $(BUILD)/bspc
	$(PY) tools/texture_bytes.py --bspc $(BUILD)/bspc

.PHONY: bench-textures

# Mutation testing of firmware/, firmware/dfu/ and hal/serial/ against the fast tests of each file
# (tools/mutate.py --help): build/mutate/report.md and docs/benchmarks.md. MUTATE_SAMPLE=N mutants,
# MUTATE_SEED=S picks them.
MUTATE_SAMPLE ?=
MUTATE_SEED ?=
mutate: deps $(GEN)/fx_tables.c
	MUTATE_SAMPLE=$(MUTATE_SAMPLE) MUTATE_SEED=$(MUTATE_SEED) $(PY) tools/mutate.py

.PHONY: mutate

clean:
	rm -rf $(BUILD)/obj $(BUILD)/san $(BUILD)/gen $(BUILD)/scene $(BUILD)/size $(PROGRAMS) $(BUILD)/*.bsc $(BUILD)/gen_tables $(BUILD)/bin2c $(BUILD)/fuzz/obj $(BUILD)/fuzz/fuzz_*

-include $(shell find $(BUILD) -name '*.d' 2>/dev/null)
