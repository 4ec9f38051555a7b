# things.mk - the Doom thing table (tools/bspc/things.txt, docs/objects.md)
# built into the scene compiler: bin2c turns it into $(GEN)/things_txt.h,
# which tools/bspc/wad.c includes, so build/bspc and every program that
# compiles scenes need no file beside them. tools/refrender.py reads the
# same text.

THINGS_H := $(GEN)/things_txt.h
$(THINGS_H): tools/bspc/things.txt $(BUILD)/bin2c
	@mkdir -p $(@D)
	$(BUILD)/bin2c bs_things_txt $< > $@

# Every variant compiles wad.c into one of these two folders (mk/report.mk and
# mk/link.mk reuse build/obj).
THINGS_USERS := $(BUILD)/obj/tools/bspc/wad.o $(BUILD)/san/obj/tools/bspc/wad.o
$(THINGS_USERS): $(THINGS_H)
$(THINGS_USERS): BASE += -I$(GEN)
