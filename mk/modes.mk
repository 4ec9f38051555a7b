# modes.mk - which render modes a bare-metal build compiles in (make firmware:
# FW_MODES, make pcvga: PC_MODES), as firmware/build_config.h's CFG_RENDER_MODES
# (bit 0 spans, bit 1 painter, bit 2 direct, bit 3 columns). The renderer's work area is only
# what the modes compiled in need (render_work_bytes).
#
#   $(call render_modes_mask,LIST)  LIST: render modes separated by commas,
#                                   e.g. direct or direct,spans,painter -> 4 or 7
#   $(call render_modes_def,LIST)   -> -DCFG_RENDER_MODES=MASK

comma := ,
RENDER_MODE_BIT_spans := 1
RENDER_MODE_BIT_painter := 2
RENDER_MODE_BIT_direct := 4
RENDER_MODE_BIT_columns := 8
RENDER_MODES_ALL := direct,spans,painter,columns

render_modes_list = $(sort $(subst $(comma), ,$(1)))
render_modes_check = $(if $(strip $(call render_modes_list,$(1))),,$(error modes: no render mode given (direct, spans, painter, columns)))$(foreach m,$(call render_modes_list,$(1)),$(if $(RENDER_MODE_BIT_$(m)),,$(error modes: '$(m)' in '$(1)' is not a render mode (direct, spans, painter, columns))))
render_modes_mask = $(strip $(call render_modes_check,$(1))$(shell echo $$(( 0 $(foreach m,$(call render_modes_list,$(1)),+ $(RENDER_MODE_BIT_$(m))) ))))
render_modes_def = -DCFG_RENDER_MODES=$(call render_modes_mask,$(1))

# FLAT=1: a bare-metal build without the texture code; textured scenes are drawn
# in their flat colours (a slow display link, a small flash).
FLAT ?=
flat_def = $(if $(filter 1,$(FLAT)),-DCFG_FLAT=1)
