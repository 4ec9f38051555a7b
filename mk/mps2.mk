# mps2.mk - the Cortex-M3 firmware on QEMU's mps2-an385 board (hal/mps2), the
# instruction-counting QEMU plugin (tools/qemu_plugin), and how to run them.
#
#   make firmware [SCENE=...] [FULL=1] [CAMPATH=default|map01] [WORK_BYTES=N] [STREAM=framelink|raw] [ARM_OUT=DIR]
#                 [FW_MODES=columns|LIST] [RAM_BYTES=N] [STACK_BYTES=N]
#       -> $(ARM_OUT)/firmware.elf (default build/arm/firmware.elf): the scene
#          (text scene, WAD map "file.wad:MAP01" or a compiled .bsc, default
#          tests/scenes/default.scene) compiled by build/bspc and built in (in
#          flash, read in place), the work area sized from it by the firmware
#          itself (or WORK_BYTES), and a camera path (default: map01 for a MAP01
#          scene, else default).
#          The renderer is built for that scene (docs/needs.md): only the
#          features it needs, fixed buffers sized to its proven bounds
#          ($(ARM_OUT)/scene_config.h, written by bspc --config). FULL=1 builds
#          every feature in, as for any scene.
#          FW_MODES: the render modes compiled in, separated by commas (mk/modes.mk;
#          default columns, whose work area the screen bounds (it draws frames with
#          objects with direct's code too); FULL=1 does not change it: e.g.
#          FW_MODES=direct,spans,painter,columns RAM_BYTES=16777216).
#          RAM_BYTES (default 200,000): all of the firmware's RAM - stack, both VRAM
#          pages, palette, .data, .bss, work area (hal/mps2/mps2.ld). A build that
#          does not fit is refused with one line giving the RAM it needs. Up to 4 MB
#          the RAM is SSRAM2/3 at 0x20000000, beyond that (benches of big work
#          areas) PSRAM at 0x21000000, up to 16 MB.
#          STACK_BYTES (default 9216, with FULL=1 14336): the stack (the firmware
#          reports its high-water mark).
#   make run-firmware [UART=FILE|stdio | PORT=tcp:N|tcp:HOST:N|pty] [RUN_ARGS="--frames 10 ..."]
#       runs the firmware last built in qemu-system-arm (no rebuild unless a
#       build setting such as SCENE= is given again) and says which scene it
#       holds (tools/run_firmware.py). The UART (the frame stream) goes to
#       build/arm/uart.bin, or to stdout alone with UART=stdio (everything else
#       on stderr), or to a TCP server that waits for its reader (PORT=tcp:N),
#       or to a pty, QEMU paused until a reader opens it (PORT=pty). The
#       firmware's messages (semihosting) go to stderr; QEMU's exit status is
#       the firmware's.
#   make insn-plugin  -> build/insn_count.so
#   make bench-m3 [BENCH_M3_ARGS=...]  instructions per frame on the Cortex-M3 per render mode,
#                     world alone and with things, and the stages of the frame, for the bench and
#                     open views (tools/qemu_plugin/bench_m3.py -> build/bench-m3.md and
#                     docs/benchmarks.md); make bench runs it too
#   make count-m3 [SCENE=...] [RUN_ARGS=...]  per-frame counts of the firmware as built
#
# Integer-only: compiled soft-float (-mfloat-abi=soft), and the link fails if
# the image contains any floating-point helper from libgcc.

ARM_OUT  ?= $(BUILD)/arm
SCENE    ?= tests/scenes/default.scene
CAMPATH  ?= $(if $(findstring MAP01,$(SCENE)),map01,default)
WORK_BYTES ?=
QEMU_ARM ?= qemu-system-arm
UART     ?= $(ARM_OUT)/uart.bin
RUN_ARGS ?=
FULL     ?=
FW_MODES ?= columns
# Mode columns' visplanes (firmware/build_config.h, 652 bytes each): a full pool is
# drawn early, nothing is lost.
COLS_PLANES ?= 10
# Mode direct's face pools (firmware/build_config.h): small on the board; objects
# beyond them are worked out again where needed, never dropped.
DIRECT_FACES ?= 8
DIRECT_EDGES ?= 48
# KNOB_DEFS: a precision knob configuration's flags (mk/report.mk), for make report's Cortex-M3 runs.
KNOB_DEFS ?=
FW_DEFS = $(call render_modes_def,$(FW_MODES)) $(flat_def) -DCFG_DIRECT_FACES=$(DIRECT_FACES)u -DCFG_DIRECT_EDGES=$(DIRECT_EDGES)u \
          -DCFG_COLS_PLANES=$(COLS_PLANES)u $(KNOB_DEFS)
