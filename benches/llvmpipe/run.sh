#!/usr/bin/env bash
# Builds the llvmpipe harness and runs it on the benchmark scenes beside `phong bench`, in the
# same run, printing for each scene the median of RUNS runs of each program (the three
# interleaved, run after run) and the ratio of the medians.
#   benches/llvmpipe/run.sh [WIDTHxHEIGHT] [FRAMES] [THREADS] [RUNS]
# Needs Debian's libosmesa6-dev, libgl-dev and libglu1-mesa-dev (see BENCHMARKS.md).
set -euo pipefail
cd "$(dirname "$0")/../.."
size=${1:-1920x1080}; frames=${2:-10}; threads=${3:-$(nproc)}; runs=${4:-3}
w=${size%x*}; h=${size#*x}
mkdir -p target/llvmpipe
cc -O2 -o target/llvmpipe/harness benches/llvmpipe/harness.c -lOSMesa -lGLU -lGL -lm
cargo build --release -q -p phong-cli
export LP_NUM_THREADS=$threads
# The textured scenes' map for the harness, as a PPM (Python's Pillow converts it).
python3 -c "from PIL import Image; Image.open('benches/scenes/assets/noise_512.png').convert('RGB').save('target/llvmpipe/noise_512.ppm')"
unset TEXTURE
ms() { sed -n 's/.*ms_per_frame=\([0-9.]*\).*/\1/p'; }
median() { sort -n | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }
run() { # name, harness args, scene file[, texture PPM]
  local ours="" ref="" theirs="" i
  for i in $(seq "$runs"); do
    theirs+="$(env ${4:+TEXTURE=$4} target/llvmpipe/harness $2 "$w" "$h" "$frames" | ms)"$'\n'
    ours+="$(target/release/phong bench "benches/scenes/$3.toml" --width "$w" --height "$h" --frames "$frames" --threads "$threads" | ms)"$'\n'
    ref+="$(target/release/phong bench "benches/scenes/$3.toml" --width "$w" --height "$h" --frames "$frames" --threads "$threads" --reference | ms)"$'\n'
  done
  theirs=$(printf '%s' "$theirs" | median); ours=$(printf '%s' "$ours" | median); ref=$(printf '%s' "$ref" | median)
  printf '| %-22s | %8.1f | %8.1f | %8.1f | %5.2fx |\n' "$1" "$ours" "$ref" "$theirs" "$(echo "$theirs / $ours" | bc -l)"
}
echo "| scene | phong fast ms | phong reference ms | llvmpipe ms | fast vs llvmpipe |"
echo "|---|---:|---:|---:|---:|"
run fill_4lights "fill 1 phong 4" fill_4lights
for t in 100k 1m; do
  seg=$([ $t = 100k ] && echo 317 || echo 1000)
  for i in gouraud phong; do
    for n in 1 4; do run "sphere_${t}_${i}_${n}" "sphere $seg $i $n" "sphere_${t}_${i}_${n}"; done
  done
done
run fill_4lights_textured "fill 1 phong 4" fill_4lights_textured target/llvmpipe/noise_512.ppm
run sphere_100k_textured_1 "sphere 317 phong 1" sphere_100k_textured_1 target/llvmpipe/noise_512.ppm
