#!/usr/bin/env bash
# Static analysis, warnings as errors:
#   1. cppcheck 2.10 (warning, style, performance, portability) over src/
#      and port/, using the compile database;
#   2. cppcheck's MISRA C:2012 addon over src/, minus the deviations listed
#      in docs/MISRA.md;
#   3. clang-tidy with the checked-in .clang-tidy over src/ and port/.
# Usage: scripts/checks/static.sh [OUTDIR] (default build-static)
set -euo pipefail
. "$(dirname "$0")/../lib.sh"
out=${1:-$TASE_ROOT/build-static}
mkdir -p "$out"
tidy=$(command -v clang-tidy-14 || command -v clang-tidy)
# Compile database from a clang configuration of the whole tree.
cmake -S "$TASE_ROOT" -B "$out" -DCMAKE_C_COMPILER=clang -DCMAKE_EXPORT_COMPILE_COMMANDS=ON \
    -DTASE_CHECKS=OFF >/dev/null
db="$out/compile_commands.json"
rc=0

common=(--std=c99 --inline-suppr --error-exitcode=1 --quiet --project="$db"
        --enable=warning,style,performance,portability --suppress=missingIncludeSystem
        --cppcheck-build-dir="$out/cppcheck" -j2)
mkdir -p "$out/cppcheck"
echo "== cppcheck: src/ port/"
cppcheck "${common[@]}" --file-filter="$TASE_ROOT/src/*" --file-filter="$TASE_ROOT/port/*" \
    --template='{file}:{line}: {severity}: {message} [{id}]' || rc=1

echo "== cppcheck MISRA C:2012: src/ (deviations: docs/MISRA.md)"
sup="$out/misra-deviations.txt"
sed -n 's/^| *\([0-9][0-9]*\.[0-9][0-9]*\) *|.*/misra-c2012-\1/p' "$TASE_ROOT/docs/MISRA.md" >"$sup"
echo "   deviations: $(tr '\n' ' ' <"$sup")"
mkdir -p "$out/misra"
cppcheck --std=c99 --inline-suppr --error-exitcode=1 --quiet --project="$db" \
    --file-filter="$TASE_ROOT/src/*" --addon=misra --suppressions-list="$sup" \
    --suppress=missingIncludeSystem --cppcheck-build-dir="$out/misra" \
    --template='{file}:{line}: MISRA {id}' || rc=1

echo "== clang-tidy: src/ port/"
# .clang-tidy turns clang-analyzer-valist.* off because no library file uses
# va_list (and clang-tidy 14 gave a false report there once); if one does,
# they must be turned back on.
if grep -rlE 'va_list|<stdarg\.h>' "$TASE_ROOT/include" "$TASE_ROOT/src" "$TASE_ROOT/port"; then
    echo "the files above use va_list: remove -clang-analyzer-valist.* from .clang-tidy"
    rc=1
fi
mapfile -t files < <(find "$TASE_ROOT/src" "$TASE_ROOT/port" -name '*.c' 2>/dev/null | sort)
for f in "${files[@]}"; do
    if ! msg=$("$tidy" -p "$out" --quiet "$f" 2>&1); then
        rc=1
    fi
    grep -v -E '^[0-9]+ (warning|error)s? .*generated' <<<"$msg" | grep . || true
done
if [ "$rc" -ne 0 ]; then
    echo "static analysis: FAILED"
    exit 1
fi
echo "static analysis: clean (${#files[@]} files for clang-tidy)"
