#!/bin/sh
# scripts/timed.sh STEP COMMAND...: run COMMAND, then append "STEP SECONDS" to target/test-steps
# (wall-clock seconds), so that make test's last line says where its time went. The command's
# exit status is kept.
step=$1
shift
start=$(date +%s)
"$@"
status=$?
mkdir -p target && echo "$step $(( $(date +%s) - start ))" >> target/test-steps
exit $status
