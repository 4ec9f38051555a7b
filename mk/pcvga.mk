# pcvga.mk - the renderer as a bare PC kernel on the VGA (hal/pcvga): a 32-bit
# multiboot image that QEMU's qemu-system-i386 boots with -kernel.
#
#   make pcvga [SCENE=...] [FULL=1] [CAMPATH=default|map01] [PC_OUT=DIR] [PC_MODES=LIST]
#       -> $(PC_OUT)/kernel.elf (default build/pcvga/kernel.elf): the scene
#          compiled by build/bspc and built in (as for make firmware), the
#          renderer built for it (FULL=1: every feature), a camera path.
#          PC_MODES: the render modes compiled in, separated by commas
#          (mk/modes.mk; default every mode: the PC has memory to spare).
#   make run-pcvga [RUN_ARGS="--present copy32 ..."] [PC_DISPLAY=sdl|gtk|none]
#       runs it in qemu-system-i386 with a window where a display exists (else
#       headless); COM1 (the kernel's log) on the terminal; QEMU's exit status is
#       2 * the kernel's + 1 (isa-debug-exit). RUN_ARGS defaults to
#       "--linger 3000", which keeps the last frame up for three seconds.
#   make bench-pcvga  write counters per frame in each present mode over the
#       camera path, beside the host's linear page (tools/pcvga.py bench ->
#       build/bench-pcvga.md); make bench runs it too
#
# Integer-only: compiled with -mgeneral-regs-only (no x87 or SSE register can
# be used), and the link fails if libgcc's floating-point helpers are in it.

PC_OUT   ?= $(BUILD)/pcvga
PC_OBJ   ?= $(PC_OUT)/obj
QEMU_PC  ?= qemu-system-i386
PC_CC    ?= $(CC)
PC_MEM   ?= 64
PC_MODES ?= $(RENDER_MODES_ALL)

