#!/usr/bin/env bash
# Two builds of phong alternating on the textured 100k sphere and its untextured twin: each
# round runs A's untextured and textured frames, then B's, and prints the four ms per frame
# and the ratios A textured/untextured, B textured/untextured and B/A textured.
#   benches/textured_ab.sh ROUNDS THREADS PHONG_A PHONG_B
set -euo pipefail
cd "$(dirname "$0")/.."
rounds=$1; threads=$2; a=$3; b=$4
ms() { "$1" bench "benches/scenes/$2.toml" --frames 10 --threads "$threads" | sed -n 's/.*ms_per_frame=\([0-9.]*\).*/\1/p'; }
echo "A untextured | A textured | B untextured | B textured | A ratio | B ratio | B/A textured"
for _ in $(seq "$rounds"); do
  au=$(ms "$a" sphere_100k_phong_1); at=$(ms "$a" sphere_100k_textured_1)
  bu=$(ms "$b" sphere_100k_phong_1); bt=$(ms "$b" sphere_100k_textured_1)
  printf '%s | %s | %s | %s | %.3f | %.3f | %.3f\n' "$au" "$at" "$bu" "$bt" \
    "$(echo "$at / $au" | bc -l)" "$(echo "$bt / $bu" | bc -l)" "$(echo "$bt / $at" | bc -l)"
done
