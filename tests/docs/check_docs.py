#!/usr/bin/python3
"""The documentation check of the test suite (ctest `docs`).

usage: check_docs.py --root REPO --mcfbench BIN [--micro BIN]
       check_docs.py --self-test --mcfbench BIN [--micro BIN]

Reads README.md, CHANGELOG.md, reports/README.md and docs/*.md under REPO and fails (exit 1,
one line per problem) when

- a relative link does not resolve: `[text](path)` and `[text](path#anchor)` must name a file
  or folder of the repository, and an anchor a heading of the Markdown file it points into
  (GitHub's slugs); links to web pages (http:, https:, mailto:) are not followed;
- an `mcfbench` command line in a code block (fenced, or an inline span that starts with the
  command) names a subcommand the binary does not have, or a flag that its subcommand's
  `--help` does not list; every such line is also run with `--help` appended, with its
  placeholder values (N, DIR, CONFIG.json, $VAR) left out, so a value CLI11 refuses (a
  number out of range, a word for a number) fails too, while nothing runs;
- an `mcfbench_micro` line (with --micro) uses a flag its `--help` does not list, or a
  `--benchmark_filter` that selects no benchmark;
- README.md is longer than 200 lines;
- README.md, reports/README.md or a page of docs/ other than docs/benchmarks.md holds a date
  (YYYY-MM-DD): dated measurements belong in docs/benchmarks.md, history in CHANGELOG.md.

--self-test runs the check on small fabricated trees and fails unless each kind of problem
above is reported (and a clean tree passes), so the check cannot silently stop catching them.
"""

import argparse
import os
import re
import shlex
import subprocess
import sys
import tempfile

README_MAX_LINES = 200
DATE = re.compile(r"(?<![0-9])[0-9]{4}-[0-9]{2}-[0-9]{2}(?![0-9])")
DATES_ALLOWED = {"CHANGELOG.md", os.path.join("docs", "benchmarks.md")}
SHELL_OPERATORS = {"|", "||", "&&", ";", "&"}


# ---------------------------------------------------------------------------------------------
# Markdown


def doc_files(root):
    """The documentation files checked, relative to root."""
    out = [f for f in ("README.md", "CHANGELOG.md", os.path.join("reports", "README.md"))
           if os.path.isfile(os.path.join(root, f))]
    docs = os.path.join(root, "docs")
    if os.path.isdir(docs):
        out += sorted(os.path.join("docs", f) for f in os.listdir(docs) if f.endswith(".md"))
    return out


SHELL_LANGUAGES = {"", "sh", "bash", "shell", "console", "zsh"}


def split_blocks(text, shell_only=False):
    """(prose lines, code lines): each a list of (line number, text). Fenced blocks (``` or ~~~)
    are code; everything else prose. With shell_only, code lines of blocks whose info string names
    another language (json, text, cpp ...) are left out."""
    prose, code = [], []
    fence, keep = None, True
    for n, line in enumerate(text.splitlines(), 1):
        m = re.match(r"^\s*(```+|~~~+)\s*([\w+-]*)", line)
        if fence is None and m:
            fence = m.group(1)[0] * 3
            keep = not shell_only or m.group(2).lower() in SHELL_LANGUAGES
            continue
        if fence is not None and line.strip().startswith(fence):
            fence = None
            continue
        if fence is None:
            prose.append((n, line))
        elif keep:
            code.append((n, line))
    return prose, code


def inline_spans(line):
    """Contents of the inline code spans of a prose line."""
    return [m.group(2) for m in re.finditer(r"(`+)(.+?)\1", line)]


def strip_inline_code(line):
    return re.sub(r"(`+)(.+?)\1", "", line)


