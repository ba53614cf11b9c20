#!/usr/bin/env bash
# Every public function of src/ and of the bare-metal port: the names the
# headers of include/tase/ and port/baremetal/tase/ declare, one a line,
# sorted (a qualifier macro such as TASE_INLINE_ may stand before the
# name). bench/bench.sh lists those TIMING.md lacks a row for;
# scripts/checks/timing-rows.sh fails on any.
# Usage: bench/public-fns.sh [SOURCE_DIR] (default: this repository)
set -euo pipefail
root=${1:-$(cd "$(dirname "$0")/.." && pwd)}
grep -ho '^[a-z][A-Za-z0-9_ *]* \**tase_[a-z0-9_]*(' "$root"/include/tase/*.h \
    "$root"/port/baremetal/tase/*.h |
    sed 's/($//; s/.*[ *]//' | sort -u
