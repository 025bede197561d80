#!/usr/bin/env bash
# Seeds the fuzz corpora (fuzz/corpus/, not committed) from the example scenes and, where the
# checkout has it, ../shared/models/ (read there, never copied into the repository's files).
set -euo pipefail
cd "$(dirname "$0")"
mkdir -p corpus/scene_toml corpus/obj_mtl corpus/scene_json
for f in ../examples/scenes/*.toml ../benches/scenes/*.toml ../examples/fit/*.toml ../crates/phong-serve/src/default.toml; do
  cp "$f" "corpus/scene_toml/$(echo "$f" | tr '/.' '__')"
done
for f in ../examples/scenes/*.toml ../crates/phong-serve/src/default.toml; do
  python3 -c 'import sys, json, tomllib; print(json.dumps(tomllib.load(open(sys.argv[1], "rb"))))' "$f" \
    > "corpus/scene_json/$(basename "$f" .toml).json"
done
models=../../shared/models
{ ls ../examples/scenes/assets/*.obj; find "$models" -name '*.obj' -size -200k 2>/dev/null || true; } | while IFS= read -r obj; do
  out="corpus/obj_mtl/$(echo "$obj" | md5sum | cut -c1-12)"
  mtl=$(grep -m1 '^mtllib' "$obj" | awk '{print $2}' || true)
  { cat "$obj"; if [ -n "$mtl" ] && [ -f "$(dirname "$obj")/$mtl" ]; then printf '\0'; cat "$(dirname "$obj")/$mtl"; fi; } > "$out"
done
for d in corpus/*; do echo "$d: $(ls "$d" | wc -l) inputs"; done
