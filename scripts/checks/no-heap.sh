#!/usr/bin/env bash
# Fail if any given object or archive references malloc, calloc, realloc or
# free. Usage: scripts/checks/no-heap.sh NM FILE...
set -euo pipefail
nm=$1; shift
bad=$("$nm" -u "$@" 2>/dev/null | grep -E '^\s*U (malloc|calloc|realloc|free)$' || true)
if [ -n "$bad" ]; then
    echo "heap functions referenced by the core:"; echo "$bad"; exit 1
fi
echo "no heap references in $# file(s)"
