# The harness's front door. Everything a fresh machine needs is installed here: Rust crates
# through cargo, the Python environment of the NGSolve cross-check by crosscheck/setup.sh.
CARGO ?= cargo
# cargo builds into $(CARGO_TARGET_DIR) when it is set, target/ otherwise
BIN := $(or $(CARGO_TARGET_DIR),target)/release/signorini
SCRATCH := $(or $(CARGO_TARGET_DIR),target)/test-scratch
# clippy's check build, beside the release build of the tests (make test)
CLIPPY_TARGET := $(abspath $(or $(CARGO_TARGET_DIR),target)/clippy)
# each step of make test timed into target/test-steps (its last line lists them)
TIMED := scripts/timed.sh

.PHONY: all build test measured cluster-test figures reproduce drift crosscheck bench roundoff meshes mesh clean

all: build

build:
	$(CARGO) build --release --locked

# What CI runs: formatting and lints (rustfmt.toml, clippy -D warnings), unit and integration tests (release mode: the convergence tests solve real
# systems), the drift check (every study rerun and compared with results/ at every level, deep
# studies in their tiers (docs/drift.md): quick prefixes, their `full` runs to the end, the last level of their
# `replay` runs rebuilt from the stored refinement history and solved again; plus levels.csv,
# provenance and CLAIMS.md against the records), and the NGSolve cross-check.
# Test-time outputs (drift report, cross-check tables with timings) go under target/; the last
# step fails if the run changed any file git sees.
# After the formatting check, the first steps compile and install, side by side (scripts/beside.sh:
# each leaves a core idle at times, at the ends of its builds or waiting on PyPI): the test binaries and
# the example; clippy, with the check build of the dependencies it reads, in a target folder of
# its own (cargo builds one thing at a time in a folder, and a check build shares nothing with a
# release build); the cross-check's Python environment. The last line gives their time apart
# from the checks' own. The last line starts with
# "N passed, N failed, N skipped" over every test binary and the doc tests of the cargo test step
# (for CI tools), then the timing; make test writes only under target/ (its numbers there are what
# `make measured` copies into docs/measured.json).
test: build
	@mkdir -p target && date +%s > target/test-started && rm -f target/test-steps target/test-summary target/test-counts target/test-finished
	@(git rev-parse --short HEAD 2>/dev/null || echo unknown) > target/test-commit
	@(git status --porcelain --untracked-files=all 2>/dev/null || true) > target/status-before-test
	$(TIMED) fmt $(CARGO) fmt --all --check
	scripts/beside.sh build-tests '$(CARGO) build --release --locked --all-targets' \
		clippy 'CARGO_TARGET_DIR=$(CLIPPY_TARGET) $(CARGO) clippy --release --locked --all-targets -- -D warnings' \
		venv crosscheck/setup.sh
	@date +%s > target/test-compiled
	@scripts/chromium.sh >/dev/null || echo "NOTE: no chromium on this machine: the browser check of the study pages (tests/it/report_page.rs) is SKIPPED, and counted as skipped (apt-get install chromium; CI installs it)"
	@# the tests' scratch folders (std::env::temp_dir) under target/, emptied first, not left in /tmp
	@rm -rf $(SCRATCH) && mkdir -p $(SCRATCH)
	@# cargo's output as it prints it, kept in target/cargo-test.log; without chromium the browser test
	@# is skipped by name; target/test-summary gets "N passed, N failed, N skipped" over every test
	@# binary and the doc tests (scripts/test-summary.sh), printed again as make test's last line
	TMPDIR=$(abspath $(SCRATCH)) $(TIMED) cargo-test scripts/cargo-test.sh $(CARGO) test --release --locked --no-fail-fast
	$(TIMED) example $(CARGO) run --release --locked --example own_problem
	$(TIMED) drift $(BIN) drift
	$(TIMED) report $(BIN) report
	SIGNORINI=$(abspath $(BIN)) CROSSCHECK_OUT=target/crosscheck-report $(TIMED) crosscheck crosscheck/run.sh
	@(git status --porcelain --untracked-files=all 2>/dev/null || true) > target/status-after-test
	@diff target/status-before-test target/status-after-test >/dev/null || { echo "make test changed files git sees (before/after below); test outputs belong under target/"; diff target/status-before-test target/status-after-test; exit 1; }
	@date +%s > target/test-finished
	@echo "$$(cat target/test-summary); make test: PASSED in $$(( $$(cat target/test-finished) - $$(cat target/test-started) )) s after make build: $$(( $$(cat target/test-compiled) - $$(cat target/test-started) )) s for the formatting check, then compiling the tests and the example beside clippy (with its dependencies' check build) and installing the cross-check's Python environment, then $$(( $$(cat target/test-finished) - $$(cat target/test-compiled) )) s of checks (cargo test, the example, drift: none, study pages, NGSolve cross-check; the tree unchanged). Seconds per step: $$(tr '\n' ' ' < target/test-steps)"

# Copy the numbers of the last make test (what it left in target/) and of its /usr/bin/time -v log
# into docs/measured.json and docs/measured.md, deliberately (make test itself writes only under
# target/). On a fresh clone: `mkdir -p target && /usr/bin/time -v -o target/time.txt .ci/run`, then
# `make measured TIME_LOG=target/time.txt LOAD="nearly idle"` (idle, nearly idle or under load;
# BUILD_TIME_LOG=F adds make build's time from `/usr/bin/time -v -o F make build`, run first);
# commit both files, and update the quotes that tests/it/measured_numbers.rs then names.
measured:
	@test -n "$(TIME_LOG)" && test -n "$(LOAD)" || { echo 'usage: make measured TIME_LOG=target/time.txt LOAD="idle|nearly idle|under load"'; exit 2; }
	scripts/measured.py test --time-log $(TIME_LOG) --load "$(LOAD)" $(if $(BUILD_TIME_LOG),--build-time-log $(BUILD_TIME_LOG))