def slug(heading):
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces to hyphens."""
    s = heading.strip().lower()
    s = re.sub(r"[^\w\- ]", "", s)
    return s.replace(" ", "-")


def anchors(path):
    prose, _ = split_blocks(open(path, encoding="utf-8").read())
    seen, out = {}, set()
    for _, line in prose:
        m = re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
        if not m:
            continue
        s = slug(m.group(1))
        if s in seen:
            seen[s] += 1
            out.add("%s-%d" % (s, seen[s]))
        else:
            seen[s] = 0
            out.add(s)
    return out


LINK = re.compile(r"!?\[[^\]]*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
REF_LINK = re.compile(r"^\s*\[[^\]]+\]:\s*<?(\S+?)>?(?:\s+\"[^\"]*\")?\s*$")


def check_links(root, rel, problems):
    path = os.path.join(root, rel)
    prose, _ = split_blocks(open(path, encoding="utf-8").read())
    for n, line in prose:
        text = strip_inline_code(line)
        targets = [m.group(1) for m in LINK.finditer(text)]
        m = REF_LINK.match(text)
        if m:
            targets.append(m.group(1))
        for target in targets:
            if re.match(r"^[a-zA-Z][a-zA-Z0-9+.-]*:", target):
                continue  # http:, https:, mailto: ...
            file_part, _, anchor = target.partition("#")
            dest = os.path.normpath(os.path.join(os.path.dirname(path), file_part)) if file_part else path
            where = "%s:%d: link %s" % (rel, n, target)
            if not os.path.realpath(dest).startswith(os.path.realpath(root) + os.sep) and \
                    os.path.realpath(dest) != os.path.realpath(root):
                problems.append("%s points outside the repository" % where)
                continue
            if not os.path.exists(dest):
                problems.append("%s: no such file" % where)
                continue
            if anchor:
                if not dest.endswith(".md") or os.path.isdir(dest):
                    problems.append("%s: anchor on a file that is not Markdown" % where)
                elif anchor not in anchors(dest):
                    problems.append("%s: no heading with that anchor in %s" % (where, os.path.relpath(dest, root)))


def check_length_and_dates(root, rel, problems):
    lines = open(os.path.join(root, rel), encoding="utf-8").read().splitlines()
    if rel == "README.md" and len(lines) > README_MAX_LINES:
        problems.append("README.md: %d lines, at most %d" % (len(lines), README_MAX_LINES))
    if rel in DATES_ALLOWED:
        return
    for n, line in enumerate(lines, 1):
        m = DATE.search(line)
        if m:
            problems.append("%s:%d: date %s (dated text goes to docs/benchmarks.md or CHANGELOG.md)"
                            % (rel, n, m.group(0)))


# ---------------------------------------------------------------------------------------------
# Command lines


def logical_lines(lines):
    """Code lines joined where they end in a backslash: [(first line number, text)]."""
    out, buf, start = [], "", None
    for n, line in lines:
        if start is None:
            start = n
        if line.rstrip().endswith("\\"):
            buf += line.rstrip()[:-1] + " "
            continue
        out.append((start, buf + line))
        buf, start = "", None
    if buf:
        out.append((start, buf))
    return out


def tokens_of(text):
    text = re.sub(r"^\s*\$\s+", "", text)  # a shell prompt
    return shlex.split(text, comments=True, posix=True)


def is_operator(tok):
    return tok in SHELL_OPERATORS or re.match(r"^[0-9&]?[<>]", tok) is not None


def invocations(tokens, program):
    """Every (args after the program name) of `program` in a token list, also inside quoted
    arguments (sbatch --wrap '...', bash -c '...')."""
    out = []
    i = 0
    while i < len(tokens):
        tok = tokens[i]
        if os.path.basename(tok) == program:
            args = []
            j = i + 1
            while j < len(tokens) and not is_operator(tokens[j]):
                t = tokens[j]
                if t.endswith(";"):
                    args.append(t[:-1])
                    j += 1
                    break
                args.append(t)
                j += 1
            out.append(args)
            i = j
            continue
        if " " in tok and program in tok:
            try:
                out += invocations(tokens_of(tok), program)
            except ValueError:
                pass
        i += 1
    return out


def command_lines(root, rel):
    """(line number, text) of every code line and every inline code span of a file."""
    prose, code = split_blocks(open(os.path.join(root, rel), encoding="utf-8").read(), shell_only=True)
    lines = logical_lines(code)
    for n, line in prose:
        for span in inline_spans(line):
            first = span.strip().split(" ", 1)[0]
            if os.path.basename(first) in ("mcfbench", "mcfbench_micro"):
                lines.append((n, span))
    return lines


def run(argv, stderr=True):
    """(exit status, stdout and, unless stderr=False, stderr)."""
    p = subprocess.run(argv, stdout=subprocess.PIPE,
                       stderr=subprocess.STDOUT if stderr else subprocess.DEVNULL, text=True, timeout=120)
    return p.returncode, p.stdout


class Cli:
    """What the mcfbench binary accepts, read from its --help output."""

    def __init__(self, binary):
        self.binary = binary
        rc, text = run([binary, "--help"])
        if rc != 0:
            raise RuntimeError("%s --help exited %d" % (binary, rc))
        self.subcommands = set()
        section = None
        for line in text.splitlines():
            if re.match(r"^\S.*:\s*$", line):
                section = line.strip().rstrip(":").lower()
                continue
            m = re.match(r"^\s{2}(\S+)", line)
            if section == "subcommands" and m:
                self.subcommands.add(m.group(1))
        self.main_flags = options_of(text)
        self._options = {}

    def options(self, sub):
        """{flag: takes a value} of a subcommand."""
        if sub not in self._options:
            rc, text = run([self.binary, sub, "--help"])
            if rc != 0:
                raise RuntimeError("%s %s --help exited %d" % (self.binary, sub, rc))
            self._options[sub] = options_of(text)
        return self._options[sub]


def options_of(help_text):
    """{flag: takes a value} from CLI11's option list (lines "  -h,--help", "  --out TEXT ...")."""
    out = {}
    for line in help_text.splitlines():
        # The value's type follows the names after one space ("--out TEXT"); the description
        # after a wider gap.
        m = re.match(r"^\s{2}(-\S+)( [A-Z]+(?![a-z]))?", line)
        if not m:
            continue
        takes_value = m.group(2) is not None
        for name in m.group(1).split(","):
            if name.startswith("-"):
                out[name] = takes_value
    return out


