# report.mk - the precision knobs' configurations and `make report`: error
# against the reference renderer versus instructions per frame.
#
#   make report   builds build/knob/CONFIG/render (-O2) for every configuration
#                 below and runs tools/report.py: per configuration and render
#                 mode, the error against tools/refrender.py over the bench views
#                 and the extreme scenes' views, the texel-and-light error
#                 against tools/reflook.py over the bench views, and
#                 instructions per frame (callgrind) over the bench views
#                 -> build/report/report.md, build/report/error_vs_ir.png
#   make build/knob/CONFIG/render      one configuration
#   make build/knob/CONFIG/san/render  the same with ASan + UBSan
#   make report-configs                prints the table, one "NAME: FLAGS" a line
#
# The knobs (documented where they are defined): VIEW_SHIFT, VIEW_SUBPIXEL_BITS,
# VIEW_RECIP_BITS (firmware/view.h), RAST_STEP_BITS (firmware/raster.h),
# FX_SIN_BITS, FX_SIN_LERP (firmware/fixed.h); the texture knobs TEX_SUBDIV_BITS,
# TEX_RECIP_BITS, TEX_LIGHT_BITS (firmware/texture.h), whose error the report
# also gives as the share of pixels not within one texel and one light step of
# tools/reflook.py. Configuration "default" sets none and draws exactly what
# build/render draws.

KNOB := $(BUILD)/knob
# The configurations' compile lines (some 480 of them) are shown with V=1 only;
# each finished binary is named instead.
KNOB_Q := $(if $(filter 1,$(V)),,@)

# name -> flags. A few values of each knob, from nearly exact to coarse, and one
# configuration that combines cheap choices of three of them.
KNOB_FLAGS_default  :=
KNOB_FLAGS_subpix8  := -DVIEW_SUBPIXEL_BITS=8
KNOB_FLAGS_subpix4  := -DVIEW_SUBPIXEL_BITS=4
KNOB_FLAGS_subpix2  := -DVIEW_SUBPIXEL_BITS=2
KNOB_FLAGS_subpix0  := -DVIEW_SUBPIXEL_BITS=0
KNOB_FLAGS_step16   := -DRAST_STEP_BITS=16
KNOB_FLAGS_step12   := -DRAST_STEP_BITS=12
KNOB_FLAGS_step8    := -DRAST_STEP_BITS=8
KNOB_FLAGS_step6    := -DRAST_STEP_BITS=6
KNOB_FLAGS_step4    := -DRAST_STEP_BITS=4
KNOB_FLAGS_recip12  := -DVIEW_RECIP_BITS=12
KNOB_FLAGS_recip8   := -DVIEW_RECIP_BITS=8
KNOB_FLAGS_recip6   := -DVIEW_RECIP_BITS=6
KNOB_FLAGS_recip4   := -DVIEW_RECIP_BITS=4
KNOB_FLAGS_view12   := -DVIEW_SHIFT=12
KNOB_FLAGS_view10   := -DVIEW_SHIFT=10
KNOB_FLAGS_view8    := -DVIEW_SHIFT=8
KNOB_FLAGS_view6    := -DVIEW_SHIFT=6
KNOB_FLAGS_sin8     := -DFX_SIN_BITS=8
KNOB_FLAGS_sin4     := -DFX_SIN_BITS=4
KNOB_FLAGS_sin12n   := -DFX_SIN_BITS=12 -DFX_SIN_LERP=0
KNOB_FLAGS_sin8n    := -DFX_SIN_BITS=8 -DFX_SIN_LERP=0
KNOB_FLAGS_cheap    := -DRAST_STEP_BITS=8 -DVIEW_RECIP_BITS=8 -DVIEW_SUBPIXEL_BITS=4
# textures: wall span subdivision (default 2^3 pixels), the depth reciprocal
# table (default: exact divides), light steps (default all 32 tables)
KNOB_FLAGS_texsub0    := -DTEX_SUBDIV_BITS=0
KNOB_FLAGS_texsub2    := -DTEX_SUBDIV_BITS=2
KNOB_FLAGS_texsub4    := -DTEX_SUBDIV_BITS=4
KNOB_FLAGS_texsub5    := -DTEX_SUBDIV_BITS=5
KNOB_FLAGS_texrecip12 := -DTEX_RECIP_BITS=12
KNOB_FLAGS_texrecip8  := -DTEX_RECIP_BITS=8
KNOB_FLAGS_texrecip6  := -DTEX_RECIP_BITS=6
KNOB_FLAGS_texlight4  := -DTEX_LIGHT_BITS=4
KNOB_FLAGS_texlight3  := -DTEX_LIGHT_BITS=3
KNOB_FLAGS_texlight2  := -DTEX_LIGHT_BITS=2
# and no textures at all: the build without the texture code (CFG_FLAT=1), the
# flat-shaded frame of the same scenes
KNOB_FLAGS_flat       := -DCFG_FLAT=1
REPORT_CONFIGS := default subpix8 subpix4 subpix2 subpix0 step16 step12 step8 step6 step4 \
                  recip12 recip8 recip6 recip4 view12 view10 view8 view6 sin8 sin4 sin12n sin8n cheap \
                  texsub0 texsub2 texsub4 texsub5 texrecip12 texrecip8 texrecip6 texlight4 texlight3 texlight2 \
                  flat

