# board.mk - the display board (hal/board): a Cortex-M3 on QEMU's mps2-an385 that
# receives the frame link on UART0 and shows the frames, behind a DFU bootloader.
#
#   make display-board
#       -> build/arm/display-board.elf  the application, linked at 0x00010000 (the slot)
#          build/arm/board-boot.elf     the DFU bootloader, at 0x00000000
#          build/arm/display-board.bin  the whole 4 MiB flash: bootloader, 0xFF, the
#                                       application and the valid mark as a DFU download
#                                       leaves them (build/board_image)
#          build/arm/display-board.dfu  the application bytes with a DFU suffix 1209:0001
#   make run-board [BOARD_PORT=tcp:N] [BOARD_ARGS="--log-frames --frames N"]
#       boots display-board.bin in qemu-system-arm (-kernel loads a raw image at 0 on M-profile) with UART0 a TCP server on port N
#       (default 5555), waiting for the sender to connect
#   make bench-board   the decoder's instructions per frame on the Cortex-M3
#                      (tools/bench_board.py -> build/bench-board.md)
#
# The board reuses hal/mps2's startup, UART, semihosting and log, and its linker
# script with the ROM moved (MPS2_ROM_ORIGIN/MPS2_ROM_BYTES). Flash layout:
# hal/board/board_layout.h. Variables below are expanded late: this file is
# read before mk/mps2.mk, which defines ARM_CFLAGS and the tools.

BOARD_OUT   := $(BUILD)/arm
BOARD_OBJ   := $(BOARD_OUT)/board-obj
# All of the board's RAM: stack, the two pages, palette, display-start register
# (hal/mps2/mps2.ld's .display), one link message, the decoder (hal/board/README.md).
BOARD_RAM_BYTES   ?= 221184
BOARD_STACK_BYTES ?= 4096
# UART0's receive ring (hal/mps2/uart.c): a power of two; the main loop is woken
# at each message's first byte and delimiter and at every half ring.
BOARD_RX_RING     ?= 2048
BOARD_BASE_SRC := hal/mps2/startup.c hal/mps2/uart.c hal/mps2/semihost.c hal/mps2/log.c hal/mps2/tick.c \
                  hal/bare/format.c hal/bare/libc.c firmware/crc32.c
BOARD_APP_SRC  := $(BOARD_BASE_SRC) hal/board/main.c hal/board/board_args.c \
                  hal/serial/fl_framing.c hal/serial/fl_codec.c hal/serial/fl_copy.c hal/serial/fl_decoder.c
BOARD_BOOT_SRC := $(BOARD_BASE_SRC) hal/board/boot.c hal/board/boot_vectors.c firmware/dfu/dfu_device.c firmware/dfu/dfu_proto.c
BOARD_CFLAGS = $(ARM_CFLAGS) -Ihal/board -DUART_RX_RING=$(BOARD_RX_RING) -DUART_RX_SPANS=1
# $(1): ROM origin, $(2): ROM bytes
board_ld = -T hal/mps2/mps2.ld -Wl,--gc-sections -Wl,--defsym=MPS2_ROM_ORIGIN=$(1) -Wl,--defsym=MPS2_ROM_BYTES=$(2) \
           -Wl,--defsym=MPS2_RAM_BYTES=$(BOARD_RAM_BYTES) -Wl,--defsym=MPS2_STACK_BYTES=$(BOARD_STACK_BYTES)

# hal/board is a target like the others: no floating point (the links below check
# the images for soft-float helpers too).
.PHONY: nofloat-board
nofloat: nofloat-board
nofloat-board: $(NOFLOAT_DIR)/board.ok
$(NOFLOAT_DIR)/board.ok: hal/board/main.c hal/board/board_args.c hal/board/boot.c hal/board/boot_vectors.c $(NOFLOAT_DEPS)
	@printf 'hal/board: '; NOFLOAT_INC='-Ihal/mps2 -Ihal/serial -Ihal/board' tools/check_nofloat.sh hal/board/main.c hal/board/board_args.c
	@printf 'hal/board (bootloader): '; NOFLOAT_INC='-Ihal/mps2 -Ihal/board' tools/check_nofloat.sh hal/board/boot.c hal/board/boot_vectors.c
	@touch $@

