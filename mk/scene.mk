# scene.mk - host programs built for one scene (docs/needs.md): the renderer
# with only the features the scene needs, every fixed buffer sized to the
# bounds the compiler proved for it, and a loader that refuses any scene that
# needs more.
#
#   make scene-host SCENE=... [SCENE_OUT=DIR]
#       -> DIR/render, DIR/emu (the scene built in) and DIR/san/render (ASan +
#          UBSan); DIR defaults to build/scene/NAME, NAME from SCENE's file name
#          (freedoom2.wad:MAP01 -> freedoom2_wad-MAP01). SCENE as for make
#          firmware: a text scene, file.wad:MAP01 or a compiled .bsc.
#   DIR/scene_config.h is what bspc --config wrote for the scene
#   (firmware/build_config.h reads it).
#
# The Cortex-M firmware is built for its scene the same way by make firmware
# (mk/mps2.mk; FULL=1 there builds every feature in).

scene_name = $(subst :,-,$(subst .,_,$(notdir $(1))))
SCENE_OUT ?= $(BUILD)/scene/$(call scene_name,$(SCENE))

# Only the firmware and the programs' mains read build_config.h; the compiler,
# PNG writer and HAL objects are shared with build/ (build/san/).
SCENE_SRC    := $(FW_SRC) $(HOST_ENG) host/render.c
SCENE_SHARED := $(HOST_LIB) $(BSPC_LIB) $(HAL_SRC) $(NULL_SRC)

.PHONY: scene-host SCENE_FORCE
SCENE_FORCE:

# The scene, rewritten only when it changes.
$(SCENE_OUT)/scene: SCENE_FORCE
	@mkdir -p $(@D)
	@echo '$(SCENE)' | cmp -s - $@ || echo '$(SCENE)' > $@

# Recipes shared with mk/mps2.mk. $(1) the compiled scene to write: SCENE
# compiled by build/bspc, or copied when it is compiled already; $(2) who says so.
define scene_bsc_recipe
	@mkdir -p $(dir $(1))
	@case '$(SCENE)' in \
	  *.bsc) echo "$(2): $(SCENE) is compiled already: used as it is"; cp '$(SCENE)' $(1) ;; \
	  *) $(BUILD)/bspc '$(SCENE)' -o $(1) ;; \
	esac
endef
# $(1) the compiled scene, $(2) the header to write (only when it changes), $(3)
# who says so. A scene that does not load gets every feature, so the build
# refuses it at start with the loader's message.
define scene_config_recipe
	@$(BUILD)/bspc $(1) --config $(2).tmp || { echo "$(3): built with every feature (it will refuse the scene)"; \
	  echo '/* the scene does not load: every feature (build_config.h) */' > $(2).tmp; }
	@cmp -s $(2).tmp $(2) || mv $(2).tmp $(2)
	@rm -f $(2).tmp
endef

$(SCENE_OUT)/scene.bsc: $(SCENE_OUT)/scene $(BUILD)/bspc $(wildcard $(firstword $(subst :, ,$(SCENE))))
	$(call scene_bsc_recipe,$@,scene-host)
$(SCENE_OUT)/scene_config.h: $(SCENE_OUT)/scene.bsc $(BUILD)/bspc
	$(call scene_config_recipe,$<,$@,scene-host)

SCENE_DEF = -DSCENE_CONFIG='"$(abspath $(SCENE_OUT)/scene_config.h)"'

# $(1) output folder, $(2) optimisation flags, $(3) folder of the shared objects
define scene_variant
$(1)/obj/%.o: %.c $(GEN)/fx_tables.c $(SCENE_OUT)/scene_config.h
	@mkdir -p $$(@D)
	$$(CC) $$(BASE) $(2) $$(SCENE_DEF) $$(call fwflags,$$<) $$(if $$(filter host/emu.c,$$<),$$(SDL_CFLAGS)) -MMD -MP -c $$< -o $$@
$(1)/render: $(patsubst %.c,$(1)/obj/%.o,$(SCENE_SRC)) $(patsubst %.c,$(3)/obj/%.o,$(SCENE_SHARED))
	$$(CC) $(2) $$^ -o $$@ $$(PNG_LIBS) -lm
endef
$(eval $(call scene_variant,$(SCENE_OUT),$(REL),$(BUILD)))
$(eval $(call scene_variant,$(SCENE_OUT)/san,$(SAN),$(BUILD)/san))

# emu with the scene built in (host/emu.c's default_scene)
$(SCENE_OUT)/gen/scene_blob.c: $(SCENE_OUT)/scene.bsc $(BUILD)/bin2c
	@mkdir -p $(@D)
	$(BUILD)/bin2c default_scene $< > $@
$(SCENE_OUT)/obj/gen/scene_blob.o: $(SCENE_OUT)/gen/scene_blob.c
	@mkdir -p $(@D)
	$(CC) $(BASE) $(REL) $(FW_FLAGS) -c $< -o $@
$(SCENE_OUT)/emu: $(patsubst %.c,$(SCENE_OUT)/obj/%.o,$(FW_SRC) $(HOST_ENG) host/emu.c) $(SCENE_OUT)/obj/gen/scene_blob.o \
                  $(patsubst %.c,$(BUILD)/obj/%.o,$(HOST_LIB) $(BSPC_LIB) $(HAL_SRC) $(SDL_SRC))
	$(CC) $(REL) $^ -o $@ $(SDL_LIBS) $(PNG_LIBS) -lm

scene-host: $(SCENE_OUT)/render $(SCENE_OUT)/san/render $(SCENE_OUT)/emu
	@echo "scene-host: $(SCENE_OUT)/render, emu, san/render built for $(SCENE) ($$(sed -n 's/^#define CFG_FEATURES \(0x[0-9a-f]*\)u.*/features \1/p' $(SCENE_OUT)/scene_config.h))"
