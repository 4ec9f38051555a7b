# fuzz.mk - libFuzzer harnesses (tests/fuzz/, docs/fuzzing.md): every decoder of
# outside bytes fed garbage under ASan and UBSan.
#
#   make fuzz [FUZZ_TIME=60] [FUZZ_JOBS=2] [FUZZ=text wad ...]
#       each harness for FUZZ_TIME seconds from its seeds (real inputs), its kept
#       regressions and the corpus it grew before (build/fuzz/corpus/NAME);
#       crashes land in build/fuzz/crashes/NAME/; figures in build/fuzz/report.md
#   make fuzz-smoke   (part of make test) every seed and regression once, then a
#                     few seconds of fuzzing each
#
# Harnesses (tests/fuzz/fuzz_NAME.c; seeds from tests/fuzz/seeds_NAME.py or tools/fuzz.py):
#   text    the scene text parser, through the whole compile and the loader
#   wad     the WAD map reader, through the whole compile and the loader
#   scene   the compiled-scene loader (the firmware's), then a frame of what it accepts
#   render  the renderer: scenes the compiler accepts, seen from arbitrary cameras
#   link    the frame-link decoder
#   dfu     the DFU image and suffix parser

FUZZ_CC    := clang
FUZZ_DIR   := $(BUILD)/fuzz
FUZZ_SAN   := -fsanitize=address,undefined -fno-sanitize-recover=all
FUZZ_CFLAGS = -std=c11 -g -O1 -fno-omit-frame-pointer -fno-strict-aliasing $(WARN) $(INC) -D_DEFAULT_SOURCE \
              -Ihost/flash -Ifirmware/dfu -Itests/fuzz $(FUZZ_SAN)
FUZZ_NAMES := text wad scene render link dfu
FUZZ_TIME  ?= 60
FUZZ_JOBS  ?= 2

FUZZ_ENGINE := $(BSPC_LIB) $(FW_SRC) $(HAL_SRC) $(NULL_SRC) tests/fuzz/fuzz_common.c
FUZZ_SRC_text   := $(FUZZ_ENGINE)
FUZZ_SRC_wad    := $(FUZZ_ENGINE)
FUZZ_SRC_scene  := $(FUZZ_ENGINE)
FUZZ_SRC_render := $(FUZZ_ENGINE)
FUZZ_SRC_link   := $(LINK_SRC) firmware/crc32.c
FUZZ_SRC_dfu    := firmware/dfu/dfu_device.c firmware/dfu/dfu_image.c firmware/dfu/dfu_proto.c firmware/crc32.c

$(FUZZ_DIR)/obj/%.o: %.c $(GEN)/fx_tables.c
	@mkdir -p $(@D)
	$(FUZZ_CC) $(FUZZ_CFLAGS) -fsanitize=fuzzer-no-link -MMD -MP -c $< -o $@

$(FUZZ_DIR)/obj/tools/bspc/wad.o: $(THINGS_H)
$(FUZZ_DIR)/obj/tools/bspc/wad.o: FUZZ_CFLAGS += -I$(GEN)

define fuzz_harness
$(FUZZ_DIR)/fuzz_$(1): $(FUZZ_DIR)/obj/tests/fuzz/fuzz_$(1).o $(patsubst %.c,$(FUZZ_DIR)/obj/%.o,$(FUZZ_SRC_$(1)))
	$$(FUZZ_CC) $(FUZZ_SAN) -fsanitize=fuzzer $$^ -o $$@ -lm
endef
$(foreach h,$(FUZZ_NAMES),$(eval $(call fuzz_harness,$(h))))

FUZZ_BINS := $(addprefix $(FUZZ_DIR)/fuzz_,$(FUZZ_NAMES))
# Seeds are made by the programs under test: compiled scenes, streams, images.
FUZZ_TOOLS := $(BUILD)/bspc $(BUILD)/fltool $(BUILD)/flash

.PHONY: fuzz fuzz-smoke fuzz-build
fuzz-build: $(FUZZ_BINS)
fuzz: deps $(FUZZ_BINS) $(FUZZ_TOOLS)
	$(PY) tools/fuzz.py --time $(FUZZ_TIME) --jobs $(FUZZ_JOBS) $(FUZZ)
fuzz-smoke: $(FUZZ_BINS) $(FUZZ_TOOLS)
	$(PY) tools/fuzz.py --smoke $(FUZZ)
