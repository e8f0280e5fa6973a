#!/usr/bin/env bash
# Formats every C++ file git tracks with the project's .clang-format (clang-format 14, Debian's).
# --check changes nothing and lists the files that differ; it exits 1 if there are any (CI).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
command -v clang-format >/dev/null || { echo "format: clang-format is not installed" >&2; exit 1; }
mapfile -t files < <(git ls-files '*.cc' '*.h')
if [[ "${1:-}" != "--check" ]]; then
  clang-format -i "${files[@]}"
  exit 0
fi
differing=()
for file in "${files[@]}"; do
  clang-format "$file" | cmp -s - "$file" || differing+=("$file")
done
if ((${#differing[@]} > 0)); then
  echo "format: ${#differing[@]} files differ from .clang-format (run scripts/format.sh):" >&2
  printf '  %s\n' "${differing[@]}" >&2
  exit 1
fi
echo "format: ${#files[@]} files match .clang-format"
