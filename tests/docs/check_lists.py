#!/usr/bin/python3
"""Each list of the project has one source, and the documents that repeat it agree with it
(ctest `lists`).

usage: check_lists.py --root REPO

- The studies, harness/configs/studies.json: each has its config harness/configs/<name>.json and its
  report module reports/<name>.py; every experiment config of the folder is a study or an example;
  docs/studies.md's table lists them in the manifest's order; README.md's count of the studies
  demo.sh runs is the number marked run_by_default.
- The layers, cmake/layers.txt: docs/design.md's layer table has a row per layer, in its order,
  whose "uses" column names exactly the layers it links; README.md's folder list names every layer,
  in its order.
Every disagreement is printed (file: what differs); exit 1 if there is one.
"""

import argparse
import json
import os
import re
import sys

NUMBERS = ["zero", "one", "two", "three", "four", "five", "six", "seven", "eight", "nine", "ten",
           "eleven", "twelve"]


def read(root, path):
    with open(os.path.join(root, path)) as f:
        return f.read()


def layers(root):
    """[(layer, [layers it links])] of cmake/layers.txt, bottom first."""
    out = []
    for line in read(root, "cmake/layers.txt").splitlines():
        line = line.split("#", 1)[0]
        if ":" in line:
            name, links = line.split(":", 1)
            out.append((name.strip(), links.split()))
    return out


def check_layers(root, errors):
    order = layers(root)
    names = [n for n, _ in order]
    if not names:
        errors.append("cmake/layers.txt: no layers")
        return
    design = read(root, "docs/design.md")
    section = design.split("## Layers", 1)[-1].split("\n## ", 1)[0]
    rows = re.findall(r"^\| `([a-z_]+)/` \|.*\| ([^|]*) \|$", section, re.M)
    listed = [(n, uses) for n, uses in rows if n in names]
    if [n for n, _ in listed] != names:
        errors.append("docs/design.md: the layer table lists %s; cmake/layers.txt has %s"
                      % ([n for n, _ in listed], names))
    links = dict(order)
    for n, uses in listed:
        named = sorted(w for w in re.findall(r"[a-z_]+", uses) if w in names)
        if named != sorted(links[n]):
            errors.append("docs/design.md: layer %s uses %s; cmake/layers.txt links %s"
                          % (n, named, sorted(links[n])))
    readme = read(root, "README.md")
    folders = [f for f in re.findall(r"^([a-z_]+)/ ", readme, re.M) if f in names]
    if folders != names:
        errors.append("README.md: the folder list names the layers %s; cmake/layers.txt has %s"
                      % (folders, names))


def check_studies(root, errors):
    path = "harness/configs/studies.json"
    manifest = json.loads(read(root, path))
    studies = [s["name"] for s in manifest["studies"]]
    default = [s["name"] for s in manifest["studies"] if s.get("run_by_default")]
    examples = manifest.get("examples", [])
    for name in studies:
        for need in ("harness/configs/%s.json" % name, "reports/%s.py" % name):
            if not os.path.isfile(os.path.join(root, need)):
                errors.append("%s: study %s has no %s" % (path, name, need))
    configs = sorted(f[:-5] for f in os.listdir(os.path.join(root, "harness", "configs"))
                     if f.endswith(".json") and ".reference." not in f and f != "studies.json")
    for name in configs:
        if name not in studies and name not in examples:
            errors.append("%s: harness/configs/%s.json is neither a study nor an example" % (path, name))
    table = re.findall(r"^\| \[`([a-z_0-9]+)`\]\(#", read(root, "docs/studies.md"), re.M)
    if table != studies:
        errors.append("docs/studies.md: the table lists %s; %s has %s" % (table, path, studies))
    m = re.search(r"runs the `--quick` variant of (\w+) studies", read(root, "README.md"))
    if not m or m.group(1) != NUMBERS[len(default)]:
        errors.append("README.md: says demo.sh runs %s studies; %s marks %d run_by_default"
                      % (m.group(1) if m else "(no count)", path, len(default)))


def main(argv):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--root", required=True)
    args = p.parse_args(argv)
    errors = []
    check_layers(args.root, errors)
    check_studies(args.root, errors)
    for e in errors:
        print(e)
    if not errors:
        print("lists ok")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
