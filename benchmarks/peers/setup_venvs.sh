#!/bin/sh
# Create the peer virtualenvs of benchmarks/star_id.py (idempotent: a venv whose stamp names the
# same requirement is left alone).  Each peer lives in its own venv because cedar-solve pins numpy<2.
#   benchmarks/.venv-cedar     cedar-solve==0.5.1 (imports as `tetra3`)
#   benchmarks/.venv-tetra3rs  tetra3rs==0.14.0 (Rust core, binary wheel)
# Usage: sh benchmarks/peers/setup_venvs.sh [PYTHON]   (PYTHON defaults to python3)
set -eu
PYTHON=${1:-python3}
HERE=$(cd "$(dirname "$0")/.." && pwd)

make_venv() {
    dir=$1
    requirement=$2
    stamp=$dir/.installed
    if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$requirement" ]; then
        return 0
    fi
    test -x "$dir/bin/python" || "$PYTHON" -m venv "$dir"
    "$dir/bin/python" -m pip install --quiet --upgrade pip
    "$dir/bin/python" -m pip install --quiet "$requirement"
    printf '%s' "$requirement" > "$stamp"
}

make_venv "$HERE/.venv-cedar" "cedar-solve==0.5.1"
make_venv "$HERE/.venv-tetra3rs" "tetra3rs==0.14.0"
