#!/usr/bin/env bash
# Regenerate docs/FOOTPRINT.md: flash/RAM per module, receive path and whole
# core for Cortex-M0+ and M4 at -Os, sizeof of the public types, worst-case
# stack depths, and the two example images (the autopilot's stack is
# measured on its mission against tase-sim: --sim names the binary, else one
# is built). Usage: bench/footprint.sh [--out FILE] [--build DIR] [--sim TASE_SIM]
set -euo pipefail
. "$(dirname "$0")/../scripts/lib.sh"
tase_need base firmware
exec python3 "$TASE_ROOT/bench/footprint.py" "$@"
