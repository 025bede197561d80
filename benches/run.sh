#!/usr/bin/env bash
# Runs `phong bench` on every benchmark scene and prints one line each.
#   benches/run.sh [BACKEND] [WIDTHxHEIGHT] [FRAMES] [extra phong bench flags...]
# e.g. benches/run.sh cpu 1920x1080 10      benches/run.sh gpu 3840x2160 5
set -euo pipefail
cd "$(dirname "$0")/.."
backend=${1:-cpu}; size=${2:-1920x1080}; frames=${3:-10}; shift $(( $# < 3 ? $# : 3 ))
w=${size%x*}; h=${size#*x}
cargo build --release -q -p phong-cli
for s in benches/scenes/*.toml; do
  printf '%-28s ' "$(basename "$s" .toml)"
  ./target/release/phong bench "$s" --backend "$backend" --width "$w" --height "$h" --frames "$frames" "$@" 2>/dev/null
done
