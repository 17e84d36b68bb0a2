#!/usr/bin/env bash
# Out of space and out of rights: `mcfbench flow` with frames, `mcfbench run`, `mcfbench collect`
# and reports/make_report.py writing into a full 3 MB tmpfs (MODE full) or a read-only one (MODE
# readonly) each exit non-zero with an error naming the path, write no half result (no temporary
# or staging file, no result without its frames, no empty folder) and leave the files an earlier
# run wrote there byte for byte. After space is freed, the stopped run resumes and completes.
#
# usage: test_unwritable.sh full|readonly MCFBENCH
#
# A real file system, not chmod (root, as CI runs, ignores it) nor `ulimit -f` (SIGXFSZ, not the
# ENOSPC of a full disk). Mounting needs root (CAP_SYS_ADMIN): elsewhere the test exits 77, which
# ctest reports as skipped. The mounts live in a private mount namespace when `unshare` allows,
# so they vanish with the test however it ends.
set -u
mode=${1:?usage: test_unwritable.sh full|readonly MCFBENCH}
mcfbench=${2:?usage: test_unwritable.sh full|readonly MCFBENCH}
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
py=/usr/bin/python3

if [ -z "${MCFBENCH_UNWRITABLE_NS:-}" ] && [ "$(id -u)" = 0 ] &&
  unshare --mount --propagation private true 2>/dev/null; then
  MCFBENCH_UNWRITABLE_NS=1 exec unshare --mount --propagation private bash "$0" "$@"
fi

work=$(mktemp -d)
m=$work/disk
mkdir -p "$m"
cleanup() {
  umount "$m" 2>/dev/null
  rm -rf "$work"
}
trap cleanup EXIT
size=3m
[ "$mode" = readonly ] && size=8m # room for everything written before it is made read-only
if ! mount -t tmpfs -o size=$size tmpfs "$m" 2>"$work/mount.err"; then
  echo "SKIP: cannot mount a tmpfs here (needs root with CAP_SYS_ADMIN): $(cat "$work/mount.err")"
  exit 77
fi

fail=0
no() {
  echo "FAIL: $*"
  fail=1
}
# Every file under a folder with its checksum (hidden ones included), sorted.
snapshot() { (cd "$1" && find . -type f -print0 | sort -z | xargs -0 -r sha256sum); }
# Fills the disk, leaving about $1 KiB free.
fill() {
  rm -f "$m/.fill"
  dd if=/dev/zero of="$m/.fill" bs=64k status=none 2>/dev/null
  truncate -s $(($(stat -c %s "$m/.fill") - $1 * 1024)) "$m/.fill"
}
pages() { echo $((($1 + 4095) / 4096)); } # the 4 KiB pages a file of $1 bytes takes on a tmpfs
# The command (arguments) fails, its stderr naming $want and $why.
expect_failure() {
  local what=$1 want=$2 why=$3
  shift 3
  "$@" >"$work/out.txt" 2>"$work/err.txt"
  local rc=$?
  [ $rc != 0 ] || no "$what: exit status 0"
  grep -qF -- "$want" "$work/err.txt" || no "$what: the error does not name $want: $(cat "$work/err.txt")"
  grep -qi -- "$why" "$work/err.txt" || no "$what: the error does not say \"$why\": $(cat "$work/err.txt")"
}
# No temporary or staging file anywhere under the mount (the filler aside).
no_leftovers() {
  local left
  left=$(find "$m" \( -name '*.tmp*' -o -name '.mcfbench-staging' -o -name '.report-staging' \) -print)
  [ -z "$left" ] || no "$1: left behind: $left"
}
has_matplotlib() { [ -x "$py" ] && "$py" -c "import matplotlib, numpy" 2>/dev/null; }

cat >"$work/tiny.json" <<'EOF'
{"name": "tiny",
 "defaults": {"mesh": "icosphere:level=1", "steps": 2, "threads": 1},
 "axes": {"dt": [0.001, 0.002, 0.003]}}
EOF
# Frames of 2562 vertices (about 130 KB each) from its first step.
cat >"$work/framed.json" <<'EOF'
{"name": "framed",
 "defaults": {"mesh": "icosphere:level=4", "steps": 3, "save_every": 1, "threads": 1},
 "axes": {"dt": [0.001, 0.002]}}
EOF
small_flow=(flow --mesh icosphere:level=1 --steps 2 --save-every 1 --threads 1)
big_flow=(flow --mesh icosphere:level=4 --steps 20 --save-every 1 --threads 1)
long_flow=(flow --mesh icosphere:level=4 --steps 80 --threads 1) # final.ply 130 KB, result.json 60 KB

# What an earlier session left in the folders: a flow with frames, a finished run, its index and
# its report.
"$mcfbench" "${small_flow[@]}" --out "$m/flow" 2>"$work/err.txt" || no "first flow: $(cat "$work/err.txt")"
"$mcfbench" run "$work/tiny.json" --out "$m/run" >/dev/null 2>"$work/err.txt" || no "first run: $(cat "$work/err.txt")"
"$mcfbench" collect "$m/run" >/dev/null 2>"$work/err.txt" || no "first collect: $(cat "$work/err.txt")"
report=no
if has_matplotlib; then
  report=yes
  "$py" "$root/reports/make_report.py" "$m/run" "$m/report" >/dev/null 2>"$work/err.txt" ||
    no "first report: $(cat "$work/err.txt")"
  [ -s "$m/report/index.md" ] || no "first report: no index.md"
