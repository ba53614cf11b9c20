#!/usr/bin/env bash
# Regenerate docs/FOOTPRINT.md: flash/RAM per module, receive path and whole
# core for Cortex-M0+ and M4 at -Os, sizeof of the public types, worst-case
# stack depths. Usage: scripts/footprint.sh [--out FILE] [--build DIR]
set -euo pipefail
. "$(dirname "$0")/lib.sh"
tase_need base firmware
exec python3 "$TASE_ROOT/scripts/footprint.py" "$@"
