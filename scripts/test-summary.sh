#!/bin/sh
# scripts/test-summary.sh LOG [COUNTS]: read the output of `cargo test` (LOG, as make test tees it
# to target/cargo-test.log) and print one line "N passed, N failed, N skipped", summed over every
# test binary and the doc tests. Skipped counts cargo's "ignored" and "filtered out" (make test
# skips the browser test by name when there is no Chromium: tests/it/report_page.rs). A binary that
# did not get to its "test result:" line (a crash, a failed build) counts as one failure. With
# COUNTS, also write "KEY VALUE" lines there: passed, failed, skipped, and the tests run
# (passed + failed) by kind: unit (every "Running unittests"), integration (every other "Running"),
# doc (every "Doc-tests"). Works on saved output: scripts/test-summary.sh saved-cargo-output.txt
set -eu
log=$1
counts=${2:-}
awk -v counts="$counts" '
function flush() {
    if (kind != "" && !seen) { failed++; byk[kind]++ }
    kind = ""; seen = 0
}
/^[[:space:]]*Running unittests / { flush(); kind = "unit"; next }
/^[[:space:]]*Running /            { flush(); kind = "integration"; next }
/^[[:space:]]*Doc-tests /          { flush(); kind = "doc"; next }
/^test result: / {
    line = $0
    p = f = i = x = 0
    if (match(line, /[0-9]+ passed/)) p = substr(line, RSTART, RLENGTH) + 0
    if (match(line, /[0-9]+ failed/)) f = substr(line, RSTART, RLENGTH) + 0
    if (match(line, /[0-9]+ ignored/)) i = substr(line, RSTART, RLENGTH) + 0
    if (match(line, /[0-9]+ filtered out/)) x = substr(line, RSTART, RLENGTH) + 0
    passed += p; failed += f; skipped += i + x
    k = (kind == "") ? "unknown" : kind
    byk[k] += p + f
    seen = 1
    next
}
END {
    flush()
    printf "%d passed, %d failed, %d skipped\n", passed, failed, skipped
    if (counts != "") {
        printf "passed %d\nfailed %d\nskipped %d\nunit %d\nintegration %d\ndoc %d\n", passed, failed, skipped, byk["unit"], byk["integration"], byk["doc"] > counts
    }
}' "$log"