def is_placeholder(tok):
    """A value a reader substitutes: N, DIR, OLD_DIR, CONFIG.json, DIR@COMMIT, $VAR, a|b."""
    return ("$" in tok or "|" in tok or "..." in tok or "<" in tok
            or re.match(r"^[A-Z][A-Z0-9_]*([.@/].*)?$", tok) is not None)


def flag_name(tok):
    return tok.split("=", 1)[0]


def is_flag(tok):
    return tok.startswith("-") and not re.match(r"^-[0-9.]", tok) and tok != "-"


def check_mcfbench(cli, where, args, problems):
    args = [a.strip("[]") for a in args if a.strip("[]")]
    if not args:
        return
    sub = args[0]
    if is_flag(sub):
        for a in args:
            if is_flag(a) and flag_name(a) not in cli.main_flags:
                problems.append("%s: mcfbench has no option %s" % (where, flag_name(a)))
        return
    if is_placeholder(sub):
        return  # "mcfbench SUBCOMMAND --help"
    if sub not in cli.subcommands:
        problems.append("%s: mcfbench has no subcommand '%s' (it has: %s)"
                        % (where, sub, ", ".join(sorted(cli.subcommands))))
        return
    options = cli.options(sub)
    concrete = [sub]
    i = 1
    while i < len(args):
        a = args[i]
        if is_flag(a):
            name = flag_name(a)
            if name not in options:
                problems.append("%s: `mcfbench %s` has no option %s" % (where, sub, name))
                i += 1
                continue
            if options[name] and "=" not in a and i + 1 < len(args):
                value = args[i + 1]
                if not is_placeholder(value):
                    concrete += [a, value]
                i += 2
                continue
            if "=" not in a or not is_placeholder(a.split("=", 1)[1]):
                concrete.append(a)
        elif not is_placeholder(a):
            concrete.append(a)
        i += 1
    rc, out = run([cli.binary] + concrete + ["--help"])
    if rc != 0:
        msg = " ".join(l for l in out.splitlines() if l.strip() and "--help for more" not in l)
        problems.append("%s: `mcfbench %s` refuses it: %s" % (where, " ".join(concrete), msg[:200]))


class Micro:
    def __init__(self, binary):
        self.binary = binary
        rc, text = run([binary, "--help"])
        self.flags = set(re.findall(r"--([a-z_]+)", text))

    def check(self, where, args, problems):
        for a in args:
            if not a.startswith("--"):
                continue
            name = a[2:].split("=", 1)[0]
            if name not in self.flags:
                problems.append("%s: mcfbench_micro has no flag --%s" % (where, name))
            elif name == "benchmark_filter" and "=" in a:
                regex = a.split("=", 1)[1]
                rc, out = run([self.binary, "--benchmark_list_tests=true", "--benchmark_filter=" + regex],
                              stderr=False)
                if rc != 0 or not out.strip():
                    problems.append("%s: --benchmark_filter=%s selects no benchmark" % (where, regex))


def check_commands(root, rel, cli, micro, problems):
    for n, line in command_lines(root, rel):
        if "mcfbench" not in line:
            continue
        where = "%s:%d" % (rel, n)
        try:
            toks = tokens_of(line)
        except ValueError as e:
            problems.append("%s: cannot split the command line (%s)" % (where, e))
            continue
        for args in invocations(toks, "mcfbench"):
            check_mcfbench(cli, where, args, problems)
        if micro:
            for args in invocations(toks, "mcfbench_micro"):
                micro.check(where, args, problems)


