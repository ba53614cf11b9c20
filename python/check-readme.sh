#!/usr/bin/env bash
# The README's Python section must stay true (issue 22): run its install
# commands in a fresh venv in a scratch directory (offline: --no-index),
# then its example against tase-sim. The package is copied out of the
# source tree first, so that pip's in-tree build leaves the clone clean
# (TASE_SOURCE_DIR points the build at the sources).
# Usage: python/check-readme.sh TASE_SIM [PYTHON]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
sim=$1
py=${2:-python3}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
section=$(awk '/^## Python$/{f = 1; next} /^## /{f = 0} f' "$root/README.md")
[ -n "$section" ] || { echo "README.md has no '## Python' section"; exit 1; }
cp -r "$root/python" "$work/python"
rm -rf "$work/python/build" "$work/python/"*.egg-info
# the install commands: indented lines running python3 -m venv or the venv's programs
grep -E '^    ((/usr/bin/)?python3 -m venv|~/tase-venv/bin/)' <<<"$section" |
    sed -e "s|~/tase-venv|$work/venv|g" -e "s|^    \(/usr/bin/\)\{0,1\}python3 |$py |" \
        -e "s| \./python| $work/python|" \
        >"$work/install.sh"
[ "$(wc -l <"$work/install.sh")" -ge 3 ] || { cat "$work/install.sh"; echo "install commands not found"; exit 1; }
echo "== README install commands:"
cat "$work/install.sh"
(cd "$work" && TASE_SOURCE_DIR="$root" PIP_NO_INPUT=1 bash -euo pipefail "$work/install.sh") >"$work/install.log" 2>&1 || {
    cat "$work/install.log"
    echo "FAIL: the README's install commands"
    exit 1
}
tail -1 "$work/install.log"
# the example: the indented block that starts with "import tase"
awk '/^    import tase$/{f = 1} f && /^$/{exit} f {print substr($0, 5)}' <<<"$section" >"$work/example.py"
[ -s "$work/example.py" ] || { echo "README example not found"; exit 1; }
echo "== README example against tase-sim:"
(cd "$work" && TASE_SIM="$sim" timeout 60 "$work/venv/bin/python" example.py) >"$work/example.out" 2>&1 || {
    cat "$work/example.out"
    echo "FAIL: the README's example"
    exit 1
}
head -3 "$work/example.out"
grep -q '"name":"GIMBAL_ANGLE"' "$work/example.out" || { echo "FAIL: no telemetry printed"; exit 1; }
echo "README Python section: installed offline in a fresh venv, example ran against tase-sim"
