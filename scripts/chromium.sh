#!/bin/sh
# scripts/chromium.sh: print the Chromium the browser test would use and exit 0, or exit 1 if
# there is none. The same search as tests/it/common/browser.rs: $CHROMIUM, then chromium,
# chromium-browser, google-chrome, google-chrome-stable, each answering --version.
for c in ${CHROMIUM:-} chromium chromium-browser google-chrome google-chrome-stable; do
    if "$c" --version >/dev/null 2>&1; then
        echo "$c"
        exit 0
    fi
done
exit 1
