#!/usr/bin/env bash
# The README's C example must stay true: extract the first ```c block,
# compile it against the core with the project's warning set, run it.
set -euo pipefail
. "$(dirname "$0")/../lib.sh"
out=${1:-$TASE_ROOT/build/readme-example}
mkdir -p "$out"
awk '/^```c/{n++; if (n == 1) {f = 1; next}} /^```/{f = 0} f' "$TASE_ROOT/README.md" > "$out/example.c"
[ -s "$out/example.c" ] || { echo "no C example found in README.md"; exit 1; }
cc -std=c99 -Wall -Wextra -Wpedantic -Wconversion -Wsign-conversion -Wshadow -Werror \
    -I"$TASE_ROOT/include" "$out/example.c" "$TASE_ROOT"/src/*.c -o "$out/example"
"$out/example"
echo "README example builds warning-free and runs"
