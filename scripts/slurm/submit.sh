#!/bin/bash
# Submit a study to Slurm: an array of shards, then a job that draws the study's figures once
# every shard has finished. Prints the two job ids.
#
#   scripts/slurm/submit.sh [options] MANIFEST
#
# Options (defaults in brackets):
#   --tasks N         array tasks, one shard each [4]
#   --results DIR     results folder the shards share [results]
#   --partition P     Slurm partition [the cluster's default]
#   --time T          time limit per task, Slurm's format [the partition's default]
#   --cpus C          CPUs per task (the solver's threads) [1]
#   --logs DIR        where the jobs' output goes [DIR/slurm-logs, DIR the results folder]
#   --bin PATH        the signorini binary [target/release/signorini, built with make build]
set -euo pipefail
usage="usage: submit.sh [options] MANIFEST (options first; see the comment at the top of $0)"
fail() { echo "submit.sh: $*" >&2; exit 2; }
tasks=4 results=results partition= time= cpus=1 logs= bin=target/release/signorini
# every argument is checked before anything is created or submitted
while [ $# -gt 0 ]; do
    case $1 in
        --tasks|--results|--partition|--time|--cpus|--logs|--bin)
            [ $# -ge 2 ] && [ -n "$2" ] && [ "${2#--}" = "$2" ] || fail "$1 needs a value; $usage"
            case $1 in
                --tasks) tasks=$2 ;;
                --results) results=$2 ;;
                --partition) partition=$2 ;;
                --time) time=$2 ;;
                --cpus) cpus=$2 ;;
                --logs) logs=$2 ;;
                --bin) bin=$2 ;;
            esac
            shift 2 ;;
        --*) fail "unknown option $1; $usage" ;;
        *) [ $# -eq 1 ] || fail "the manifest comes last, after the options (got $1 before: ${*:2}); $usage"
           break ;;
    esac
done
[ $# -eq 1 ] || fail "no manifest given; $usage"
manifest=$1
for n in tasks cpus; do
    [[ ${!n} =~ ^[1-9][0-9]*$ ]] || fail "--$n ${!n}: expected a whole number >= 1"
done
[ -f "$manifest" ] || fail "no manifest $manifest"
[ -x "$bin" ] || fail "no binary $bin (make build)"
# a bare name is the file here (as -x found it), not a command looked up on PATH
case $bin in */*) ;; *) bin=./$bin ;; esac
# the manifest as a run checks it, and the last task's shard must hold a run: a task beyond the
# study's runs would fail, and the finish job (afterok) would then never start
plan=$("$bin" run --plan --shard "$tasks/$tasks" --results "$results" "$manifest" 2>&1 >/dev/null) ||
    fail "--tasks $tasks: $bin run --plan --shard $tasks/$tasks --results $results $manifest refused it: ${plan#error: }"
logs=${logs:-$results/slurm-logs}
mkdir -p "$logs"
here=$(cd "$(dirname "$0")" && pwd)
opts=(--parsable --cpus-per-task="$cpus" --chdir="$PWD")
[ -n "$partition" ] && opts+=(--partition="$partition")
[ -n "$time" ] && opts+=(--time="$time")
array=$(sbatch "${opts[@]}" --array=1-"$tasks" --output="$logs/%x-%A_%a.out" \
    "$here/study.sbatch" "$manifest" "$results" "$tasks" "$bin")
finish=$(sbatch "${opts[@]}" --dependency=afterok:"$array" --output="$logs/%x-%j.out" \
    "$here/finish.sbatch" "$manifest" "$results" "$bin")
echo "array $array ($tasks tasks of $manifest into $results), finish $finish (after all tasks succeed); logs in $logs"
