#!/usr/bin/env python3
"""include_graph.py - who includes whom among firmware/, hal/, host/ and tools/.

A module is a source file and its header together (firmware/render.c and
firmware/render.h are the module firmware/render), so a circle shows even when
it runs through a .c file: spans.c including render.h while render.c includes
spans.h is the module circle render -> spans -> render, though no header
includes itself back.

    tools/include_graph.py [ROOT]      cycles, then the host <-> tools edges

Exit status 1 if a cycle lies within firmware/ and hal/ (the freestanding
core and its targets), else 0. Quoted includes only (<...> are the system's);
a name is looked up beside the including file, then along the Makefile's -I
list, then anywhere in the four trees (all matches: a name two targets define,
like log.h, links to both).
"""
import os
import re
import sys

TREES = ("firmware", "hal", "host", "tools")
# the Makefile's INC, in order
INCLUDE_DIRS = ("firmware", "hal", "hal/null", "hal/sdl", "hal/serial", "tools/bspc", "host")
INCLUDE_RE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)
SOURCE_EXT = (".c", ".h")


def source_files(root):
    """Relative paths of every .c and .h under the four trees."""
    out = []
    for tree in TREES:
        for d, _, names in os.walk(os.path.join(root, tree)):
            for n in names:
                if n.endswith(SOURCE_EXT):
                    out.append(os.path.relpath(os.path.join(d, n), root))
    return sorted(out)


def module_of(path):
    return os.path.splitext(path)[0]


def resolve(root, including, name, by_base):
    """The files an include of name in file including can mean."""
    here = os.path.normpath(os.path.join(os.path.dirname(including), name))
    if os.path.isfile(os.path.join(root, here)):
        return [here]
    for d in INCLUDE_DIRS:
        p = os.path.normpath(os.path.join(d, name))
        if os.path.isfile(os.path.join(root, p)):
            return [p]
    return by_base.get(os.path.basename(name), [])


def module_graph(root):
    """{module: set of modules it includes}, without self-edges."""
    files = source_files(root)
    by_base = {}
    for f in files:
        by_base.setdefault(os.path.basename(f), []).append(f)
    graph = {module_of(f): set() for f in files}
    for f in files:
        with open(os.path.join(root, f), encoding="utf-8", errors="replace") as fh:
            text = fh.read()
        for name in INCLUDE_RE.findall(text):
            for target in resolve(root, f, name, by_base):
                a, b = module_of(f), module_of(target)
                if a != b:
                    graph[a].add(b)
    return graph


def cycles(graph):
    """Strongly connected components of more than one module (Tarjan's,
    iterative: no recursion limit), each sorted; the list sorted."""
    index, low, on_stack, stack, out = {}, {}, set(), [], []
    counter = 0
    for start in sorted(graph):
        if start in index:
            continue
        work = [(start, iter(sorted(graph[start])))]
        index[start] = low[start] = counter
        counter += 1
        stack.append(start)
        on_stack.add(start)
        while work:
            v, it = work[-1]
            advanced = False
            for w in it:
                if w not in graph:
                    continue
                if w not in index:
                    index[w] = low[w] = counter
                    counter += 1
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(sorted(graph[w]))))
                    advanced = True
                    break
                if w in on_stack:
                    low[v] = min(low[v], index[w])
            if advanced:
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop()
                    on_stack.discard(w)
                    comp.append(w)
                    if w == v:
                        break
                if len(comp) > 1:
                    out.append(sorted(comp))
    return sorted(out)


def tree_of(module):
    return module.split("/", 1)[0]


def core_cycles(graph):
    """Cycles whose modules all lie in firmware/ and hal/."""
    core = {m: {t for t in ts if tree_of(t) in ("firmware", "hal")}
            for m, ts in graph.items() if tree_of(m) in ("firmware", "hal")}
    return cycles(core)


def cross_edges(graph, a, b):
    """Module edges from tree a into tree b, sorted."""
    return sorted((m, t) for m, ts in graph.items() if tree_of(m) == a for t in ts if tree_of(t) == b)


def main(argv):
    root = argv[1] if len(argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    graph = module_graph(root)
    every = cycles(graph)
    core = core_cycles(graph)
    print(f"{len(graph)} modules, {sum(len(t) for t in graph.values())} include edges between them")
    print(f"cycles: {len(every)} ({len(core)} within firmware/ and hal/)")
    for c in every:
        print("  cycle: " + " <-> ".join(c))
    for a, b in (("host", "tools"), ("tools", "host")):
        edges = cross_edges(graph, a, b)
        print(f"{a} -> {b}: {len(edges)} edges")
        for m, t in edges:
            print(f"  {m} -> {t}")
    return 1 if core else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
