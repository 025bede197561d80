#!/usr/bin/env bash
# The textured 100k-triangle model at 1080p: Spot subdivided to 93,696 triangles
# (spot_100k.py), rendered as `phong render MODEL` renders a model (its material, three lights,
# 4 samples a pixel), with its texture and without (spot_100k_plain.obj), alternating. Prints
# each round's ms per frame and ratio, then the medians. With ONE=1, the scenes of the sphere
# benchmark's form instead (spot_100k_1.toml: one light, one sample a pixel).
#   [ONE=1] benches/models/spot_100k.sh ROUNDS THREADS PHONG [SHARED_MODELS]
set -euo pipefail
cd "$(dirname "$0")/../.."
rounds=$1; threads=$2; phong=$3; shared=${4:-../shared/models}
out=target/bench-models
python3 benches/models/spot_100k.py "$shared/spot" "$out" >&2
if [ "${ONE:-0}" = 1 ]; then input() { echo "$out/$1_1.toml"; }; else input() { echo "$out/$1.obj"; }; fi
ms() { "$phong" bench "$(input "$1")" --width 1920 --height 1080 --frames 10 --threads "$threads" |
  sed -n 's/.*ms_per_frame=\([0-9.]*\).*/\1/p'; }
echo "untextured | textured | ratio"
for _ in $(seq "$rounds"); do
  u=$(ms spot_100k_plain); t=$(ms spot_100k)
  printf '%s | %s | %.3f\n' "$u" "$t" "$(echo "$t / $u" | bc -l)"
done | tee /dev/stderr | python3 -c '
import statistics, sys
rows = [[float(x) for x in l.split("|")] for l in sys.stdin]
u, t, r = (statistics.median(c) for c in zip(*rows))
q = sorted(x[2] for x in rows)
print(f"{len(rows)} rounds: medians untextured {u:.2f} ms, textured {t:.2f} ms, ratio {r:.3f} (10th-90th percentile {q[len(q) // 10]:.3f}-{q[len(q) * 9 // 10]:.3f})")
'
