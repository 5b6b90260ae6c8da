#!/usr/bin/env python3
"""The shape of the source tree, for reviews (docs/architecture.md, "Rules a
reviewer checks"):

  scripts/shape.py [--check] [SRC_DIR]

prints, for src/ (default: the src/ next to this script):
  - lines per layer (directory) and the files over 800 lines;
  - functions over 150 lines (C definitions starting at column 0);
  - import cycles between units (a unit is foo.c + foo.h + foo_impl.h) and
    between layers;
  - solver files that test a backend (a backend name compared, an
    #if/#ifdef on PX_HAVE_OPENCL), include a backend's *_impl.h or bind
    OpenCL arguments by number (px_opencl_arg(, clSetKernelArg).
With --check it exits 1 when any rule is broken (for CI once the tree
complies), after printing the same report.
"""
import os
import re
import sys
from collections import defaultdict

FILE_MAX = 800
FUNC_MAX = 150


def sources(src):
    for root, _, files in os.walk(src):
        for f in sorted(files):
            if f.endswith((".c", ".h", ".cl")):
                yield os.path.join(root, f)


def layer(src, path):
    rel = os.path.relpath(path, src)
    parts = rel.split(os.sep)[:-1]
    # solvers/<name>, compute/<backend>, io/geometry: a layer each
    return "/".join(parts[:2]) if parts and parts[0] in ("solvers", "compute", "io") else (
        parts[0] if parts else ".")


def unit(path):
    """foo.c, foo.h and foo_impl.h (foo's private header) are one unit."""
    base = os.path.splitext(path)[0]
    return base[:-5] if base.endswith("_impl") else base


DEF_RE = re.compile(r"^[A-Za-z_][A-Za-z0-9_ \*]*\b([A-Za-z_][A-Za-z0-9_]*)\s*\([^;]*$")


def functions(path, lines):
    """(name, first line, length) of each function definition: a line at
    column 0 that looks like a declarator, up to the `}` at column 0."""
    out = []
    i = 0
    n = len(lines)
    while i < n:
        line = lines[i]
        m = DEF_RE.match(line)
        if m and not line.startswith(("typedef", "#", "return")) and "=" not in line.split("(")[0]:
            # find the opening brace of the body before a `;`
            j = i
            while j < n and "{" not in lines[j] and ";" not in lines[j]:
                j += 1
            if j < n and "{" in lines[j] and ";" not in lines[j].split("{")[0]:
                k = j
                while k < n and not lines[k].startswith("}"):
                    k += 1
                out.append((m.group(1), i + 1, k - i + 1))
                i = k + 1
                continue
        i += 1
    return out


INC_RE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    check = "--check" in sys.argv
    src = args[0] if args else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src")
    src = os.path.normpath(src)
    files = list(sources(src))
    text = {}
    for p in files:
        with open(p, encoding="utf-8", errors="replace") as f:
            text[p] = f.read().split("\n")
    broken = 0

    print("== lines per layer")
    per = defaultdict(int)
    for p in files:
        per[layer(src, p)] += len(text[p])
    for k in sorted(per):
        print(f"{per[k]:7d}  {k}")
    print(f"{sum(per.values()):7d}  total")

    print(f"\n== files over {FILE_MAX} lines")
    for p in sorted(files, key=lambda p: -len(text[p])):
        if len(text[p]) > FILE_MAX and not p.endswith(".cl"):
            print(f"{len(text[p]):7d}  {os.path.relpath(p, src)}")
            broken += 1

    print(f"\n== functions over {FUNC_MAX} lines")
    longf = []
    for p in files:
        if p.endswith(".c") or p.endswith(".h"):
            for name, first, length in functions(p, text[p]):
                if length > FUNC_MAX:
                    longf.append((length, name, os.path.relpath(p, src), first))
    for length, name, rel, first in sorted(longf, reverse=True):
        print(f"{length:7d}  {name}  {rel}:{first}")
    broken += len(longf)

    # include graph between units and between layers
    known = {os.path.relpath(p, src): p for p in files}
    edges = defaultdict(set)
    ledges = defaultdict(set)
    for p in files:
        for line in text[p]:
            m = INC_RE.match(line)
            if not m:
                continue
            inc = m.group(1)
            target = known.get(inc)
            if not target:
                continue
            a, b = unit(os.path.relpath(p, src)), unit(inc)
            if a != b:
                edges[a].add(b)
            la, lb = layer(src, p), layer(src, target)
            if la != lb:
                ledges[la].add(lb)

    def cycles(graph):
        # strongly connected components with more than one node (Tarjan)
        index, low, stack, on, out = {}, {}, [], set(), []
        counter = [0]

        def visit(v):
            index[v] = low[v] = counter[0]
            counter[0] += 1
            stack.append(v)
            on.add(v)
            for w in sorted(graph.get(v, ())):
                if w not in index:
                    visit(w)
                    low[v] = min(low[v], low[w])
                elif w in on:
                    low[v] = min(low[v], index[w])
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop()
                    on.discard(w)
                    comp.append(w)
                    if w == v:
                        break
                if len(comp) > 1:
                    out.append(sorted(comp))

        sys.setrecursionlimit(10000)
        for v in sorted(graph):
            if v not in index:
                visit(v)
        return out

    # a unit's .c including its own header is not a cycle; a header pair
    # foo.h <-> foo_impl.h is one unit in spirit: both .c and .h of a unit
    # map to the same node already (unit = path without extension)
    print("\n== import cycles between units (files without extension)")
    uc = cycles(edges)
    for c in uc:
        print("  " + " <-> ".join(c))
    print("\n== import cycles between layers")
    lc = cycles(ledges)
    for c in lc:
        print("  " + " <-> ".join(c))
    broken += len(uc) + len(lc)

    print("\n== solver code that tests a backend or binds OpenCL arguments by number")
    bad = re.compile(r'strcmp\([^)]*"(cpu|opencl)"|"(cpu|opencl)"\s*\)\s*==\s*0|'
                     r'#\s*if(def)?\b.*PX_HAVE_OPENCL|#\s*if\s+defined\(PX_HAVE_OPENCL|'
                     r'_impl\.h"|px_opencl_arg\(|px_opencl_arg_mem\(|px_opencl_arg_local\(|'
                     r'clSetKernelArg')
    for p in files:
        rel = os.path.relpath(p, src)
        if not rel.startswith("solvers" + os.sep):
            continue
        for i, line in enumerate(text[p]):
            if bad.search(line):
                # a solver's own *_impl.h is its business, and
                # compute/backend_impl.h (PX_BACKEND_PICK, PX_IF_OPENCL) is for
                # every module; a backend's internals are not
                if '_impl.h"' in line and not re.search(r'compute/(opencl|cpu)/', line):
                    continue
                print(f"  {rel}:{i + 1}: {line.strip()}")
                broken += 1

    print(f"\n{broken} rule(s) broken")
    return 1 if check and broken else 0


if __name__ == "__main__":
    sys.exit(main())
