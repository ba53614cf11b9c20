#!/usr/bin/env bash
# Valgrind memcheck over the tests of an existing build: every ctest test
# labelled `unit` (the cmocka programs, corpus replays) or `e2e` (the
# tools' end-to-end tests) is re-run under
#   valgrind --error-exitcode=1 --leak-check=full
# A test whose command is a script is run with --trace-children=yes, so the
# programs it starts from the build tree (tools/tase, tase-sim, ...) are
# checked too; system programs (/usr, /bin, ...) are skipped. Tests see
# TASE_UNDER_VALGRIND=1 and may scale their timeouts by it.
# Usage: scripts/checks/valgrind.sh [BUILDDIR] [all|serial|parallel]
#   (default build, all). `serial` takes only the tests ctest runs alone
#   (RUN_SERIAL: on the real clock), `parallel` the others; ctest registers
#   the two halves as valgrind_serial and valgrind, so that they run side by
#   side while each half keeps its tests one after another.
set -euo pipefail
. "$(dirname "$0")/../lib.sh"
build=$(cd "${1:-$TASE_ROOT/build}" && pwd)
part=${2:-all}
case $part in
    all | serial | parallel) ;;
    *) echo "usage: $0 [BUILDDIR] [all|serial|parallel]" >&2; exit 2 ;;
esac
# shellcheck disable=SC2054 # the commas are in valgrind's own option values
vg=(valgrind -q --error-exitcode=99 --leak-check=full --errors-for-leak-kinds=definite,indirect
    --show-leak-kinds=definite,indirect --track-origins=yes)
skip='/usr/*,/bin/*,/sbin/*,/lib/*,/lib64/*,/etc/*'
list=$(cd "$build" && ctest --show-only=json-v1 | python3 -c '
import json, sys
part = sys.argv[1]
for t in json.load(sys.stdin)["tests"]:
    props = {p["name"]: p["value"] for p in t.get("properties", [])}
    labels = props.get("LABELS", [])
    if part != "all" and bool(props.get("RUN_SERIAL")) != (part == "serial"):
        continue
    if ("unit" in labels or "e2e" in labels) and t.get("command"):
        wd = props.get("WORKING_DIRECTORY", "")
        env = props.get("ENVIRONMENT", [])
        print("\x1f".join([t["name"], wd, "\x1e".join(env)] + t["command"]))
' "$part")
n=0; failed=()
while IFS=$'\x1f' read -r -a f; do
    [ ${#f[@]} -ge 4 ] || continue
    name=${f[0]}; wd=${f[1]:-$build}; envs=${f[2]}; cmd=("${f[@]:3}")
    extra=()
    if ! head -c4 "${cmd[0]}" 2>/dev/null | grep -q 'ELF'; then
        extra=(--trace-children=yes --trace-children-skip="$skip")
    fi
    envargs=(TASE_UNDER_VALGRIND=1)
    if [ -n "$envs" ]; then IFS=$'\x1e' read -r -a e <<<"$envs"; envargs+=("${e[@]}"); fi
    n=$((n + 1))
    start=$SECONDS
    if (cd "$wd" && env "${envargs[@]}" "${vg[@]}" "${extra[@]}" "${cmd[@]}" \
            >"$build/valgrind-$name.log" 2>&1); then
        echo "memcheck $name: clean ($((SECONDS - start)) s)"
    else
        echo "memcheck $name: FAILED, log $build/valgrind-$name.log"
        # the test's own failures (FAIL lines, its last words), then memcheck's
        # reports without its notes on ioctls it does not model (TIOCEXCL)
        log=$build/valgrind-$name.log
        grep -E '^FAIL ' "$log" | head -20 || true
        grep -v -e '^==[0-9]*==' -e '^FAIL ' "$log" | tail -3
        grep -E '^==[0-9]+==' "$log" | grep -v -E 'unhandled ioctl|spurious value errors|README_MISSING_SYSCALL' |
            head -30 || true
        failed+=("$name")
    fi
done <<<"$list"
[ "$n" -gt 0 ] || { echo "no unit/e2e tests ($part) found in $build"; exit 1; }
if [ ${#failed[@]} -gt 0 ]; then echo "memcheck failed: ${failed[*]}"; exit 1; fi
echo "valgrind memcheck ($part): $n test(s) clean"
