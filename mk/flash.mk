# mk/flash.mk - USB DFU flashing: build/flash (and its ASan+UBSan twin build/san/flash,
# run by the tests), the device-side DFU state machine in firmware/dfu/, and `make flash`.
#
# Exports for the Makefile:
#   UNIT_EXTRA        += the DFU sources tests/unit/test_dfu.c needs (the device state
#                        machine and image parser under firmware/dfu/, the host engine
#                        and loopback transport under host/flash/)
#   EXTRA_NOFLOAT_SRC += firmware/dfu/*.c (freestanding, integer-only: `make nofloat`)

LIBUSB_CFLAGS := $(shell pkg-config --cflags libusb-1.0 2>/dev/null || echo -I/usr/include/libusb-1.0)
LIBUSB_LIBS   := $(shell pkg-config --libs libusb-1.0 2>/dev/null || echo -lusb-1.0)

DFU_FW_SRC   := firmware/dfu/dfu_device.c firmware/dfu/dfu_image.c firmware/dfu/dfu_proto.c
DFU_HOST_SRC := host/flash/dfu_host.c host/flash/dfu_loopback.c
FLASH_SRC    := host/flash/flash_main.c host/flash/dfu_libusb.c $(DFU_HOST_SRC) $(DFU_FW_SRC) firmware/crc32.c

UNIT_EXTRA        += $(DFU_FW_SRC) $(DFU_HOST_SRC)
EXTRA_NOFLOAT_SRC += $(DFU_FW_SRC)

# The Makefile's $(1)/obj/%.o rule compiles these (firmware/dfu/ with the freestanding
# flags, as all of firmware/); only the libusb transport needs libusb's include path.
define flash_variant
$(1)/flash: $(patsubst %.c,$(1)/obj/%.o,$(FLASH_SRC))
	$$(CC) $(2) $$^ -o $$@ $$(LIBUSB_LIBS)
$(1)/obj/host/flash/dfu_libusb.o: BASE += $$(LIBUSB_CFLAGS)
endef
$(eval $(call flash_variant,$(BUILD),$(REL)))
$(eval $(call flash_variant,$(BUILD)/san,$(SAN)))

all: $(BUILD)/flash
pytest: $(BUILD)/flash $(BUILD)/san/flash $(BUILD)/libdfudev.so

# The device state machine as a shared library, for the USB device emulator
# tests/usbdfu_mock.py (ctypes): the same sources the bootloader builds, freestanding
# and integer-only, only position-independent.
DFUDEV_SRC := firmware/dfu/dfu_device.c firmware/dfu/dfu_proto.c firmware/crc32.c
$(BUILD)/libdfudev.so: $(DFUDEV_SRC) firmware/dfu/dfu_device.h firmware/dfu/dfu_proto.h firmware/crc32.h
	@mkdir -p $(@D)
	$(CC) $(BASE) $(REL) $(FW_FLAGS) -fPIC -shared $(DFUDEV_SRC) -o $@

# make flash IMAGE=fw.dfu DEVICE=1209:0001 [FLASH_ARGS="--serial SN -v"]
# make flash IMAGE=fw.dfu LOOPBACK=1       (simulated device, no hardware)
.PHONY: flash
flash: $(BUILD)/flash
	@if [ -z "$(IMAGE)" ]; then \
	  echo "make flash IMAGE=FILE.dfu DEVICE=VID:PID [FLASH_ARGS=...], or LOOPBACK=1 instead of DEVICE"; \
	  echo "(make an image with: $(BUILD)/flash --add-suffix FILE.bin --vid VID --pid PID -o FILE.dfu)"; \
	  exit 2; fi
	$(BUILD)/flash $(IMAGE) $(if $(LOOPBACK),--loopback,--device $(DEVICE)) $(FLASH_ARGS)
