#!/usr/bin/env bash
# Installs what is missing and builds arcwheel (Release) into build/. ARCWHEEL_WERROR=ON (as CI
# sets it) makes every compiler warning an error.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/scripts/install_deps.sh"
cmake -S "$root" -B "$root/build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DARCWHEEL_WERROR="${ARCWHEEL_WERROR:-OFF}" "$@" >/dev/null
cmake --build "$root/build" --parallel "$(nproc)"
