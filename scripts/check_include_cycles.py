#!/usr/bin/env python3
"""Fails if the files of one folder include each other in a circle (docs/design.md "Layers").

A file pair (x.h with x.cpp) is one node; x -> y when x.h or x.cpp includes y.h from the same
folder. A circle (flow_config.cpp includes a registry whose header includes flow_config.h) means
neither file pair can be read, tested or moved without the other. Tests, fuzz targets and
examples are left out. Usage: check_include_cycles.py [ROOT]; --self-test checks that a circle in a
made-up tree is found.
"""
import os
import re
import subprocess
import sys
import tempfile

SKIP = ("tests/", "fuzz/", "examples/", "build")


def graph(root, files):
    edges = {}
    for f in files:
        if f.startswith(SKIP):
            continue
        folder, node = os.path.dirname(f), os.path.splitext(f)[0]
        edges.setdefault(node, set())
        with open(os.path.join(root, f), errors="replace") as text:
            for line in text:
                m = re.match(r'\s*#include "([^"]+)"', line)
                if m and os.path.dirname(m.group(1)) == folder:
                    target = os.path.splitext(m.group(1))[0]
                    if target != node:
                        edges[node].add(target)
    return edges


def circles(edges):
    """Strongly connected components of more than one node (Tarjan, iterative)."""
    index, low, on, stack, found, counter = {}, {}, set(), [], [], [0]
    for start in sorted(edges):
        if start in index:
            continue
        work = [(start, iter(sorted(edges.get(start, ()))))]
        index[start] = low[start] = counter[0]
        counter[0] += 1
        stack.append(start)
        on.add(start)
        while work:
            v, it = work[-1]
            advanced = False
            for w in it:
                if w not in index:
                    index[w] = low[w] = counter[0]
                    counter[0] += 1
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(sorted(edges.get(w, ())))))
                    advanced = True
                    break
                if w in on:
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
                    on.discard(w)
                    comp.append(w)
                    if w == v:
                        break
                if len(comp) > 1:
                    found.append(sorted(comp))
    return found


def check(root, files):
    found = circles(graph(root, files))
    for comp in found:
        print("include circle in %s/: %s" % (os.path.dirname(comp[0]), " <-> ".join(comp)))
    return 1 if found else 0


def self_test():
    with tempfile.TemporaryDirectory() as root:
        os.makedirs(os.path.join(root, "flows"))
        files = {"flows/a.h": "", "flows/a.cpp": '#include "flows/a.h"\n#include "flows/b.h"\n',
                 "flows/b.h": '#include "flows/a.h"\n', "flows/c.h": '#include "flows/a.h"\n'}
        for name, text in files.items():
            with open(os.path.join(root, name), "w") as out:
                out.write(text)
        if check(root, list(files)) != 1:
            print("self-test: the circle a <-> b was not found")
            return 1
        del files["flows/b.h"]
        if check(root, list(files)) != 0:
            print("self-test: a tree without a circle was refused")
            return 1
    print("self-test: ok")
    return 0


if __name__ == "__main__":
    if sys.argv[1:] == ["--self-test"]:
        sys.exit(self_test())
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..")
    listed = subprocess.check_output(["git", "-C", root, "ls-files", "*.h", "*.cpp"], text=True)
    status = check(root, listed.split())
    if status == 0:
        print("no include circle inside any folder")
    sys.exit(status)
