#!/usr/bin/env bash
# Same behaviour before and after a change (the check of issue 26's redesign):
#
#   bash scripts/same-behaviour.sh REV_BEFORE REV_AFTER
#
# builds the CLI of both revisions (release, in worktrees under a temporary folder, in a target
# folder of their own, target/same-behaviour/, so the dependencies compile once for both; not in
# target/ itself: cargo hashes a workspace crate without its path, and a worktree build newer
# than this checkout's sources would be taken as this checkout's build) and runs on each: `moreau theta` (table
# and --json) on every examples/*.toml, `simulate` of the worked example, the amplitude sweep
# (examples/sweeps/amplitude.toml) and `discover-bench --cases 1 --seed 2626`. It then lists each
# output file as identical or differing; run times ("(0.5 s;", "seconds": ..., "diagnosis
# time") and the output folder's name are blanked before comparing. Exit code 1 if any file
# differs after that. The runs take about 1 minute; the first build about 5 more (the dependencies).
set -euo pipefail
[ $# -eq 2 ] || { echo "usage: $0 REV_BEFORE REV_AFTER" >&2; exit 2; }
repo="$(cd "$(dirname "$0")/.." && pwd)"
work="$(mktemp -d)"
trap 'git -C "$repo" worktree remove --force "$work/before" 2>/dev/null || true;
      git -C "$repo" worktree remove --force "$work/after" 2>/dev/null || true; rm -rf "$work"' EXIT

blank_times() {
    sed -E 's/\([0-9.]+ s;/(T s;/; s/"seconds": [0-9.e-]+/"seconds": T/;
            s/[0-9.]+ s total, [0-9.]+ s per case/T/; s#'"$work"'/out-(before|after)#OUT#g' "$1"
}

for side in before after; do
    rev=$1; [ $side = after ] && rev=$2
    git -C "$repo" worktree add -q --detach "$work/$side" "$rev"
    (cd "$work/$side" && CARGO_TARGET_DIR="$repo/target/same-behaviour" cargo build -q --release --locked -p moreau)
    cp "$repo/target/same-behaviour/release/moreau" "$work/moreau-$side"
    out="$work/out-$side"; mkdir -p "$out"; bin="$work/moreau-$side"
    cd "$work/$side"
    for m in examples/*.toml; do
        n=$(basename "$m" .toml)
        { "$bin" theta "$m" 2>&1; echo "rc=$?"; } > "$out/theta-$n.txt" || true
        "$bin" theta "$m" --json > "$out/theta-$n.json" 2>/dev/null || true
    done
    "$bin" simulate examples/worked-example.toml --out "$out/sim" > "$out/simulate.txt" 2>&1 || true
    "$bin" sweep examples/sweeps/amplitude.toml --out "$out/sweep" > "$out/sweep.txt" 2>&1 || true
    "$bin" discover-bench --cases 1 --seed 2626 --json "$out/bench.json" > "$out/bench.txt" 2>&1 || true
    cd "$repo"
done

differ=0
for f in $(cd "$work/out-before" && find . -type f | sort); do
    a="$work/out-before/$f"; b="$work/out-after/$f"
    if [ ! -e "$b" ]; then echo "missing after: $f"; differ=1
    elif cmp -s "$a" "$b"; then echo "identical        $f"
    elif cmp -s <(blank_times "$a") <(blank_times "$b"); then echo "same but times   $f"
    else echo "DIFFERS          $f"; differ=1
    fi
done
exit $differ
