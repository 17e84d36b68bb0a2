#!/usr/bin/env python3
"""Fails if a function outside the tests is longer than LIMIT lines (150), signature to closing
brace: a longer one does several things that each want a name (docs/design.md "Layers").

It reads the sources as clang-format lays them out, without a compiler: comments and string
literals are dropped, then braces are matched; a brace opened at namespace or class scope after a
parenthesised header (a function, a constructor, a namespace-scope lambda, a macro's body such as
PYBIND11_MODULE) opens a function. Tests, fuzz targets and examples are left out.
Usage: check_function_length.py [ROOT]; --self-test checks that a made-up long function is found.
"""
import os
import re
import subprocess
import sys
import tempfile

LIMIT = 150
SKIP = ("tests/", "fuzz/", "examples/", "build")


def code_only(text):
    """`text` with comments, preprocessor lines and string and character literals blanked,
    newlines kept."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if c == "#" and text[text.rfind("\n", 0, i) + 1:i].strip() == "":
            j = i
            while True:  # to the end of the directive, over its continued lines
                j = text.find("\n", j)
                if j < 0 or text[j - 1] != "\\":
                    break
                j += 1
            j = n if j < 0 else j
            out.append("\n" * text.count("\n", i, j))
            i = j
        elif text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("\n" * text.count("\n", i, j))
            i = j
        elif c == "R" and text.startswith('R"', i) and (i == 0 or not text[i - 1].isalnum()):
            k = text.find("(", i)
            end = ")" + text[i + 2:k] + '"'
            j = text.find(end, k)
            j = n if j < 0 else j + len(end)
            out.append('""' + "\n" * text.count("\n", i, j))
            i = j
        elif c in "\"'" and not (c == "'" and i > 0 and text[i - 1].isalnum()):
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            out.append(c + c)
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def long_functions(text, limit=LIMIT):
    """(first line, lines, header) of each function over `limit` lines."""
    code = code_only(text)
    found, stack = [], []  # stack: (kind, start line, header)
    header, header_line, line = "", 1, 1
    for c in code:
        if c == "\n":
            line += 1
        if c == "{":
            scope = stack[-1][0] if stack else "namespace"
            kind = "block"
            if scope in ("namespace", "class"):
                h = header.strip()
                if re.match(r"(namespace|extern)\b", h):
                    kind = "namespace"
                elif re.search(r"\b(struct|class|union|enum)\b", h.split("(")[0]):
                    kind = "class"
                elif ")" in h:
                    kind = "function"
            stack.append((kind, header_line, " ".join(header.split())[:90]))
            header = ""
        elif c == "}":
            if stack:
                kind, start, h = stack.pop()
                if kind == "function" and line - start + 1 > limit:
                    found.append((start, line - start + 1, h))
            header = ""
        elif c == ";":
            header = ""
        else:
            if not header.strip() and not c.isspace():
                header_line = line
            header += c
    return found


def check(root, files):
    status = 0
    for f in files:
        if f.startswith(SKIP):
            continue
        with open(os.path.join(root, f), errors="replace") as text:
            for start, lines, header in long_functions(text.read()):
                print("%s:%d: %d lines (at most %d): %s" % (f, start, lines, LIMIT, header))
                status = 1
    return status


def self_test():
    body = "".join("  x += %d;  // } {\n" % i for i in range(LIMIT - 2))
    long_one = ('#include "a.h"\n#define M(x) \\\n  {\nnamespace a {\nstruct S {\n  int f(int x) {\n' +
                body + '  x += 1;\n  return x; }\n};\n}\n')
    short = '#include <map>\nconst char* s = "{{{";\nint g(int x) {\n' + body + '}\n'
    with tempfile.TemporaryDirectory() as root:
        for name, text in {"core/long.cpp": long_one, "core/short.cpp": short}.items():
            os.makedirs(os.path.dirname(os.path.join(root, name)), exist_ok=True)
            with open(os.path.join(root, name), "w") as out:
                out.write(text)
        if check(root, ["core/long.cpp"]) != 1:
            print("self-test: a function of %d lines was not found" % (LIMIT + 1))
            return 1
        if check(root, ["core/short.cpp"]) != 0:
            print("self-test: a function of %d lines was refused" % LIMIT)
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
        print("no function over %d lines outside the tests" % LIMIT)
    sys.exit(status)