# No image may link libgcc's floating-point helpers.
board_nofloat = helpers=$$($(ARMNM) $(1) | awk '{print $$NF}' | grep -E $(ARM_FLOAT_HELPERS)); \
	if [ -n "$$helpers" ]; then echo "board: $(1) links floating-point helpers: $$helpers"; rm -f $(1); exit 1; fi

.PHONY: display-board run-board bench-board
display-board: $(BOARD_OUT)/display-board.elf $(BOARD_OUT)/board-boot.elf $(BOARD_OUT)/display-board.bin \
               $(BOARD_OUT)/display-board.dfu

$(BOARD_OBJ)/%.o: %.c
	@mkdir -p $(@D)
	$(ARMCC) $(BOARD_CFLAGS) -MMD -MP -c $< -o $@

# The application: up to the slot's last page, which holds the valid mark.
$(BOARD_OUT)/display-board.elf: $(patsubst %.c,$(BOARD_OBJ)/%.o,$(BOARD_APP_SRC)) hal/mps2/mps2.ld
	$(ARMCC) $(BOARD_CFLAGS) $(call board_ld,0x00010000,0x003EF000) -Wl,-Map=$(BOARD_OUT)/display-board.map \
	  $(filter %.o,$^) -lgcc -o $@
	@$(call board_nofloat,$@)
	@$(ARMSIZE) $@ | sed 's/^/board: /'
	@need=$$(($$($(ARMNM) $@ | awk '$$3=="__ram_need"{print "0x"$$1}'))); \
	echo "board: RAM $$need of $(BOARD_RAM_BYTES) bytes: stack $(BOARD_STACK_BYTES), pages + palette + display start 128772, the rest .data/.bss (the link message, the decoder, the $(BOARD_RX_RING)-byte receive ring)"

$(BOARD_OUT)/board-boot.elf: $(patsubst %.c,$(BOARD_OBJ)/%.o,$(BOARD_BOOT_SRC)) hal/mps2/mps2.ld
	$(ARMCC) $(BOARD_CFLAGS) $(call board_ld,0x00000000,0x00010000) $(filter %.o,$^) -lgcc -o $@
	@$(call board_nofloat,$@)
	@$(ARMSIZE) $@ | sed 's/^/board: /'

$(BOARD_OUT)/%.app.bin: $(BOARD_OUT)/%.elf
	arm-none-eabi-objcopy -O binary $< $@

$(BOARD_OUT)/display-board.bin: $(BOARD_OUT)/board-boot.app.bin $(BOARD_OUT)/display-board.app.bin $(BUILD)/board_image
	$(BUILD)/board_image $(BOARD_OUT)/board-boot.app.bin $(BOARD_OUT)/display-board.app.bin $@

$(BOARD_OUT)/display-board.dfu: $(BOARD_OUT)/display-board.app.bin $(BUILD)/flash
	$(BUILD)/flash --add-suffix $< --vid 1209 --pid 0001 -o $@

# The host tool that writes the flash image through firmware/dfu's device (a DFU
# download over the loopback transport).
BOARD_IMAGE_SRC := host/flash/board_image.c host/flash/dfu_host.c host/flash/dfu_loopback.c \
                   firmware/dfu/dfu_device.c firmware/dfu/dfu_image.c firmware/dfu/dfu_proto.c firmware/crc32.c
$(BUILD)/board_image: $(patsubst %.c,$(BUILD)/obj/%.o,$(BOARD_IMAGE_SRC))
	$(CC) $(REL) $^ -o $@

BOARD_PORT ?= tcp:5555
BOARD_ARGS ?= --log-frames
run-board: display-board
	@echo "board: UART0 (the frame link) on $(BOARD_PORT), waiting for the sender; log below"
	$(QEMU_ARM) -M mps2-an385 -nographic -monitor none -semihosting-config enable=on,target=native \
	  -kernel $(BOARD_OUT)/display-board.bin \
	  -serial $(patsubst tcp:%,tcp:127.0.0.1:%$(comma)server=on$(comma)wait=on,$(BOARD_PORT)) \
	  $(if $(BOARD_ARGS),-append '$(BOARD_ARGS)')

bench-board: deps display-board firmware $(BUILD)/insn_count.so $(BUILD)/render
	$(PY) tools/bench_board.py --out $(BUILD)/bench-board.md

pytest: display-board

-include $(shell find $(BOARD_OBJ) -name '*.d' 2>/dev/null)
