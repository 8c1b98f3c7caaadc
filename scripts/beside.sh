#!/usr/bin/env bash
# scripts/beside.sh STEP 'COMMAND' [STEP 'COMMAND']...: run the first step in the foreground (its
# output as it comes) and the others beside it, each through scripts/timed.sh, so that each step's
# own wall seconds go to target/test-steps. The others' output goes to target/STEP.log and is
# printed, step by step, once every step has finished. The exit status is 0 only if every step's
# is; the failed steps are named.
#
# make test uses it for steps that each leave a core idle at times when run alone: the compile of
# the test binaries beside clippy's check build and the cross-check's Python environment (mostly
# waiting on PyPI).
set -uo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
if [ $# -lt 2 ] || [ $(($# % 2)) -ne 0 ]; then
    echo "usage: scripts/beside.sh STEP 'COMMAND' [STEP 'COMMAND']..." >&2
    exit 2
fi
mkdir -p target
first_step=$1 first_command=$2
shift 2
# the names of the steps run side by side, for scripts/measured.py (make test's numbers)
{
    echo "$first_step"
    for ((i = 1; i <= $#; i += 2)); do echo "${!i}"; done
} >target/test-beside
steps=() pids=()
while [ $# -gt 0 ]; do
    echo "$1: running beside $first_step (its output: target/$1.log)"
    "$here/timed.sh" "$1" sh -c "$2" >"target/$1.log" 2>&1 &
    steps+=("$1") pids+=($!)
    shift 2
done
"$here/timed.sh" "$first_step" sh -c "$first_command"
status=$?
failed=()
[ $status -eq 0 ] || failed+=("$first_step")
for i in "${!steps[@]}"; do
    wait "${pids[$i]}" || failed+=("${steps[$i]}")
    echo "--- ${steps[$i]} (target/${steps[$i]}.log):"
    cat "target/${steps[$i]}.log"
done
if [ ${#failed[@]} -gt 0 ]; then
    echo "scripts/beside.sh: failed: ${failed[*]}" >&2
    exit 1
fi
