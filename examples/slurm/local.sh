#!/usr/bin/env bash
# The job array without Slurm: N shards as local processes, then the merge. Useful to check a
# config before submitting it (and what tests/it/scale.rs does in-process).
#
#   bash examples/slurm/local.sh configs/quickstart.toml out/quickstart 4
set -euo pipefail
CONFIG=${1:?usage: local.sh CONFIG OUT_PREFIX N}
PREFIX=${2:?usage: local.sh CONFIG OUT_PREFIX N}
N=${3:?usage: local.sh CONFIG OUT_PREFIX N}
POUND=${POUND:-pound}
BACKEND=${BACKEND:-cpu}

mkdir -p "$(dirname "$PREFIX")"
for ((i = 0; i < N; i++)); do
    SLURM_ARRAY_TASK_COUNT=$N SLURM_ARRAY_TASK_ID=$i BACKEND=$BACKEND POUND=$POUND \
        bash "$(dirname "$0")/sweep.sbatch" "$CONFIG" "$PREFIX"
done
bash "$(dirname "$0")/merge.sbatch" "$PREFIX" "$N"
