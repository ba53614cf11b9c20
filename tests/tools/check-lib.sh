# Assertions shared by the capture and dissector checks; source it after
# setting `dir` (a scratch directory). Each check prints "ok" or "FAIL" and
# the script ends with `check_summary WHAT`.
# shellcheck shell=bash
fails=0
# Under scripts/checks/valgrind.sh (TASE_UNDER_VALGRIND=1) the programs run
# under memcheck and start and run about ten times slower: time limits and
# the lifetimes of background simulators scale by `slow`.
slow=1
if [ "${TASE_UNDER_VALGRIND:-}" = 1 ]; then slow=10; fi
ok() { echo "ok   $*"; }
bad() { echo "FAIL $*"; fails=$((fails + 1)); }
# check NAME CONDITION-COMMAND...: a named assertion
check() {
    local name=$1
    shift
    if "$@"; then ok "$name"; else bad "$name"; fi
}
# wait_for FILE PATTERN: up to 5 s (times slow) for PATTERN to appear in FILE
wait_for() {
    local i
    for i in $(seq $((100 * slow))); do
        grep -q -- "$2" "$1" 2>/dev/null && return 0
        sleep 0.05
    done
    return 1
}
# expect_error NAME STATUS PATTERN CMD...: CMD exits with STATUS (any
# non-zero if STATUS is "nz") and prints exactly one line on stderr,
# matching PATTERN
expect_error() {
    local name=$1 want=$2 pat=$3 rc lines
    shift 3
    "$@" >"$dir/out" 2>"$dir/err.all" </dev/null
    rc=$?
    # memcheck's own notes (==PID== lines, e.g. on TIOCEXCL) are not ours;
    # a memory error shows as exit 99
    grep -v '^==[0-9]*==' "$dir/err.all" >"$dir/err"
    lines=$(wc -l <"$dir/err")
    if { [ "$want" = nz ] && [ $rc -ne 0 ] || [ "$rc" = "$want" ]; } &&
        [ "$lines" -eq 1 ] && grep -q -- "$pat" "$dir/err"; then
        ok "$name: exit $rc, $(cat "$dir/err")"
    else
        bad "$name: exit $rc, $lines stderr lines: $(head -c 300 "$dir/err")"
    fi
}
# under_valgrind VAR...: under scripts/checks/valgrind.sh (TASE_UNDER_VALGRIND=1)
# the shell itself is not traced, so the programs named by the variables
# are wrapped in memcheck here (an error exits 99 and fails the check).
under_valgrind() {
    local v
    [ "${TASE_UNDER_VALGRIND:-}" = 1 ] || return 0
    for v in "$@"; do
        printf '#!/bin/sh\nexec valgrind -q --vgdb=no --error-exitcode=99 --leak-check=full --errors-for-leak-kinds=definite,indirect --show-leak-kinds=definite,indirect "%s" "$@"\n' \
            "${!v}" >"$dir/vg-$v"
        chmod +x "$dir/vg-$v"
        eval "$v=\$dir/vg-\$v"
    done
}
# wait_link PATH...: wait up to 5 s (times slow) for each PATH to exist as
# a symbolic link, as a simulator started in the background makes its pty's;
# returns 1 when one did not appear
wait_link() {
    local p
    for p in "$@"; do
        for _ in $(seq $((100 * slow))); do
            [ -L "$p" ] && break
            sleep 0.05
        done
        [ -L "$p" ] || return 1
    done
}
# sim_says PATTERN: how many lines of the simulator's log ($dir/sim.log) match
sim_says() { grep -c -- "$1" "$dir/sim.log"; }
# sim_reaches N PATTERN: true when the simulator's log comes to N matching
# lines (waiting up to 5 s, times slow: a loaded machine runs the simulator
# late) and still has N 0.2 s later (a duplicate shows then)
sim_reaches() {
    for _ in $(seq $((100 * slow))); do
        [ "$(sim_says "$2")" -ge "$1" ] && break
        sleep 0.05
    done
    sleep 0.2
    [ "$(sim_says "$2")" = "$1" ]
}
# check_summary WHAT: exit 1 when a check failed
check_summary() {
    if [ $fails -ne 0 ]; then
        echo "$fails $1 check(s) failed"
        exit 1
    fi
}