# Only the firmware and build/render's main include the knobs' headers; the
# scene compiler, PNG writer and HAL objects are shared with build/ (build/san/).
KNOB_SRC    := $(FW_SRC) $(HOST_ENG) host/render.c
KNOB_SHARED := $(HOST_LIB) $(BSPC_LIB) $(HAL_SRC) $(NULL_SRC)

.PHONY: report report-configs REPORT_FORCE
REPORT_FORCE:

# $(1) config, $(2) output folder, $(3) optimisation flags, $(4) folder of the shared objects
define knob_variant
$(2)/obj/%.o: %.c $(GEN)/fx_tables.c $(KNOB)/$(1)/flags
	@mkdir -p $$(@D)
	$$(KNOB_Q)$$(CC) $$(BASE) $(3) $$(KNOB_FLAGS_$(1)) $$(if $$(filter $$(FLOATFREE),$$<),$$(FW_FLAGS)) -MMD -MP -c $$< -o $$@
$(2)/render: $(patsubst %.c,$(2)/obj/%.o,$(KNOB_SRC)) $(patsubst %.c,$(4)/obj/%.o,$(KNOB_SHARED))
	$$(KNOB_Q)$$(CC) $(3) $$^ -o $$@ $$(PNG_LIBS) -lm
	$$(if $$(KNOB_Q),@echo "report: built $$@")
endef

# The flags a configuration was built with, rewritten only when they change, so
# that editing the table rebuilds what it must.
define knob_config
$(KNOB)/$(1)/flags: REPORT_FORCE
	@mkdir -p $$(@D)
	@echo '$$(strip $$(KNOB_FLAGS_$(1)))' | cmp -s - $$@ || echo '$$(strip $$(KNOB_FLAGS_$(1)))' > $$@
$(eval $(call knob_variant,$(1),$(KNOB)/$(1),$(REL),$(BUILD)))
$(eval $(call knob_variant,$(1),$(KNOB)/$(1)/san,$(SAN),$(BUILD)/san))
endef
$(foreach c,$(REPORT_CONFIGS),$(eval $(call knob_config,$(c))))

KNOB_RENDERS := $(foreach c,$(REPORT_CONFIGS),$(KNOB)/$(c)/render)

report-configs:
	@$(foreach c,$(REPORT_CONFIGS),echo '$(c): $(strip $(KNOB_FLAGS_$(c)))';)

# make report REPORT_CONFIGS="default subpix0": a few configurations only;
# REPORT_ARGS: more options of tools/report.py (--views N, --tex-views N, --m3-views N, --no-ir, --jobs N).
report: deps $(BUILD)/bspc $(BUILD)/render $(BUILD)/bin2c $(BUILD)/insn_count.so $(KNOB_RENDERS)
	$(PY) tools/report.py --configs $(REPORT_CONFIGS) $(REPORT_ARGS)

# tests/test_report.py renders with two knob configurations beside the default.
pytest: $(KNOB)/default/render $(KNOB)/subpix0/render $(KNOB)/subpix0/san/render $(KNOB)/texlight2/render

# (their dependency files are included with the rest of build/ by the Makefile)