PCVGA_SRC := $(sort $(wildcard hal/pcvga/*.c)) $(BARE_SRC)
PCVGA_ASM := $(sort $(wildcard hal/pcvga/*.S))
PC_CFLAGS := -std=c11 -O2 -g -m32 -march=i686 -ffreestanding -nostdlib -fno-pic -fno-pie -fno-stack-protector \
             -fno-asynchronous-unwind-tables -mgeneral-regs-only -fno-strict-aliasing \
             -fno-tree-loop-distribute-patterns -ffunction-sections -fdata-sections \
             $(WARN) -Ifirmware -Ihal -Ihal/pcvga -Ihal/bare
PC_SRC    := $(FW_SRC) $(HAL_SRC) $(PCVGA_SRC)
PC_SCENE_DEF  := $(if $(FULL),,-DSCENE_CONFIG='"$(abspath $(PC_OUT)/scene_config.h)"') $(call render_modes_def,$(PC_MODES)) $(flat_def)
PC_CONFIG_DEP := $(if $(FULL),,$(PC_OUT)/scene_config.h) $(PC_OBJ)/modes
PC_OBJS   := $(patsubst %.c,$(PC_OBJ)/%.o,$(PC_SRC)) $(patsubst %.S,$(PC_OBJ)/%.o,$(PCVGA_ASM)) $(PC_OUT)/fw_scene.o
# libgcc's floating-point helpers for i386 (soft-float entry points and conversions).
PC_FLOAT_HELPERS := '^__(add|sub|mul|div|neg|fix|fixuns|float|floatun|extend|trunc|cmp|eq|ne|lt|le|gt|ge|unord|pow|powi)[sdtx]f[0-9]?$$'

.PHONY: pcvga run-pcvga nofloat-pcvga bench-pcvga

# hal/pcvga is a target like the others: no floating point (`make nofloat`).
nofloat: nofloat-pcvga
nofloat-pcvga: $(NOFLOAT_DIR)/pcvga.ok
$(NOFLOAT_DIR)/pcvga.ok: $(PCVGA_SRC) $(NOFLOAT_DEPS) $(call nofloat_list,pcvga,$(PCVGA_SRC))
	@printf 'hal/pcvga: '; tools/check_nofloat.sh $(PCVGA_SRC)
	@touch $@

pcvga: $(PC_OUT)/kernel.elf

$(PC_OBJ)/%.o: %.c $(GEN)/fx_tables.c $(PC_CONFIG_DEP)
	@mkdir -p $(@D)
	$(PC_CC) $(PC_CFLAGS) $(PC_SCENE_DEF) -MMD -MP -c $< -o $@
$(PC_OBJ)/%.o: %.S
	@mkdir -p $(@D)
	$(PC_CC) -m32 -c $< -o $@

# The render modes the objects were compiled with; rewritten only when they change.
$(PC_OBJ)/modes: FORCE
	@mkdir -p $(@D)
	@echo '$(call render_modes_def,$(PC_MODES))' | cmp -s - $@ || echo '$(call render_modes_def,$(PC_MODES))' > $@

$(PC_OUT)/config: FORCE
	@mkdir -p $(@D)
	@echo 'SCENE=$(SCENE) CAMPATH=$(CAMPATH) FULL=$(FULL)' | cmp -s - $@ || \
	  echo 'SCENE=$(SCENE) CAMPATH=$(CAMPATH) FULL=$(FULL)' > $@

$(PC_OUT)/scene.bsc: $(PC_OUT)/config $(BUILD)/bspc $(wildcard $(firstword $(subst :, ,$(SCENE))))
	$(call scene_bsc_recipe,$@,pcvga)
$(PC_OUT)/scene_config.h: $(PC_OUT)/scene.bsc $(BUILD)/bspc
	$(call scene_config_recipe,$<,$@,pcvga)

# The built-in part: the scene, its name and the camera path's name.
$(PC_OUT)/gen/fw_scene.c: $(PC_OUT)/scene.bsc $(BUILD)/bin2c
	@mkdir -p $(@D)
	@name=$$(printf '%s' '$(SCENE)' | sed 's/[\\"]/\\&/g'); \
	{ $(BUILD)/bin2c fw_scene $< && \
	  echo "const char fw_scene_name[] = \"$$name\";" && \
	  echo "const char fw_campath_name[] = \"$(CAMPATH)\";"; } > $@.tmp && mv $@.tmp $@
$(PC_OUT)/fw_scene.o: $(PC_OUT)/gen/fw_scene.c
	$(PC_CC) $(PC_CFLAGS) -c $< -o $@

$(PC_OUT)/kernel.elf: $(PC_OBJS) hal/pcvga/pcvga.ld $(PC_OUT)/config
	$(PC_CC) -m32 -nostdlib -static -no-pie -T hal/pcvga/pcvga.ld -Wl,--gc-sections -Wl,--build-id=none -Wl,--no-warn-rwx-segments \
	  -Wl,-Map=$(PC_OUT)/kernel.map $(PC_OBJS) -lgcc -o $@.tmp
	@helpers=$$(nm $@.tmp | awk '{print $$NF}' | grep -E $(PC_FLOAT_HELPERS)); \
	if [ -n "$$helpers" ]; then echo "pcvga: the kernel links floating-point helpers (it must be integer-only):"; \
	  echo "$$helpers" | sed 's/^/    /'; rm -f $@.tmp; exit 1; fi
	@mv $@.tmp $@
	@size $@ | sed 's/^/pcvga: /'
	@echo "pcvga: $@: scene $(SCENE), camera path $(CAMPATH), $(if $(FULL),every feature,built for the scene)"

# ---- running it -----------------------------------------------------------------
PC_DISPLAY ?= $(if $(DISPLAY)$(WAYLAND_DISPLAY),sdl,none)
PC_QEMU = $(QEMU_PC) -m $(PC_MEM) -kernel $(PC_OUT)/kernel.elf -device isa-debug-exit,iobase=0xf4,iosize=0x04 \
          -vga std -monitor none -serial stdio -no-reboot

run-pcvga: RUN_ARGS ?= --linger 3000
run-pcvga: $(PC_OUT)/kernel.elf
	@echo "pcvga: display $(PC_DISPLAY); COM1 below; QEMU exits with 2 x the kernel's status + 1"
	$(PC_QEMU) -display $(PC_DISPLAY) $(if $(RUN_ARGS),-append '$(RUN_ARGS)'); \
	  s=$$?; echo "pcvga: QEMU exit status $$s (kernel status $$(( (s - 1) / 2 )))"; [ $$s -eq 1 ]

bench-pcvga: $(PC_OUT)/kernel.elf $(BUILD)/render
	$(PY) tools/pcvga.py bench $(PC_OUT)/kernel.elf --scene $(PC_OUT)/scene.bsc -o $(BUILD)/bench-pcvga.md

bench: bench-pcvga

-include $(shell find $(PC_OBJ) -name '*.d' 2>/dev/null)
