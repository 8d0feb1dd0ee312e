#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# One shard of a labelled point-cloud dataset per MPI rank: verdant itself has no MPI; the rank
# and the number of ranks choose the shard. Open MPI sets OMPI_COMM_WORLD_RANK/SIZE, MPICH and
# Intel MPI set PMI_RANK/PMI_SIZE. All ranks write into one shared folder; the last to finish
# writes manifest.json. Run with, e.g.:  mpirun -np 16 bash examples/dataset_mpirun.sh
set -euo pipefail
VERDANT=${VERDANT:-verdant}
OUT=${OUT:-datasets/arabidopsis-10k}
RANK=${OMPI_COMM_WORLD_RANK:-${PMI_RANK:-0}}
SIZE=${OMPI_COMM_WORLD_SIZE:-${PMI_SIZE:-1}}
exec "$VERDANT" dataset data/arabidopsis.lpy --count 10000 --points 100000 --seed 1 \
  --vary ROSETTE_LEAF=0.025:0.045 -o "$OUT" --shard "$RANK/$SIZE" --jobs 1 --no-progress
