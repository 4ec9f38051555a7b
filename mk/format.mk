# mk/format.mk - one written style (HACKING.md, .clang-format):
#   make format         rewrite the project's C files in place with clang-format
#   make format-check   list the files that differ from .clang-format and fail; changes nothing
#                       (the first step of make test)
#
# The files are the project's own C, named folder by folder. Left out, on purpose:
#   build/               generated sources (fx_tables.c, default_scene.c): rewritten by every build
#   *.inc                number tables written by a generator (hal/serial/fl_tables.inc comes from
#                        tools/framelink.py --train); the generator owns their layout
# Formatting differs between clang-format releases; the config is written for clang-format 14
# (Debian bookworm's clang-format, installed by make deps).
CLANG_FORMAT ?= clang-format
FORMAT_STYLE := $(CURDIR)/.clang-format
FORMAT_DIRS := firmware firmware/dfu hal hal/bare hal/board hal/mps2 hal/null hal/pcvga hal/sdl hal/serial \
               host host/flash tools tools/bspc tools/flbench_m3 tools/qemu_plugin tests/unit tests/fuzz
FORMAT_SRC := $(sort $(foreach d,$(FORMAT_DIRS),$(wildcard $(d)/*.c $(d)/*.h)))

.PHONY: format format-check
format:
	@$(CLANG_FORMAT) -i --style=file:$(FORMAT_STYLE) $(FORMAT_SRC)
	@echo "format: $(words $(FORMAT_SRC)) files"

format-check:
	@command -v $(CLANG_FORMAT) >/dev/null || { echo "format-check: $(CLANG_FORMAT) not found (make deps)"; exit 1; }
	@bad=$$(for f in $(FORMAT_SRC); do $(CLANG_FORMAT) --style=file:$(FORMAT_STYLE) "$$f" | cmp -s - "$$f" || echo "$$f"; done); \
	if [ -n "$$bad" ]; then \
	  echo "format-check: these files differ from .clang-format (make format rewrites them):"; \
	  echo "$$bad" | sed 's/^/  /'; exit 1; \
	fi; \
	echo "format-check: $(words $(FORMAT_SRC)) files match .clang-format"
