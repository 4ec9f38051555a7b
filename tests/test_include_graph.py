"""No include circle in firmware/ and hal/ (tools/include_graph.py): a module
(a .c and its .h) never includes, directly or around a circle, a module that
includes it back, so the render modes depend on the shared code and not the
reverse."""
import importlib.util
import subprocess
import sys

from conftest import ROOT

spec = importlib.util.spec_from_file_location("include_graph", ROOT / "tools" / "include_graph.py")
include_graph = importlib.util.module_from_spec(spec)
spec.loader.exec_module(include_graph)


def test_no_cycle_in_firmware_or_hal():
    graph = include_graph.module_graph(str(ROOT))
    assert "firmware/render" in graph and "firmware/spans" in graph  # the tree was read
    assert include_graph.core_cycles(graph) == []


def test_no_mode_includes_the_dispatcher():
    graph = include_graph.module_graph(str(ROOT))
    for mode in ("firmware/direct", "firmware/spans", "firmware/painter", "firmware/surfaces"):
        assert "firmware/render" not in graph[mode], mode
    assert {"firmware/direct", "firmware/spans", "firmware/painter"} <= graph["firmware/render"]


def write(root, path, text):
    p = root / path
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_text(text)


def test_a_circle_through_a_c_file_is_found(tmp_path):
    # the old shape of the core: spans.c includes render.h, render.c includes spans.h
    write(tmp_path, "firmware/render.h", "int render(void);\n")
    write(tmp_path, "firmware/render.c", '#include "render.h"\n#include "spans.h"\n')
    write(tmp_path, "firmware/spans.h", "int spans(void);\n")
    write(tmp_path, "firmware/spans.c", '#include "spans.h"\n#include "render.h"\n')
    write(tmp_path, "firmware/raster.h", '#include "scene.h"\n')
    write(tmp_path, "firmware/scene.h", "int scene;\n")
    graph = include_graph.module_graph(str(tmp_path))
    assert include_graph.core_cycles(graph) == [["firmware/render", "firmware/spans"]]
    proc = subprocess.run([sys.executable, str(ROOT / "tools" / "include_graph.py"), str(tmp_path)],
                          capture_output=True, text=True)
    assert proc.returncode == 1 and "firmware/render <-> firmware/spans" in proc.stdout


def test_a_long_circle_and_the_include_path(tmp_path):
    # hal/a.c -> firmware/b.h (found on the -I path) -> hal/c.h -> hal/a.h
    write(tmp_path, "hal/a.c", '#include "b.h"\n')
    write(tmp_path, "hal/a.h", "\n")
    write(tmp_path, "firmware/b.h", '#include "c.h"\n')
    write(tmp_path, "hal/c.h", '#include "a.h"\n')
    write(tmp_path, "host/d.c", '#include "b.h"\n#include <stdio.h>\n')
    graph = include_graph.module_graph(str(tmp_path))
    assert include_graph.core_cycles(graph) == [["firmware/b", "hal/a", "hal/c"]]
    assert graph["host/d"] == {"firmware/b"}


def test_host_and_tools_depend_one_way():
    """host/ uses the compiler's library in tools/ (scene loading, fxtext); nothing in tools/
    includes host/ (issue 19: the arrow points one way)."""
    graph = include_graph.module_graph(str(ROOT))
    assert include_graph.cross_edges(graph, "host", "tools"), "host/ no longer uses tools/: update this test"
    assert include_graph.cross_edges(graph, "tools", "host") == []
