#!/usr/bin/env bash
# `phong batch` over 1, 2 and 4 shards of one thumbnail jobs file on a Slurm cluster
# (.ci/slurm-up starts a one-node one): the wall time of each array from its submission to
# the end of its last task (squeue polled every 0.05 s: `sbatch --wait` polls every 10 s),
# alternating the shard counts over ROUNDS rounds.
#
#   benches/batch/slurm_scaling.sh [RENDERS] [ROUNDS] [PHONG]
set -euo pipefail
renders=${1:-1000}
rounds=${2:-3}
phong=$(realpath "${3:-target/release/phong}")
root=$(cd "$(dirname "$0")/../.." && pwd)
work=$(mktemp -d)
python3 - "$renders" "$work/jobs.jsonl" <<'PY'
import json, sys
from pathlib import Path
sys.path.insert(0, str(Path.cwd() / "benches" / "python"))
from thumbnails import jobs
Path(sys.argv[2]).write_text("".join(json.dumps(j) + "\n" for j in jobs(int(sys.argv[1]))))
PY
for r in $(seq 1 "$rounds"); do
  for n in 1 2 4; do
    out="$work/out-$n-$r"
    t0=$(date +%s.%N)
    id=$(JOBS="$work/jobs.jsonl" OUT="$out" PHONG="$phong" \
      sbatch --parsable --array=0-$((n - 1)) --chdir="$work" --output="$work/log-%A_%a.txt" \
      --export=ALL "$root/examples/batch/slurm.sh")
    while [ -n "$(squeue -h -j "$id" 2>/dev/null)" ]; do sleep 0.05; done
    t1=$(date +%s.%N)
    made=$(find "$out" -name '*.png' | wc -l)
    printf 'round %d shards %d: %.2f s, %d images, %.1f images/s\n' "$r" "$n" "$(echo "$t1 - $t0" | bc)" \
      "$made" "$(echo "$made / ($t1 - $t0)" | bc -l)"
  done
done
rm -rf "$work"
