#!/usr/bin/env bash
# phong serve's benchmarks (BENCHMARKS.md, "phong serve"): the browser latency while dragging
# the Shininess slider, alternating half-size and full-size previews, RUNS times; then the
# 20-client load on the API. Needs chromium and chromium-driver.
#   benches/serve/run.sh [RUNS]
set -euo pipefail
cd "$(dirname "$0")/../.."
runs=${1:-3}
cargo build --release -q
for i in $(seq "$runs"); do
  for q in "" "&preview=full"; do
    PHONG_BENCH_QUERY="$q" PHONG_BENCH_MOVES=200 cargo test --release -q -p phong-cli --test browser \
      bench_slider_latency -- --ignored --nocapture 2>/dev/null | grep -E "latency|median"
  done
done
./target/release/phong serve --port 8099 --threads 2 >/dev/null 2>&1 &
pid=$!
trap 'kill $pid 2>/dev/null' EXIT
sleep 1
python3 benches/serve/load.py --clients 20 --seconds 20 --pid "$pid"
python3 benches/serve/load.py --clients 20 --seconds 20 --format png --pid "$pid"
grep VmHWM "/proc/$pid/status"
