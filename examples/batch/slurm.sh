#!/usr/bin/env bash
# A Slurm job array over `phong batch`: each array task renders its shard of JOBS into OUT
# (`phong batch` reads SLURM_ARRAY_TASK_ID and SLURM_ARRAY_TASK_COUNT itself).
#
#   sbatch --array=0-15 examples/batch/slurm.sh                 # 16 shards
#   JOBS=thumbs.jsonl OUT=thumbs sbatch --array=0-99 examples/batch/slurm.sh
#
# After a failure or a preemption, submit the same command again: complete images are
# skipped. Each task's outcome is in OUT/results-I-of-N.jsonl.
#SBATCH --job-name=phong-batch
#SBATCH --cpus-per-task=1
#SBATCH --output=phong-batch-%A_%a.log
set -euo pipefail
JOBS=${JOBS:-jobs.jsonl}
OUT=${OUT:-renders}
PHONG=${PHONG:-phong}
exec "$PHONG" batch "$JOBS" --out "$OUT" --threads "${SLURM_CPUS_PER_TASK:-1}"
