#!/usr/bin/env bash
# Flows every mesh file of the CGAL data archive (or the files given) with each basis — hat with
# CHOLMOD, hat with its surface multigrid, octree with multigrid — for a few small steps, and
# classifies every run as flowed or refused with a named reason (docs/testing.md "The mesh
# sweep"). Writes OUT/sweep.tsv (file, basis, outcome, reason, detail) and prints a summary per
# basis. Exits 1 when a run is unexplained: a flow that turned singular, a refusal whose message
# names no known reason, or a crash; else 0.
#
#   scripts/sweep_meshes.sh [--out DIR] [--steps N] [--dt DT] [FILE...]
#
# Without FILE it sweeps data/meshes/ of libcgal-demo's data.tar.gz (where scripts/setup.sh puts
# it, as datasets/catalogue.cpp finds it), extracted into OUT/meshes. MCFBENCH_BINARY names the
# binary (default build/mcfbench); MCFBENCH_SWEEP_TIMEOUT the seconds one run may take (600).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${MCFBENCH_BINARY:-$root/build/mcfbench}
out=out/sweep
steps=2
dt=1e-5
files=()
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out=$2; shift 2 ;;
    --steps) steps=$2; shift 2 ;;
    --dt) dt=$2; shift 2 ;;
    -h|--help) sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "sweep_meshes.sh: unknown option $1" >&2; exit 2 ;;
    *) files+=("$1"); shift ;;
  esac
done
[ -x "$bin" ] || { echo "sweep_meshes.sh: no binary $bin (build first, or set MCFBENCH_BINARY)" >&2; exit 2; }
mkdir -p "$out"
out=$(cd "$out" && pwd)

if [ ${#files[@]} -eq 0 ]; then
  archive=$(bash "$(dirname "$0")/cgal_archive.sh") || archive=
  if [ -z "$archive" ]; then
    echo "sweep_meshes.sh: libcgal-demo's data.tar.gz not found; run scripts/setup.sh" >&2
    exit 77
  fi
  mkdir -p "$out/meshes"
  tar -xzf "$archive" -C "$out/meshes" --wildcards 'data/meshes/*'
  while IFS= read -r f; do files+=("$f"); done < <(
    find "$out/meshes/data/meshes" -type f \( -iname '*.off' -o -iname '*.ply' -o -iname '*.obj' -o -iname '*.stl' \) | LC_ALL=C sort)
fi

# name|flags: the bases and solvers swept.
configs=(
  "hat+cholmod|--basis hat --solver cholmod"
  "hat+multigrid|--basis hat --solver multigrid --cycle V --smooth 2 --cycles 2"
  "octree|--basis octree --depth 6 --solver multigrid"
)
runs=$out/runs
rm -rf "$runs"
mkdir -p "$runs"
: > "$out/runs.list"
i=0
for f in "${files[@]}"; do
  for c in "${configs[@]}"; do
    name=${c%%|*}
    flags=${c#*|}
    dir=$runs/$i
    i=$((i + 1))
    rc=0
    # shellcheck disable=SC2086  # flags are words
    timeout "${MCFBENCH_SWEEP_TIMEOUT:-600}" "$bin" flow --mesh "$f" $flags --steps "$steps" --dt "$dt" \
      --threads 1 --out "$dir/out" >/dev/null 2>"$dir.err" || rc=$?
    printf '%s\t%s\t%s\t%s\n' "$f" "$name" "$rc" "$dir" >> "$out/runs.list"
  done
done

/usr/bin/python3 - "$out" <<'EOF'
# Classifies each run of runs.list into sweep.tsv and prints the summary per basis.
import collections, json, os, re, sys

out = sys.argv[1]
# A refusal's message names its reason; the first pattern that matches classifies it.
REASONS = [
    ("non-orientable", r"non-orientable mesh"),
    ("non-manifold", r"non-manifold"),
    ("degenerate face", r"is degenerate \(area"),
    ("repeated corner", r"repeats (a )?vertex"),
    ("empty mesh", r"empty mesh|empty file"),
    ("parse error", r"line \d+|byte \d+|header|keyword|expected|could not parse"),
    ("unit cube", r"--cube|octree\.cube"),
    ("memory", r"estimated .* more than"),
]
rows, unexplained = [], 0
summary = collections.OrderedDict()
for line in open(os.path.join(out, "runs.list")):
    f, basis, rc, d = line.rstrip("\n").split("\t")
    rc = int(rc)
    err = open(d + ".err", errors="replace").read()
    name = os.path.basename(f)
    detail = ""
    if rc == 0:
        r = json.load(open(os.path.join(d, "out", "result.json")))
        notes = r.get("notes", []) + r["mesh"].get("notes", [])
        if r["status"] == "ok":
            outcome = "flowed"
            if r["system"].get("free_functions", 1) == 0:
                reason = "nothing free to move (mesh unchanged)"
            elif r["mesh"].get("reoriented_faces", 0):
                reason = "reoriented"
            elif r["mesh"].get("degenerate_faces", 0):
                reason = "degenerate faces kept"
            else:
                reason = ""
        else:
            outcome, reason = "singular", r["stop"]["reason"]
            unexplained += 1
        detail = "; ".join(notes)
    else:
        message = next((l for l in err.splitlines() if "error" in l), err.strip()[-300:])
        detail = message
        if rc > 128 or rc == 124:
            outcome, reason = "crashed", "exit status %d" % rc
            unexplained += 1
        else:
            outcome = "refused"
            reason = next((k for k, p in REASONS if re.search(p, message)), None)
            if reason is None:
                reason = "unclassified"
                unexplained += 1
    rows.append((name, basis, outcome, reason, detail.replace("\t", " ").replace("\n", " ")))
    key = outcome + (": " + reason if reason else "")
    summary.setdefault(basis, collections.Counter())[key] += 1

with open(os.path.join(out, "sweep.tsv"), "w") as t:
    t.write("file\tbasis\toutcome\treason\tdetail\n")
    for r in rows:
        t.write("\t".join(r) + "\n")
files = len({r[0] for r in rows})
print("mesh sweep: %d files, %d runs; table in %s" % (files, len(rows), os.path.join(out, "sweep.tsv")))
for basis, counts in summary.items():
    print("  %s:" % basis)
    for key, n in sorted(counts.items(), key=lambda kv: (-kv[1], kv[0])):
        print("    %4d  %s" % (n, key))
if unexplained:
    print("%d run(s) unexplained (singular, crashed or an unclassified refusal):" % unexplained)
    for r in rows:
        if r[2] in ("singular", "crashed") or r[3] == "unclassified":
            print("  %s [%s] %s: %s %s" % (r[0], r[1], r[2], r[3], r[4][:300]))
sys.exit(1 if unexplained else 0)
EOF
