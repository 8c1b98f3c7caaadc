#!/usr/bin/env bash
# `make crosscheck`: export cases with the Rust binary, then run the NGSolve self-test, comparison,
# rate check and estimator check on them. Every step runs even if an earlier one failed (all tables
# get printed); the exit status is non-zero if any failed. Results: {selftest,compare,rates,estimator}.{json,md} in
# $CROSSCHECK_OUT (default results/crosscheck, what `make crosscheck` stores; `make test` writes them
# under target/ so that a test run changes no tracked file: the tables carry timings).
set -uo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(dirname "$here")"
bin="${SIGNORINI:-$root/target/release/signorini}"
cases="$root/target/crosscheck"  # scratch space, under the ignored target/
out="${CROSSCHECK_OUT:-$root/results/crosscheck}"

"$here/setup.sh" || exit 1
py="$here/.venv/bin/python"
rm -rf "$cases" && mkdir -p "$cases"
all=() exact=()
for spec in ex71:8 ex71:16 ex71:32 ex71:64 ex72:8 ex72:16 ex72:32 fb:8 fb:16 fb:32 fb:64; do
    p="${spec%%:*}" n="${spec##*:}"
    dir="$cases/$p-structured-$n"
    "$bin" export --problem "$p" --mesh "structured:$n" --out "$dir" || exit 1
    all+=("$dir")
    [ "$p" != ex72 ] && exact+=("$dir")  # problems with an exact solution: rates
done

# adaptive meshes (level 10 of the studies' loop) and the Example 7.2 reference solution of the
# studies (experiments/ex72.toml: adaptive, theta 0.5, eta_5 without full-contact nodes, NDF >= 250,000)
for p in ex71 ex72 fb; do
    dir="$cases/$p-adaptive-10"
    "$bin" export --problem "$p" --mesh structured:4 --adapt-levels 10 --out "$dir" || exit 1
    all+=("$dir")
done
# the meshes the repaired estimator grades (study estimator_repair: contact_term
# tensile_on_full_contact), level 10
for p in ex71 ex72 fb; do
    dir="$cases/$p-adaptive-repaired-10"
    "$bin" export --problem "$p" --mesh structured:4 --adapt-levels 10 --contact-term tensile-on-full-contact --out "$dir" || exit 1
    all+=("$dir")
done
# the estimator's cases (`crosscheck.py estimator`): besides the structured and adaptive ones above
# (contact_term as_written and tensile_on_full_contact), eta_5 without full-contact nodes on
# structured meshes, Example 7.2 on rollers, and Hertz from its Gmsh mesh (experiments/hertz.toml's
# problem and mesh), on the mesh itself and refined adaptively with the repaired contact terms
est=("$cases/ex71-structured-16" "$cases/ex72-structured-16" "$cases/fb-structured-16")
for p in ex71 ex72 fb; do
    est+=("$cases/$p-adaptive-10" "$cases/$p-adaptive-repaired-10")
done
for p in ex71 ex72 fb; do
    dir="$cases/$p-structured-16-without-full-contact"
    "$bin" export --problem "$p" --mesh structured:16 --contact-term without-full-contact --out "$dir" || exit 1
    est+=("$dir")
done
# Example 7.2 on rollers (experiments/problems/ex72_rollers.toml): the traction of the component
# Gamma_D leaves free, in eta_3 at the Dirichlet nodes
dir="$cases/ex72_rollers-structured-16"
"$bin" export --problem "$root/experiments/problems/ex72_rollers.toml" --mesh structured:16 --out "$dir" || exit 1
est+=("$dir")
hertz=(--problem "$root/experiments/problems/hertz.toml" --mesh "gmsh:$root/experiments/meshes/hertz.msh")
"$bin" export "${hertz[@]}" --out "$cases/hertz" || exit 1
"$bin" export "${hertz[@]}" --adapt-levels 4 --contact-term tensile-on-full-contact --out "$cases/hertz-adaptive-repaired-4" || exit 1
est+=("$cases/hertz" "$cases/hertz-adaptive-repaired-4")

dir="$cases/ex72-reference"
"$bin" export --problem ex72 --mesh structured:4 --adapt-min-ndof 250000 --theta 0.5 \
    --contact-term without-full-contact --out "$dir" || exit 1
all+=("$dir")

# a .geo of one's own, outside the repository, meshed as the README says (`make mesh GEO=...` runs
# this generate.py) and solved on: the path a reviewer takes with a mesh of their own
own="$cases/own-geo"
mkdir -p "$own" && cp "$root/experiments/meshes/quarter_disc.geo" "$own/disc.geo"
cat > "$own/disc.toml" <<'TOML'
description = "quarter disc pressed down onto y = 0 (cross-check of meshing a .geo of one's own)"
dirichlet = ["0", "-0.01 * y"]   # 0 at (1, 0), where the arc meets the contact part
[material]
E = 1
nu = 0.3
model = "plane_strain"
[parts]
contact = ["bottom"]
dirichlet = ["arc"]
neumann = ["left"]
[contact]
normal = [0, -1]
chi = "0"
TOML
(cd "$own" && "$py" "$root/experiments/meshes/generate.py" disc.geo) || exit 1
"$bin" solve --problem "$own/disc.toml" --mesh "gmsh:$own/disc.msh" || exit 1

# the self-test, the rates and the estimator check beside the comparison (two processes of its
# own): each prints its table when it has ended, in this order
status=0
mkdir -p "$cases/logs"
"$py" "$here/crosscheck.py" --out-dir "$out" selftest "$cases/ex71-structured-8" "$cases/ex72-structured-8" "$cases/fb-structured-8" \
    > "$cases/logs/selftest.txt" 2>&1 &
selftest=$!
"$py" "$here/crosscheck.py" --out-dir "$out" rates "${exact[@]}" > "$cases/logs/rates.txt" 2>&1 &
rates=$!
"$py" "$here/crosscheck.py" --out-dir "$out" estimator "${est[@]}" > "$cases/logs/estimator.txt" 2>&1 &
estimator=$!
"$py" "$here/crosscheck.py" --out-dir "$out" compare "${all[@]}" || status=1
wait "$selftest" || status=1
cat "$cases/logs/selftest.txt"
wait "$rates" || status=1
cat "$cases/logs/rates.txt"
wait "$estimator" || status=1
cat "$cases/logs/estimator.txt"
exit $status
