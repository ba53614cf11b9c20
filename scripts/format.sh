#!/usr/bin/env bash
# clang-format check of every C file we write (src/, include/, port/,
# tools/, tests/, examples/, fuzz/, cmake/) against the checked-in
# .clang-format. Usage:
#   scripts/format.sh          fail (exit 1) and list the files that differ
#   scripts/format.sh --fix    reformat those files in place
set -euo pipefail
. "$(dirname "$0")/lib.sh"
cf=$(command -v clang-format-14 || command -v clang-format)
cd "$TASE_ROOT"
mapfile -t files < <(find src include port tools tests examples fuzz cmake \
    -type f \( -name '*.c' -o -name '*.h' \) 2>/dev/null | sort)
if [ "${1:-}" = "--fix" ]; then
    "$cf" -i --style=file "${files[@]}"
    echo "formatted ${#files[@]} file(s)"
    exit 0
fi
bad=()
for f in "${files[@]}"; do
    "$cf" --style=file --dry-run --Werror "$f" >/dev/null 2>&1 || bad+=("$f")
done
if [ ${#bad[@]} -gt 0 ]; then
    echo "not clang-formatted (run scripts/format.sh --fix):"
    printf '  %s\n' "${bad[@]}"
    for f in "${bad[@]:0:3}"; do "$cf" --style=file "$f" | diff -u "$f" - | head -20 || true; done
    exit 1
fi
echo "clang-format: ${#files[@]} file(s) clean"
