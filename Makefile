# The harness's front door (CONTRACT.md). Everything a fresh machine needs is installed here:
# Rust crates through cargo, the Python environment of the NGSolve cross-check by crosscheck/setup.sh.
CARGO ?= cargo
BIN := target/release/signorini

.PHONY: all build test figures reproduce drift crosscheck bench clean

all: build

build:
	$(CARGO) build --release --locked

# Unit and integration tests (release mode: the convergence tests solve real systems), the
# quick drift check against results/, and the NGSolve cross-check.
test: build
	$(CARGO) test --release --locked
	$(BIN) drift --quick
	crosscheck/run.sh

# Redraw figures/ and results/CLAIMS.md from the stored results (no study is rerun).
figures: build
	$(BIN) figures

# Rerun every declared study from scratch, rewrite results/, redraw.
reproduce: build
	$(BIN) run --fresh experiments/*.toml
	$(BIN) figures

# Quick forms of every study against results/, field by field; non-zero exit on drift.
drift: build
	$(BIN) drift --quick

# NGSolve cross-check: creates crosscheck/.venv from the pinned requirements on first use.
crosscheck: build
	crosscheck/run.sh

# NGSolve's timings first, then ours with the two side by side (medians over repeats).
bench: build
	crosscheck/setup.sh && crosscheck/.venv/bin/python crosscheck/crosscheck.py --out-dir results/bench bench --sizes 32,64,128,256,512
	$(CARGO) run --release --locked --bin bench

clean:
	$(CARGO) clean
