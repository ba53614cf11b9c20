#!/usr/bin/env bash
# Moved: the receiver benchmark is bench/bench.sh (kept here so that old
# instructions still work).
exec "$(dirname "$0")/../bench/bench.sh" "$@"
