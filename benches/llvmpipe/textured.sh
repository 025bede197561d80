#!/usr/bin/env bash
# The texture's cost: the textured benchmark scenes and their untextured twins, phong and the
# llvmpipe harness alternating, RUNS rounds; prints each program's median per scene and the
# median over rounds of the textured/untextured ratio (each round's pair run back to back).
#   benches/llvmpipe/textured.sh [RUNS] [THREADS]
# Needs what run.sh needs.
set -euo pipefail
cd "$(dirname "$0")/../.."
runs=${1:-7}; threads=${2:-$(nproc)}
mkdir -p target/llvmpipe
cc -O2 -o target/llvmpipe/harness benches/llvmpipe/harness.c -lOSMesa -lGLU -lGL -lm
cargo build --release -q -p phong-cli
export LP_NUM_THREADS=$threads
python3 -c "from PIL import Image; Image.open('benches/scenes/assets/noise_512.png').convert('RGB').save('target/llvmpipe/noise_512.ppm')"
ms() { sed -n 's/.*ms_per_frame=\([0-9.]*\).*/\1/p'; }
median() { sort -n | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }
phong() { target/release/phong bench "benches/scenes/$1.toml" --frames 10 --threads "$threads" | ms; }
gl() { env ${2:+TEXTURE=$2} target/llvmpipe/harness $1 1920 1080 10 | ms; }
tex=target/llvmpipe/noise_512.ppm
declare -A col
for i in $(seq "$runs"); do
  for pair in "fill_4lights|fill 1 phong 4" "sphere_100k_phong_1|sphere 317 phong 1"; do
    IFS='|' read -r plain args <<< "$pair"
    textured=${plain/phong_1/textured_1}; [ "$plain" = fill_4lights ] && textured=fill_4lights_textured
    a=$(phong "$plain"); b=$(phong "$textured"); c=$(gl "$args"); d=$(gl "$args" "$tex")
    col[$plain.p]+="$a"$'\n'; col[$plain.pt]+="$b"$'\n'; col[$plain.g]+="$c"$'\n'; col[$plain.gt]+="$d"$'\n'
    col[$plain.rp]+="$(echo "$b / $a" | bc -l)"$'\n'; col[$plain.rg]+="$(echo "$d / $c" | bc -l)"$'\n'
  done
done
echo "| scene | phong ms | phong textured ms | ratio | llvmpipe ms | llvmpipe textured ms | ratio |"
echo "|---|---:|---:|---:|---:|---:|---:|"
for plain in fill_4lights sphere_100k_phong_1; do
  m() { printf '%s' "${col[$plain.$1]}" | median; }
  printf '| %s | %.1f | %.1f | %.2fx | %.1f | %.1f | %.2fx |\n' "$plain" "$(m p)" "$(m pt)" "$(m rp)" "$(m g)" "$(m gt)" "$(m rg)"
done
