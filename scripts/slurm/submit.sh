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
tasks=4 results=results partition= time= cpus=1 logs= bin=target/release/signorini
while [ $# -gt 1 ]; do
    case $1 in
        --tasks) tasks=$2 ;;
        --results) results=$2 ;;
        --partition) partition=$2 ;;
        --time) time=$2 ;;
        --cpus) cpus=$2 ;;
        --logs) logs=$2 ;;
        --bin) bin=$2 ;;
        *) echo "submit.sh: unknown option $1 (see the comment at the top of $0)" >&2; exit 2 ;;
    esac
    shift 2
done
manifest=${1:?usage: submit.sh [options] MANIFEST}
[ -f "$manifest" ] || { echo "submit.sh: no manifest $manifest" >&2; exit 2; }
[ -x "$bin" ] || { echo "submit.sh: no binary $bin (make build)" >&2; exit 2; }
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