RAM_BYTES ?= 200000
# The stack: the walks keep a stack of the tree's depth (CFG_MAX_DEPTH: the scene's
# in a build for it, 255 in a FULL=1 build); a textured frame adds a row of texels
# (320 bytes) and the span's samples. Measured high-water marks (hal/mps2/README.md):
# up to 6,272 bytes on freedoom2.wad:MAP12 textured (the tests keep it within 3/4
# of the stack), 11,064 with FULL=1 (make bench-size); a FULL=1 build's 64-vertex
# models, their faces worked out again inside another face's row when the pools
# cannot hold them, reach 12,560 on tests/scenes/objects.scene.
STACK_BYTES ?= $(if $(FULL),14336,9216)
# SSRAM2/3 is 4 MB (mirrored above it); more RAM than that is PSRAM's 16 MB.
MPS2_SSRAM_BYTES := 4194304
MPS2_RAM_ORIGIN := $(shell [ '$(RAM_BYTES)' -gt $(MPS2_SSRAM_BYTES) ] 2>/dev/null && echo 0x21000000 || echo 0x20000000)
ifneq ($(shell [ '$(RAM_BYTES)' -ge 1 ] 2>/dev/null && [ '$(RAM_BYTES)' -le 16777216 ] 2>/dev/null && echo ok),ok)
$(error mk/mps2.mk: RAM_BYTES=$(RAM_BYTES): a number of bytes, at most 16,777,216)
endif
# The link: mps2.ld with the RAM's place and size and the stack's size.
mps2_ld = -T hal/mps2/mps2.ld -Wl,--gc-sections -Wl,--defsym=MPS2_RAM_ORIGIN=$(1) -Wl,--defsym=MPS2_RAM_BYTES=$(2) \
          -Wl,--defsym=MPS2_STACK_BYTES=$(STACK_BYTES)