# A one-node Slurm cluster on this machine (as root; installs slurm-wlm and munge with apt-get
# if missing), a study submitted as an array of shards, a task cancelled mid-run, two arrays at
# once, each checked against a single-process run; everything under target/cluster/. About two
# minutes. See docs/studies.md, On a Slurm cluster.
cluster-test: build
	SIGNORINI=$(abspath $(BIN)) scripts/slurm/cluster-test.sh

# Redraw figures/ and results/CLAIMS.md from the stored results (no study is rerun). Builds only
# what redrawing needs (signorini-figures: records, claims, plots; no solver), which `signorini
# figures` also is, in the `figures` profile (Cargo.toml: unoptimised but for the crates drawing
# spends its time in); the records are checked as `signorini figures` checks them.
FIGURES_BIN := $(or $(CARGO_TARGET_DIR),target)/figures/signorini-figures
figures:
	$(CARGO) build --profile figures --locked -p signorini-claims --bin signorini-figures
	$(FIGURES_BIN)

# Rerun every declared study from scratch, rewrite results/, redraw.
reproduce: build
	$(BIN) run --fresh experiments/*.toml
	$(BIN) figures

# Every study rerun to the end, deep ones too (`make test` reruns deep studies in their tiers:
# docs/drift.md), and compared with results/ at every level, field by field; non-zero exit on
# drift. Report: target/drift/report.json. The scheduled CI job runs it.
drift: build
	$(BIN) drift --deep

# NGSolve cross-check: creates crosscheck/.venv from the pinned requirements on first use and
# stores its tables in results/crosscheck/.
crosscheck: build
	SIGNORINI=$(abspath $(BIN)) crosscheck/run.sh

# NGSolve's phase timings first (warm, medians over repeats in one process per size), then ours
# side by side; the numeric factorisation's rate against faer's dense LL^T (N = 256, 512, 1024);
# then whole solves in fresh processes, ours, NGSolve's (sparsecholesky) and NGSolve's with MKL
# PARDISO interleaved (medians of 3 at N = 256 and 512; PARDISO from crosscheck/.venv-bench, the
# bench's own venv with pinned MKL), the structured:1024 scale point, and the table of the targets
# with met / not met. About 30 minutes; results/bench/{ngsolve_bench,solver}.json. Then the graded
# section (issue 42): the deep study's levels nearest 2e6 NDF rebuilt from their stored histories
# and structured:512, each factorised phase by phase (orderings with their flops and METIS's as the
# anchor, symbolic, supernode sizes, numeric rate), about 5 minutes, results/bench/graded.json.
# Alone: `cargo run --release --locked --features bench-metis --bin bench -- --graded-only`
# (`--graded-ndof 9e6` for the deep study's last levels: about 13 GiB; `--graded-save DIR` writes
# each mesh as VTU and its node graph, for an independent count of fill and flops).
bench: build
	crosscheck/setup.sh && crosscheck/setup.sh bench
	crosscheck/.venv/bin/python crosscheck/crosscheck.py --out-dir results/bench bench --sizes 32,64,128,256,512
	$(CARGO) run --release --locked --features bench-metis --bin bench

# How far round-off moves the stored numbers: every study rerun three ways that change only the
# order of floating-point operations (nested dissection forced, minimum degree forced, one thread
# instead of all) by `signorini drift` (deep studies in their tiers), which compares each with
# results/ (automatic ordering, all threads; it must be current: `make drift` first); its report
# lists per study and float field the largest relative change and the largest change relative to
# the field's largest value in its run. Reports: results/roundoff/*.json, the basis of the
# manifests' [drift] tolerances. `make roundoff STUDIES="ex72_rollers hertz"` measures only those
# studies and merges them into the reports (`drift --merge`: the other studies' entries kept).
ROUNDOFF_VARIANTS := nested-dissection:$(shell nproc) minimum-degree:$(shell nproc) auto:1
roundoff: build
	@mkdir -p results/roundoff
	@set -e; for v in $(ROUNDOFF_VARIANTS); do \
		ordering=$${v%%:*}; jobs=$${v##*:}; name=$$ordering-$$jobs-threads; \
		echo "== $$name"; \
		SIGNORINI_ORDERING=$$ordering RAYON_NUM_THREADS=$$jobs $(BIN) drift $(if $(STUDIES),$(foreach s,$(STUDIES),--study $(s)) --merge) --report results/roundoff/$$name.json || true; \
	done

# Regenerate every experiments/meshes/*.msh from its .geo with gmsh's Python module, installed in
# the cross-check environment (crosscheck/requirements.txt pins it). The .msh files are committed:
# nothing else needs gmsh.
meshes:
	crosscheck/setup.sh
	crosscheck/.venv/bin/python experiments/meshes/generate.py

# Mesh a .geo of one's own: `make mesh GEO=path/to/disc.geo` writes path/to/disc.msh beside it
# (gmsh's Python module from the cross-check environment; its `gmsh` script cannot be run directly,
# its shebang names a `python` that is not the environment's).
mesh:
	@test -n "$(GEO)" || { echo "usage: make mesh GEO=path/to/file.geo"; exit 2; }
	crosscheck/setup.sh
	crosscheck/.venv/bin/python experiments/meshes/generate.py $(GEO)

clean:
	$(CARGO) clean