# ---------------------------------------------------------------------------------------------


def check(root, cli, micro):
    problems = []
    for rel in doc_files(root):
        check_links(root, rel, problems)
        check_length_and_dates(root, rel, problems)
        check_commands(root, rel, cli, micro, problems)
    if not os.path.isfile(os.path.join(root, "README.md")):
        problems.append("README.md: missing")
    return problems


def self_test(cli, micro):
    """Each fabricated fault must be reported; the clean tree must pass."""
    clean = {
        "README.md": "# t\n\nSee [flow](docs/flow.md#options) and [the tests](tests/).\n\n"
                     "```sh\nbuild/mcfbench flow --mesh torus --steps 2 --out DIR\n"
                     "build/mcfbench run CONFIG.json --quick --threads N\n"
                     "sbatch --wrap 'build/mcfbench run cfg.json --shard $I/16'\n```\n",
        "docs/flow.md": "# Flow\n\n## Options\n\n`build/mcfbench mesh-info torus --write FILE`\n",
        "tests/x": "",
    }
    faults = {
        "broken link": ("README.md", "[gone](docs/gone.md)\n", "no such file"),
        "broken anchor": ("README.md", "[a](docs/flow.md#nothing)\n", "no heading"),
        "removed flag": ("README.md", "```\nbuild/mcfbench flow --mesh torus --no-such-flag 3\n```\n",
                         "no option --no-such-flag"),
        "removed flag in a wrapped line": ("docs/flow.md", "```\nsbatch --wrap 'build/mcfbench run c.json \\\n"
                                           "  --gone $X/2'\n```\n", "no option --gone"),
        "flag in an inline span": ("docs/flow.md", "Run `mcfbench expand c.json --nope`.\n", "no option --nope"),
        "unknown subcommand": ("README.md", "```\nbuild/mcfbench flwo --mesh torus\n```\n", "no subcommand"),
        "bad value": ("README.md", "```\nbuild/mcfbench run c.json --threads 99999\n```\n", "refuses it"),
        "date in README": ("README.md", "Measured 2026-01-02.\n", "date 2026-01-02"),
        "date in docs": ("docs/flow.md", "On 2026-01-02.\n", "date 2026-01-02"),
        "long README": ("README.md", "x\n" * README_MAX_LINES, "lines, at most"),
    }
    if micro:
        faults["micro flag"] = ("docs/flow.md", "```\nbuild/mcfbench_micro --benchmark_nope=1\n```\n",
                                "no flag --benchmark_nope")
        faults["micro filter"] = ("docs/flow.md", "```\nbuild/mcfbench_micro --benchmark_filter=NoSuchBench\n```\n",
                                  "selects no benchmark")
    failures = []

    def build(tmp, extra):
        for rel, text in clean.items():
            os.makedirs(os.path.dirname(os.path.join(tmp, rel)) or tmp, exist_ok=True)
            with open(os.path.join(tmp, rel), "w") as f:
                f.write(text + (extra[1] if extra and extra[0] == rel else ""))

    with tempfile.TemporaryDirectory() as tmp:
        build(tmp, None)
        found = check(tmp, cli, micro)
        if found:
            failures.append("clean tree reported: %s" % found)
    for name, fault in faults.items():
        with tempfile.TemporaryDirectory() as tmp:
            build(tmp, fault)
            found = check(tmp, cli, micro)
            if not any(fault[2] in p for p in found):
                failures.append("%s not caught (reported: %s)" % (name, found))
    for f in failures:
        print("self-test: " + f)
    print("self-test: %d fault kinds, %d not caught" % (len(faults), len(failures)))
    return 1 if failures else 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--root", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
    ap.add_argument("--mcfbench", required=True, help="the mcfbench binary")
    ap.add_argument("--micro", help="the mcfbench_micro binary (optional)")
    ap.add_argument("--self-test", action="store_true")
    a = ap.parse_args()
    cli = Cli(a.mcfbench)
    micro = Micro(a.micro) if a.micro and os.path.exists(a.micro) else None
    if a.self_test:
        return self_test(cli, micro)
    root = os.path.abspath(a.root)
    problems = check(root, cli, micro)
    for p in problems:
        print(p)
    print("docs check: %d file(s), %d problem(s)" % (len(doc_files(root)), len(problems)))
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
