#!/usr/bin/env bash
# Fail if an object of the core references 64-bit division or
# double-precision helpers (libgcc's __aeabi_uldivmod, __aeabi_ldivmod,
# __udivmoddi4, __divdi3, __aeabi_d*, ...): on a 32-bit MCU each is a
# library call of hundreds of bytes and a data-dependent time. The KLV
# module (tase_klv.o: engineering units in double, host-side by design) is
# the one exception. Usage: scripts/checks/no-softmath.sh NM OBJECT...
set -euo pipefail
nm=$1; shift
pat='^(__aeabi_(u?ldivmod|d[a-z0-9]+|[lu]l?2d|d2[a-z]+)|__(u?divdi3|u?moddi3|u?divmoddi4))$'
bad=0
for obj in "$@"; do
    [ -f "$obj" ] || { echo "no such object: $obj"; exit 1; }
    [ "$(basename "$obj")" = tase_klv.o ] && continue
    syms=$("$nm" -u "$obj" | awk '{print $NF}' | grep -E "$pat" || true)
    if [ -n "$syms" ]; then
        echo "$(basename "$obj") references $(echo $syms)"
        bad=1
    fi
done
[ $bad = 0 ] || { echo "64-bit division or double arithmetic outside the KLV helpers"; exit 1; }
echo "no 64-bit division or double helpers in $# object(s) (tase_klv.o excepted)"
