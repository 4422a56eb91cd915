#!/bin/bash
# One sweep split over a SLURM job array: task K of N computes the points with index % N == K
# and writes sweep-shard-K-of-N.{json,csv,md,tex} into the shared directory; a dependent job
# merges them (refusing shards of another spec, conflicting or missing points).
#
#   sbatch examples/sweeps/slurm-array.sh
#   sbatch --dependency=afterok:<array job id> --wrap \
#       "moreau merge out/amplitude-200/shards --out out/amplitude-200"
#
# A task that is killed (time limit, pre-emption) resumes where it stopped when resubmitted:
# finished points are in out/.../.sweep-shard-K-of-N.checkpoint.jsonl.
#SBATCH --job-name=moreau-sweep
#SBATCH --array=0-15
#SBATCH --cpus-per-task=2
#SBATCH --time=00:30:00
#SBATCH --output=slurm-%A_%a.out
set -euo pipefail
N=${SLURM_ARRAY_TASK_COUNT:-16}
moreau sweep examples/sweeps/amplitude-200.toml \
    --out out/amplitude-200/shards \
    --shard "${SLURM_ARRAY_TASK_ID}/${N}" \
    --threads "${SLURM_CPUS_PER_TASK:-2}" --quiet
