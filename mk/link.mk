# link.mk - the frame link (hal/serial, docs/frame-link.md): its sources, the host
# tool build/fltool, and the link benchmark.
#
#   LINK_SRC              the frame link's C sources (freestanding, no float: part of
#                         `make nofloat`; linked into build/display and the unit tests)
#   make build/fltool     walk a scene, encode frames into a stream, decode a stream
#                         (host/fltool.c; tests/test_framelink.py and tools/bench_link.py use it)
#   make bench-link       bytes per frame of a MAP01 fly-through (textured, and flat:
#                         fps at 115,200 baud .. USB full speed) against raw and zlib -9,
#                         and the encoder's instructions per frame on x86-64 (callgrind)
#                         and on the Cortex-M3 (QEMU + build/insn_count.so), there beside
#                         the rendering firmware's instructions for the same cameras
#                         (build/bench-link/fw), against the goal of at most 10%
#                         -> build/bench-link.md

LINK_SRC := $(sort $(wildcard hal/serial/*.c))

FLTOOL_SRC := host/fltool.c $(HOST_ENG) $(HOST_LIB) $(BSPC_LIB) $(FW_SRC) $(HAL_SRC) $(NULL_SRC) $(LINK_SRC)
$(BUILD)/fltool: $(patsubst %.c,$(BUILD)/obj/%.o,$(FLTOOL_SRC))
	$(CC) $(REL) $^ -o $@ $(PNG_LIBS) -lm
$(BUILD)/san/fltool: $(patsubst %.c,$(BUILD)/san/obj/%.o,$(FLTOOL_SRC))
	$(CC) $(SAN) $^ -o $@ $(PNG_LIBS) -lm

# The tests run build/san/fltool (the decoder on damaged streams under ASan + UBSan).
pytest: $(BUILD)/fltool $(BUILD)/san/fltool
all: $(BUILD)/fltool

# The encoder on the Cortex-M3: a bare-metal image with the frames of
# $(FLBENCH)/frames.raw built in (tools/bench_link.py writes them, then asks for
# this target). Not part of `make all`.
FLBENCH := $(BUILD)/flbench
FLBENCH_CFLAGS := -std=c11 -O2 -g -mcpu=cortex-m3 -mthumb -mfloat-abi=soft -ffreestanding -nostdlib \
                  -fno-strict-aliasing -fno-tree-loop-distribute-patterns -Ifirmware -Ihal -Ihal/serial
$(FLBENCH)/frames.c: $(FLBENCH)/frames.raw $(BUILD)/bin2c
	$(BUILD)/bin2c fl_frames $< > $@
$(FLBENCH)/m3.elf: tools/flbench_m3/flbench_m3.c tools/flbench_m3/flbench_m3.ld $(FLBENCH)/frames.c \
                   $(LINK_SRC) $(wildcard hal/serial/*.h hal/serial/*.inc) firmware/crc32.c
	$(ARMCC) $(FLBENCH_CFLAGS) -T tools/flbench_m3/flbench_m3.ld tools/flbench_m3/flbench_m3.c \
	  $(FLBENCH)/frames.c $(LINK_SRC) firmware/crc32.c -lgcc -o $@

.PHONY: bench-link
bench-link: deps $(BUILD)/fltool $(BUILD)/render $(BUILD)/bin2c $(BUILD)/insn_count.so
	$(PY) tools/bench_link.py --out $(BUILD)/bench-link.md