fi
[ $fail = 0 ] || exit 1
snapshot "$m" | grep -v ' ./.fill$' >"$work/before"

if [ "$mode" = readonly ]; then
  mount -o remount,ro "$m" || { echo "FAIL: cannot remount the tmpfs read-only"; exit 1; }
  why="read-only file system"
  expect_failure "flow into a folder of an earlier flow" "$m/flow" "$why" \
    "$mcfbench" "${small_flow[@]}" --out "$m/flow"
  expect_failure "flow into a new folder" "$m/new" "$why" "$mcfbench" "${small_flow[@]}" --out "$m/new"
  expect_failure "run (all cells finished)" "$m/run/plans/" "$why" "$mcfbench" run "$work/tiny.json" --out "$m/run"
  expect_failure "run --force" "$m/run/plans/" "$why" "$mcfbench" run "$work/tiny.json" --out "$m/run" --force
  expect_failure "run of another study" "$m/run/plans/" "$why" "$mcfbench" run "$work/framed.json" --out "$m/run"
  expect_failure "collect" "$m/run/index.json" "$why" "$mcfbench" collect "$m/run"
  if [ $report = yes ]; then
    expect_failure "report over an earlier one" "$m/report" "$why" "$py" "$root/reports/make_report.py" "$m/run" "$m/report"
    expect_failure "report into a new folder" "$m/new_report" "$why" "$py" "$root/reports/make_report.py" "$m/run" "$m/new_report"
  fi
  snapshot "$m" >"$work/after"
  diff "$work/before" "$work/after" >"$work/diff" || { cat "$work/diff"; no "the read-only mount's files changed"; }
else
  why="no space left on device"
  # A flow that fills the disk with its second frame.
  fill 200
  expect_failure "flow into a folder of an earlier flow" "$m/flow/" "$why" "$mcfbench" "${big_flow[@]}" --out "$m/flow"
  expect_failure "flow into a new folder" "$m/new/" "$why" "$mcfbench" "${big_flow[@]}" --out "$m/new"
  [ -e "$m/new" ] && no "a failed flow left its new folder: $(ls -A "$m/new")"
  # A flow whose final.ply fits and whose result.json does not, even with the earlier run's files
  # removed: sized by the same flow run elsewhere.
  "$mcfbench" "${long_flow[@]}" --out "$work/probe" 2>/dev/null || no "probe flow"
  ply=$(pages "$(stat -c %s "$work/probe/final.ply")")
  earlier=0
  for f in "$m"/flow/*; do earlier=$((earlier + $(pages "$(stat -c %s "$f")"))); done
  [ "$(pages "$(stat -c %s "$work/probe/result.json")")" -gt $((earlier + 1)) ] ||
    no "probe: its result.json would fit in the space of the earlier run's files"
  fill $((4 * (ply + 1)))
  expect_failure "flow whose result.json does not fit" "$m/flow/" "$why" "$mcfbench" "${long_flow[@]}" --out "$m/flow"
  # Another study into the run's folder: its plan fits, the first frame of its first cell does not.
  fill 64
  expect_failure "run whose frames fill the disk" "$m/run/frames/" "$why" "$mcfbench" run "$work/framed.json" --out "$m/run"
  grep -qF "Rerun the same command to resume" "$work/err.txt" || no "run: no word on how to resume: $(cat "$work/err.txt")"
  ls "$m/run/frames" 2>/dev/null | grep -q . && no "run: the dropped cell's frames are left: $(ls "$m/run/frames")"
  rm -f "$m"/run/plans/framed@*.json # the one file that run was right to write
  # A full disk: the plan cannot be rewritten, nor a result, the index or the report.
  fill 0
  expect_failure "run --force" "$m/run/plans/" "$why" "$mcfbench" run "$work/tiny.json" --out "$m/run" --force
  expect_failure "collect" "$m/run/index.json" "$why" "$mcfbench" collect "$m/run"
  if [ $report = yes ]; then
    expect_failure "report over an earlier one" "$m/report" "$why" "$py" "$root/reports/make_report.py" "$m/run" "$m/report"
    expect_failure "report into a new folder" "$m/new_report" "$why" "$py" "$root/reports/make_report.py" "$m/run" "$m/new_report"
    [ -e "$m/new_report" ] && no "a failed report left its new folder"
  fi
  no_leftovers "full disk"
  snapshot "$m" | grep -v ' ./.fill$' >"$work/after"
  diff "$work/before" "$work/after" >"$work/diff" || { cat "$work/diff"; no "the earlier files changed"; }
  # Space again: the stopped run resumes and completes, and collect finds every cell.
  rm -f "$m/.fill"
  "$mcfbench" run "$work/framed.json" --out "$m/run" >/dev/null 2>"$work/err.txt" || no "resumed run: $(cat "$work/err.txt")"
  "$mcfbench" collect "$m/run" >"$work/out.txt" 2>"$work/err.txt" || no "collect after the resumed run: $(cat "$work/out.txt" "$work/err.txt")"
  grep -q "2 cells found of 2, 0 missing" "$work/out.txt" || no "collect after the resumed run: $(cat "$work/out.txt")"
fi

[ $fail = 0 ] || exit 1
if [ $report = no ]; then
  echo "SKIP: flow, run and collect passed; the report part needs matplotlib for /usr/bin/python3"
  exit 77
fi
echo "unwritable ($mode) test passed"
