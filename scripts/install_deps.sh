#!/usr/bin/env bash
# Installs the Debian packages listed in scripts/packages.txt that are not installed yet; with
# --binary-only, only those that building and running the `arcwheel` binary needs (the list's
# first part, scripts/demo.sh). Idempotent: does nothing (and needs no network) when everything is
# present.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
list=$(cat "$here/packages.txt")
if [[ "${1:-}" == "--binary-only" ]]; then
  list=$(sed '/^# -- binary only above/q' "$here/packages.txt")
fi
mapfile -t wanted < <(grep -v '^\s*#' <<<"$list" | grep -v '^\s*$')
missing=()
for package in "${wanted[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$package" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$package")
done
if ((${#missing[@]} == 0)); then
  exit 0
fi
echo "install_deps: installing ${missing[*]}"
sudo=()
if [[ $(id -u) -ne 0 ]]; then
  command -v sudo >/dev/null || { echo "install_deps: run as root or install sudo" >&2; exit 1; }
  sudo=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update -qq
"${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
