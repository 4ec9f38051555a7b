# make compare-doom: the project's frame of a Doom map's player start beside Chocolate Doom's
# (tools/doomcompare.py) -> build/compare/*.png and the share of 8x8 blocks that agree, over
# the whole frame (Doom's weapon left out), the blocks with things and the other blocks.
# MAP=FILE.wad:MAP picks one map (several, space-separated; `all`: the 43 Freedoom starts of
# docs/benchmarks.md); the default is the README's two.
COMPARE_MAPS := freedoom2.wad:MAP29 freedoom1.wad:E1M1
MAP ?= $(COMPARE_MAPS)

.PHONY: compare-doom
compare-doom: deps $(BUILD)/render
	$(PY) tools/doomcompare.py --render $(BUILD)/render $(MAP)
