#!/usr/bin/env bash
# The `arcwheel` target's clean build and its rebuild after an edit of fitting/sample_fit.cc, as
# issue 44 measures them: configured as scripts/demo.sh configures it (Release; tests, benchmarks
# and Python off), ccache off, `ninja -j$(nproc)`; CPU = user + sys of ninja and its compilers.
# Usage: benchmarks/build_bench.sh [REV...]   (default: the working tree)
# Each REV is checked out into a temporary worktree. The builds alternate over the REVs, ROUNDS
# times (default 2): on a machine whose speed swings from hour to hour, a before-and-after is
# only meaningful the same hour. The medians come last.
set -euo pipefail
export CCACHE_DISABLE=1
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
rounds=${ROUNDS:-2}
work=$(mktemp -d)
worktrees=()
cleanup() {
  for tree in "${worktrees[@]}"; do git -C "$root" worktree remove --force "$tree" 2>/dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT

revs=("$@")
[ ${#revs[@]} -eq 0 ] && revs=(working-tree)
sources=()
for rev in "${revs[@]}"; do
  if [ "$rev" = working-tree ]; then
    sources+=("$root")
  else
    tree="$work/src-$rev"
    git -C "$root" worktree add --detach -q "$tree" "$rev"
    worktrees+=("$tree")
    sources+=("$tree")
  fi
done

configure() {  # source dir, build dir
  cmake -S "$1" -B "$2" -G Ninja -DCMAKE_BUILD_TYPE=Release -DARCWHEEL_BUILD_TESTS=OFF \
    -DARCWHEEL_BUILD_BENCHMARKS=OFF -DARCWHEEL_BUILD_PYTHON=OFF -DARCWHEEL_CCACHE=OFF >/dev/null
}
timed_build() {  # build dir; prints "wall user sys"
  /usr/bin/time -f '%e %U %S' -o "$work/time" ninja -C "$1" -j "$(nproc)" arcwheel >/dev/null
  cat "$work/time"
}

echo "load before: $(cut -d' ' -f1-3 /proc/loadavg); $(nproc) cores"
for i in "${!revs[@]}"; do configure "${sources[$i]}" "$work/build-$i"; done
for round in $(seq 1 "$rounds"); do
  for i in "${!revs[@]}"; do
    ninja -C "$work/build-$i" -t clean >/dev/null
    read -r wall user sys < <(timed_build "$work/build-$i")
    cpu=$(python3 -c "print(round($user + $sys, 1))")
    echo "$cpu" >> "$work/cpu-$i"
    echo "$(date -u +%H:%M:%S) ${revs[$i]}: clean build ${wall} s wall, ${user} user + ${sys} sys = ${cpu} CPU-s;" \
      "load $(cut -d' ' -f1 /proc/loadavg)"
  done
done
median() { sort -n "$1" | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }
for i in "${!revs[@]}"; do
  for run in 1 2 3; do
    touch "${sources[$i]}/fitting/sample_fit.cc"
    read -r wall user sys < <(timed_build "$work/build-$i")
    echo "$wall" >> "$work/touch-$i"
  done
  echo "${revs[$i]}: clean build median $(median "$work/cpu-$i") CPU-s ($(sort -n "$work/cpu-$i" | tr '\n' ' ')); " \
    "after touching fitting/sample_fit.cc median $(median "$work/touch-$i") s ($(sort -n "$work/touch-$i" | tr '\n' ' '))"
done
