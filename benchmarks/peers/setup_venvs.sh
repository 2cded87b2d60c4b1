#!/bin/sh
# Set up the peers of the star-identification, plate-solving and spacecraft benchmarks (idempotent: a venv whose
# stamp names the same requirement is left alone).  Each Python peer lives in its own venv because
# cedar-solve pins numpy<2 and Basilisk its own versions; astrometry.net comes from Debian.
#   benchmarks/.venv-cedar     cedar-solve==0.5.1 (imports as `tetra3`)
#   benchmarks/.venv-tetra3rs  tetra3rs==0.14.0 (Rust core, binary wheel)
#   benchmarks/.venv-basilisk  bsk==2.12.1 (Basilisk, the spacecraft benchmark's peer: it pins its own numpy, sgp4, tqdm)
#   astrometry.net             Debian packages astrometry.net and astrometry-data-tycho2-10-19 (installed
#                              here when run as root with apt-get, else named for the administrator)
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
make_venv "$HERE/.venv-basilisk" "bsk==2.12.1"

ASTROMETRY="astrometry.net astrometry-data-tycho2-10-19"
if ! command -v solve-field >/dev/null 2>&1 || ! ls /usr/share/astrometry/index-tycho2-1* >/dev/null 2>&1; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
        DEBIAN_FRONTEND=noninteractive apt-get install -y -q $ASTROMETRY
    else
        echo "astrometry.net not installed: as root, apt-get install $ASTROMETRY (its benchmarks report it missing)"
    fi
fi
