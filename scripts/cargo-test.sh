#!/bin/sh
# scripts/cargo-test.sh COMMAND...: make test's cargo test step. Runs COMMAND (cargo test ...) with
# its output shown as cargo prints it and kept in target/cargo-test.log; without Chromium
# (scripts/chromium.sh) adds `-- --skip` of the browser test of the study pages, which cargo then
# counts as filtered out. Then writes the one-line summary (scripts/test-summary.sh) to
# target/test-summary and the counts by kind to target/test-counts, prints the line, and exits
# with cargo's status (a failing test fails make test; the line is printed either way).
set -u
browser_test=report_page::study_pages_load_in_chromium_with_every_image_and_claim
dir=$(dirname "$0")
mkdir -p target
if "$dir/chromium.sh" >/dev/null; then
    set -- "$@"
else
    set -- "$@" -- --skip "$browser_test"
fi
status_file=target/cargo-test.status
rm -f "$status_file"
{ "$@" 2>&1; echo $? > "$status_file"; } | tee target/cargo-test.log
status=$(cat "$status_file")
"$dir/test-summary.sh" target/cargo-test.log target/test-counts > target/test-summary
if [ "$status" != 0 ]; then
    echo "$(cat target/test-summary); make test: FAILED in cargo test (exit status $status)"
else
    cat target/test-summary
fi
exit "$status"
