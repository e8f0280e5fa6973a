#!/usr/bin/env bash
# Installs the build tree into a fresh prefix and builds and runs the consumer project
# (tests/consumer) against it, as another project would use arcwheel:
#   run_consumer_test.sh BUILD_DIR VERSION CXX_COMPILER
# Also checks the installed tree: every `#include "..."` of an installed header resolves inside
# it, no installed CMake file names the build or source tree, and bin/arcwheel runs.
set -euo pipefail
build=$(cd "$1" && pwd) version=$2 cxx=$3
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
source_dir=$(cd "$here/../.." && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/arcwheel_consumer.XXXXXX")
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix

# Prints a step's log and fails, naming the step.
run() {
  local step=$1
  shift
  if ! "$@" >"$work/$step.log" 2>&1; then
    cat "$work/$step.log"
    echo "consumer test: $step failed: $*" >&2
    exit 1
  fi
}

run install cmake --install "$build" --prefix "$prefix"

include_root=$prefix/include/arcwheel
missing=0
while read -r header included; do
  if [[ ! -f $include_root/$included ]]; then
    echo "consumer test: ${header#"$include_root"/} includes \"$included\", which is not installed" >&2
    missing=1
  fi
done < <(find "$include_root" -name '*.h' -exec grep -H '^#include "' {} + |
  sed 's/^\([^:]*\):#include "\([^"]*\)".*/\1 \2/')
((missing == 0))

if grep -rlF --include="*.cmake" -e "$build" -e "$source_dir" "$prefix"; then
  echo "consumer test: the installed CMake files above name the build or source tree" >&2
  exit 1
fi

[[ $("$prefix/bin/arcwheel" version) == "arcwheel $version" ]] || {
  echo "consumer test: $prefix/bin/arcwheel version does not print 'arcwheel $version'" >&2
  exit 1
}

run configure cmake -S "$here" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_PREFIX_PATH="$prefix" -DARCWHEEL_EXPECTED_VERSION="$version"
# The package found must be the fresh install, not one elsewhere on the machine.
found=$(sed -n 's/^arcwheel_DIR:PATH=//p' "$work/build/CMakeCache.txt")
[[ $found == "$prefix"/* ]] || {
  echo "consumer test: found arcwheel in '$found', not in $prefix" >&2
  exit 1
}
run build cmake --build "$work/build"
"$work/build/consumer"
