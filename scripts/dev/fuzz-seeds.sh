#!/usr/bin/env bash
# Regenerate the committed seed corpus fuzz/corpus/<harness>/seed-* from
# fuzz/seeds.c (deterministic). Crash regressions (regress-*) and inputs
# you add by hand are left alone.
set -euo pipefail
. "$(dirname "$0")/../lib.sh"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
cc -std=c99 -O1 -I"$TASE_ROOT/include" "$TASE_ROOT"/src/*.c "$TASE_ROOT/fuzz/seeds.c" -o "$out/seeds"
for f in "$TASE_ROOT"/fuzz/*.c; do
    h=$(basename "$f" .c)
    case $h in seeds|replay_main) continue ;; esac
    mkdir -p "$TASE_ROOT/fuzz/corpus/$h"
done
"$out/seeds" "$TASE_ROOT/fuzz/corpus"
ls "$TASE_ROOT"/fuzz/corpus/*
