#!/usr/bin/env bash
# Create crosscheck/.venv with the pinned requirements (`setup.sh bench`: crosscheck/.venv-bench with
# requirements-bench.txt, the benchmark's, which adds MKL for PARDISO). Idempotent: does nothing when the venv
# exists and is at least as new as requirements.txt; otherwise rebuilds it from scratch (--clear),
# so a changed requirements.txt never leaves stale packages behind. Needs python3 (>= 3.11, for the pinned numpy) and PyPI.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
case "${1:-}" in
    "") venv="$here/.venv"; req="$here/requirements.txt" ;;
    bench) venv="$here/.venv-bench"; req="$here/requirements-bench.txt" ;;
    *) echo "crosscheck/setup.sh: unknown argument '$1' (expected nothing or 'bench')" >&2; exit 2 ;;
esac
stamp="$venv/.requirements.stamp"

if [ -x "$venv/bin/python" ] && [ -f "$stamp" ] && [ ! "$req" -nt "$stamp" ] && [ ! "$here/requirements.txt" -nt "$stamp" ]; then
    exit 0
fi
echo "crosscheck/setup.sh: creating $venv from $(basename "$req")"
rm -f "$stamp"
python3 -m venv --clear "$venv"
"$venv/bin/python" -m pip install --disable-pip-version-check --quiet -r "$req"
"$venv/bin/python" -c "import ngsolve, meshio, numpy, gmsh" # fail here, not in the first check
touch "$stamp"
