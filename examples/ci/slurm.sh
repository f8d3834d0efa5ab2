#!/usr/bin/env bash
# A Slurm array job: 7 shards of a thorough mfh audit, then a dependent merge job.
#   sbatch --array=1-7 examples/ci/slurm.sh            # the shards; prints the job id J
#   sbatch --dependency=afterany:J --export=MERGE=1 examples/ci/slurm.sh
# Each array task runs shard $SLURM_ARRAY_TASK_ID of $SHARDS with the same scene, profile and
# seed; the merge writes reports/merged. The scripts are the ones harness/tests/shard_merge.rs
# runs.
#SBATCH --job-name=mfh-audit
#SBATCH --cpus-per-task=8
#SBATCH --time=04:00:00
set -euo pipefail
SHARDS=7
ARGS=(--scene scenes/materials.xml --profile thorough --seed 42)
export RAYON_NUM_THREADS="${SLURM_CPUS_PER_TASK:-1}"
if [ "${MERGE:-0}" = 1 ]; then
    bash examples/ci/merge.sh "$SHARDS" reports
else
    bash examples/ci/shard.sh "$SLURM_ARRAY_TASK_ID" "$SHARDS" reports "${ARGS[@]}" || [ $? -eq 1 ]
fi
