# The harness's front door (CONTRACT.md). Everything a fresh machine needs is installed here:
# Rust crates through cargo, the Python environment of the NGSolve cross-check by crosscheck/setup.sh.
CARGO ?= cargo
BIN := target/release/signorini

.PHONY: all build test figures reproduce drift crosscheck bench clean

all: build

build:
	$(CARGO) build --release --locked

# Unit and integration tests (release mode: the convergence tests solve real systems).
test: build
	$(CARGO) test --release --locked
	crosscheck/run.sh

figures: build
	@echo "figures: not generated yet (they come with the studies, issue 4); nothing to do."

reproduce: build
	@echo "reproduce: no studies are declared yet (issue 4); nothing to do."

drift: build
	@echo "drift: no stored results yet (issue 5); nothing to compare."

# NGSolve cross-check: creates crosscheck/.venv from the pinned requirements on first use.
crosscheck: build
	crosscheck/run.sh

bench: build
	$(CARGO) run --release --locked --bin bench
	crosscheck/setup.sh && crosscheck/.venv/bin/python crosscheck/crosscheck.py --out-dir results/bench bench --sizes 32,64,128,256

clean:
	$(CARGO) clean