ARMNM    := arm-none-eabi-nm
ARMSIZE  := arm-none-eabi-size
# The frame encoding on the UART (hal/mps2/stream.h): the frame link (hal/serial)
# when its encoder is in the tree, else raw records; STREAM= chooses.
STREAM   ?= $(if $(wildcard hal/serial/fl_encoder.c),framelink,raw)
ifeq ($(STREAM),framelink)
MPS2_LINK_SRC := $(sort $(wildcard hal/serial/*.c))
else ifeq ($(STREAM),raw)
MPS2_LINK_SRC :=
else
$(error mk/mps2.mk: STREAM=$(STREAM): framelink or raw)
endif
MPS2_ALL_SRC := $(sort $(wildcard hal/mps2/*.c)) $(BARE_SRC)
MPS2_SRC := $(filter-out hal/mps2/stream_%.c,$(MPS2_ALL_SRC)) $(if $(filter raw,$(STREAM)),hal/mps2/stream_raw.c,hal/mps2/stream_fl.c)
ARM_CFLAGS := -std=c11 -O2 -g -mcpu=cortex-m3 -mthumb -mfloat-abi=soft -ffreestanding -nostdlib \
              -fno-strict-aliasing -fno-tree-loop-distribute-patterns -ffunction-sections -fdata-sections \
              $(WARN) -Ifirmware -Ihal -Ihal/mps2 -Ihal/bare -Ihal/serial
ARM_SRC  := $(FW_SRC) $(HAL_SRC) $(MPS2_SRC) $(MPS2_LINK_SRC)
# Objects of a FULL=1 build do not depend on the scene: its ARM_OBJ may be
# shared by several ARM_OUTs (with the same FW_MODES). A build for one scene
# compiles them for it.
ARM_OBJ  ?= $(ARM_OUT)/obj
ARM_SCENE_DEF := $(if $(FULL),,-DSCENE_CONFIG='"$(abspath $(ARM_OUT)/scene_config.h)"') $(FW_DEFS)
ARM_CONFIG_DEP := $(if $(FULL),,$(ARM_OUT)/scene_config.h) $(ARM_OBJ)/modes
ARM_OBJS := $(patsubst %.c,$(ARM_OBJ)/%.o,$(ARM_SRC)) $(ARM_OUT)/fw_scene.o
# The soft-float helpers (as in tools/check_nofloat.sh) that may not be linked in.
ARM_FLOAT_HELPERS := '^__aeabi_([fd]|[a-z]*2[fd]$$)|^__(add|sub|mul|div|neg|fix|fixuns|float|floatun|extend|trunc|cmp|eq|ne|lt|le|gt|ge|unord|pow|powi)[sdtx]f[0-9]?$$'

# hal/mps2 is a target like the others: no floating point. `make nofloat` checks
# it on its own (its hal_* functions would clash with hal/null's in the shared
# check's combined link); the firmware link below checks the whole image.
.PHONY: nofloat-mps2
nofloat: nofloat-mps2
MPS2_NOFLOAT_SRC := $(filter-out hal/mps2/stream_fl.c,$(MPS2_ALL_SRC))
nofloat-mps2: $(NOFLOAT_DIR)/mps2.ok
$(NOFLOAT_DIR)/mps2.ok: $(MPS2_NOFLOAT_SRC) $(NOFLOAT_DEPS) $(call nofloat_list,mps2,$(MPS2_NOFLOAT_SRC))
	@printf 'hal/mps2: '; tools/check_nofloat.sh $(MPS2_NOFLOAT_SRC)
	@touch $@

.PHONY: firmware run-firmware insn-plugin bench-m3 count-m3 FORCE
FORCE:

firmware: $(ARM_OUT)/firmware.elf

$(ARM_OBJ)/%.o: %.c $(GEN)/fx_tables.c $(ARM_CONFIG_DEP)
	@mkdir -p $(@D)
	$(ARMCC) $(ARM_CFLAGS) $(ARM_SCENE_DEF) -MMD -MP -c $< -o $@

# The render modes the objects were compiled with; rewritten only when they change.
$(ARM_OBJ)/modes: FORCE
	@mkdir -p $(@D)
	@echo '$(FW_DEFS)' | cmp -s - $@ || echo '$(FW_DEFS)' > $@

# What the scene needs, as a C header (mk/scene.mk's recipe).
$(ARM_OUT)/scene_config.h: $(ARM_OUT)/scene.bsc $(BUILD)/bspc
	$(call scene_config_recipe,$<,$@,mps2)

# What the built-in part and the link depend on; rewritten only when it changes.
ARM_CONFIG_LINE = SCENE=$(SCENE) CAMPATH=$(CAMPATH) WORK_BYTES=$(WORK_BYTES) STREAM=$(STREAM) FULL=$(FULL) \
                  FW_MODES=$(FW_MODES) RAM_BYTES=$(RAM_BYTES) STACK_BYTES=$(STACK_BYTES)
$(ARM_OUT)/config: FORCE
	@mkdir -p $(@D)
	@echo '$(ARM_CONFIG_LINE)' | cmp -s - $@ || echo '$(ARM_CONFIG_LINE)' > $@

$(ARM_OUT)/scene.bsc: $(ARM_OUT)/config $(BUILD)/bspc $(wildcard $(firstword $(subst :, ,$(SCENE))))
	$(call scene_bsc_recipe,$@,mps2)

# The built-in part: the scene, its name, the camera path and a work area of
# $(2) bytes, as C ($(1) the output file).
define fw_scene_c
	@mkdir -p $(dir $(1))
	@n=$(2); name=$$(printf '%s' '$(SCENE)' | sed 's/[\\"]/\\&/g'); \
	{ $(BUILD)/bin2c fw_scene $< && \
	  echo "const char fw_scene_name[] = \"$$name\";" && \
	  echo "const char fw_campath_name[] = \"$(CAMPATH)\";" && \
	  echo "/* the work area: $$n bytes in RAM (section .work, hal/mps2/mps2.ld) */" && \
	  echo "_Alignas(8) uint8_t fw_work[$$n > 0 ? $$n : 1] __attribute__((section(\".work\")));" && \
	  echo "const uint32_t fw_work_bytes = $${n}u;"; } > $(1).tmp && mv $(1).tmp $(1)
endef

# The work area: exactly what this firmware needs for its scene (32-bit
# layouts, this build's features), as the firmware itself works it out: a
# sizing image with no work area is run once under QEMU and says how much it
# needs. WORK_BYTES= overrides. A scene the firmware refuses gets none: the
# firmware then refuses it at start with the loader's message. The sizing image
# links with all of SSRAM2/3 as its RAM, so that it runs whatever RAM_BYTES is.
$(ARM_OUT)/gen/fw_sizer.c: $(ARM_OUT)/scene.bsc $(BUILD)/bin2c
	$(call fw_scene_c,$@,0)
$(ARM_OUT)/fw_sizer.o: $(ARM_OUT)/gen/fw_sizer.c
	$(ARMCC) $(ARM_CFLAGS) -c $< -o $@
$(ARM_OUT)/sizer.elf: $(filter-out $(ARM_OUT)/fw_scene.o,$(ARM_OBJS)) $(ARM_OUT)/fw_sizer.o hal/mps2/mps2.ld
	$(ARMCC) $(ARM_CFLAGS) $(call mps2_ld,0x20000000,$(MPS2_SSRAM_BYTES)) $(filter %.o,$^) -lgcc -o $@
# With WORK_BYTES given the sizer is not run, and the file changes only with it: a
# scene built in for several builds of the objects (ARM_OBJ) is compiled once.
$(ARM_OUT)/work_bytes: $(if $(WORK_BYTES),,$(ARM_OUT)/sizer.elf) $(ARM_OUT)/config
	@if [ -n '$(WORK_BYTES)' ]; then echo '$(WORK_BYTES)' | cmp -s - $@ || echo '$(WORK_BYTES)' > $@; \
	elif n=$$(timeout 60 $(QEMU_ARM) -M mps2-an385 -nographic -monitor none -semihosting-config enable=on,target=native \
	          -kernel $< -serial null 2>&1 | sed -n 's/.* needs \([0-9]*\) bytes of work memory.*/\1/p') && [ -n "$$n" ]; then \
	  echo "$$n" > $@; \
	else echo "mps2: the firmware refuses $(SCENE): no work area built in (it will say why at start)"; \
	  echo 0 > $@; fi

$(ARM_OUT)/gen/fw_scene.c: $(ARM_OUT)/scene.bsc $(ARM_OUT)/work_bytes $(BUILD)/bin2c
	$(call fw_scene_c,$@,$$(cat $(ARM_OUT)/work_bytes))

$(ARM_OUT)/fw_scene.o: $(ARM_OUT)/gen/fw_scene.c
	@mkdir -p $(@D)
	$(ARMCC) $(ARM_CFLAGS) -c $< -o $@

# The link. When the image does not fit in RAM_BYTES, it is linked once more
# with room to spare, only to read how much RAM it needs (mps2.ld's __ram_need
# and the parts of it), and the build is refused with that figure (and no image).
$(ARM_OUT)/firmware.elf: $(ARM_OBJS) hal/mps2/mps2.ld $(ARM_OUT)/config
	@if ! $(ARMCC) $(ARM_CFLAGS) $(call mps2_ld,$(MPS2_RAM_ORIGIN),$(RAM_BYTES)) -Wl,-Map=$(ARM_OUT)/firmware.map \
	    $(ARM_OBJS) -lgcc -o $@.tmp 2> $@.err; then \
	  if $(ARMCC) $(ARM_CFLAGS) $(call mps2_ld,0x20000000,0x40000000) $(ARM_OBJS) -lgcc -o $@.fit 2>/dev/null; then \
	    $(ARMNM) $@.fit | awk -v scene='$(SCENE)' -v have=$(RAM_BYTES) -f tools/ram_need.awk; \
	    rm -f $@ $@.fit $@.err $@.tmp; exit 1; \
	  fi; cat $@.err; rm -f $@ $@.err $@.tmp; exit 1; \
	fi; cat $@.err; rm -f $@.err
	@helpers=$$($(ARMNM) $@.tmp | awk '{print $$NF}' | grep -E $(ARM_FLOAT_HELPERS)); \
	if [ -n "$$helpers" ]; then echo "mps2: the firmware links floating-point helpers (it must be integer-only):"; \
	  echo "$$helpers" | sed 's/^/    /'; rm -f $@.tmp; exit 1; fi
	@mv $@.tmp $@
	@$(ARMSIZE) $@ | sed 's/^/mps2: /'
	@$(ARMNM) $@ | awk -v have=$(RAM_BYTES) -v report=1 -f tools/ram_need.awk
	@echo "mps2: $@: scene $(SCENE), camera path $(CAMPATH), work area $$(cat $(ARM_OUT)/work_bytes) bytes, render modes $(FW_MODES), stream $(STREAM), $(if $(FULL),every feature,built for the scene)"

# ---- running it -----------------------------------------------------------------
# -nographic would put the UART and QEMU's monitor together on stdio, where a
# 0x01 byte of a frame starts a monitor escape: the UART goes to a file (or to a
# plain stdio with UART=stdio) and the monitor is off.
MPS2_QEMU = $(QEMU_ARM) -M mps2-an385 -nographic -monitor none \
            -semihosting-config enable=on,target=native -kernel $(ARM_OUT)/firmware.elf

# run-firmware runs the firmware last built, as it is (tools/run_firmware.py says which scene it
# holds): a later `make run-firmware` without SCENE= must not rebuild it for the default scene.
# Only a build setting given on the command line rebuilds first, with make's output on stderr:
# stdout carries nothing but the UART with UART=stdio.
FW_BUILD_VARS := SCENE FULL CAMPATH WORK_BYTES STREAM FW_MODES RAM_BYTES STACK_BYTES FLAT DIRECT_FACES DIRECT_EDGES \
                 COLS_PLANES
FW_BUILD_GIVEN := $(strip $(foreach v,$(FW_BUILD_VARS),$(if $(filter command line,$(origin $(v))),$(v))))
RUN_PY := $(if $(wildcard $(PY)),$(PY),python3)
PORT ?=
run-firmware:
	@$(if $(FW_BUILD_GIVEN),$(MAKE) --no-print-directory firmware >&2 &&) \
	$(RUN_PY) tools/run_firmware.py --elf $(ARM_OUT)/firmware.elf --qemu '$(QEMU_ARM)' \
	  --uart '$(UART)' $(if $(PORT),--port '$(PORT)') \
	  $(if $(RUN_ARGS),--args '$(RUN_ARGS)')

# ---- instruction counts (TCG plugin) ----------------------------------------------
$(BUILD)/insn_count.so: tools/qemu_plugin/insn_count.c tools/qemu_plugin/qemu_plugin_api.h
	@mkdir -p $(@D)
	$(CC) -std=c11 -O2 -g -Wall -Wextra -fPIC -shared -fvisibility=hidden $< -o $@

insn-plugin: $(BUILD)/insn_count.so

BENCH_M3_ARGS ?=
bench-m3: deps $(BUILD)/bspc $(BUILD)/render $(BUILD)/bin2c $(BUILD)/insn_count.so
	$(PY) tools/qemu_plugin/bench_m3.py $(BENCH_M3_ARGS)

# make bench reports the Cortex-M3 figures too.
bench: bench-m3

# Per-frame instruction counts of the firmware as built, to $(ARM_OUT)/insns.txt.
count-m3: $(ARM_OUT)/firmware.elf $(BUILD)/insn_count.so
	@begin=$$($(ARMNM) $(ARM_OUT)/firmware.elf | awk '$$3=="fw_mark_frame_begin"{print "0x"$$1}'); \
	end=$$($(ARMNM) $(ARM_OUT)/firmware.elf | awk '$$3=="fw_mark_frame_end"{print "0x"$$1}'); \
	$(MPS2_QEMU) -serial null -plugin $(BUILD)/insn_count.so,begin=$$begin,end=$$end,out=$(ARM_OUT)/insns.txt \
	  -append '--no-stream $(RUN_ARGS)' && cat $(ARM_OUT)/insns.txt

-include $(shell find $(ARM_OBJ) -name '*.d' 2>/dev/null)
