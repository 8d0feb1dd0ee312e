#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# A Slurm job array making one labelled point-cloud dataset: 10 tasks, each one shard, each
# shard using the task's cores. Every task writes into the same folder (a shared file system);
# the last one to finish writes manifest.json. Submit with:  sbatch examples/dataset_slurm.sh
# Resubmitting after a failure or a time-out makes only the missing items.
#SBATCH --job-name=verdant-dataset
#SBATCH --array=0-9
#SBATCH --cpus-per-task=8
#SBATCH --mem=8G
#SBATCH --time=01:00:00
#SBATCH --output=verdant-dataset-%A_%a.log
set -euo pipefail
VERDANT=${VERDANT:-verdant}
OUT=${OUT:-$HOME/datasets/arabidopsis-10k}
"$VERDANT" dataset data/arabidopsis.lpy --count 10000 --points 100000 --seed 1 \
  --vary ROSETTE_LEAF=0.025:0.045 --format ply -o "$OUT" \
  --shard "${SLURM_ARRAY_TASK_ID}/${SLURM_ARRAY_TASK_COUNT}" --jobs "${SLURM_CPUS_PER_TASK:-1}" --no-progress
