#!/usr/bin/env bash
# Seeds the fuzz corpora (fuzz/corpus/, not committed) from the example scenes and, where the
# checkout has it, ../shared/models/ (read there, never copied into the repository's files).
set -euo pipefail
cd "$(dirname "$0")"
mkdir -p corpus/scene_toml corpus/obj_mtl corpus/scene_json corpus/ply_stl corpus/gltf
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
# PLY and STL: a cube in ASCII and binary PLY (both byte orders) and ASCII and binary STL, each
# behind the byte that picks its name (0: .ply, 1: .stl; see fuzz_targets/ply_stl.rs).
python3 - <<'PY'
import struct
V = [(0,0,0),(1,0,0),(1,1,0),(0,1,0),(0,0,1),(1,0,1),(1,1,1),(0,1,1)]
F = [(0,3,2,1),(4,5,6,7),(0,1,5,4),(1,2,6,5),(2,3,7,6),(3,0,4,7)]
head = "ply\nformat {}\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\nelement face 6\nproperty list uchar int vertex_indices\nend_header\n"
ascii = head.format("ascii 1.0") + "".join("%d %d %d\n" % v for v in V) + "".join("4 %d %d %d %d\n" % f for f in F)
open("corpus/ply_stl/cube_ascii_ply", "wb").write(b"\0" + ascii.encode())
for name, fmt, o in [("le", "binary_little_endian 1.0", "<"), ("be", "binary_big_endian 1.0", ">")]:
    b = head.format(fmt).encode() + b"".join(struct.pack(o + "3f", *v) for v in V)
    b += b"".join(struct.pack(o + "B4i", 4, *f) for f in F)
    open("corpus/ply_stl/cube_%s_ply" % name, "wb").write(b"\0" + b)
T = [(V[f[0]], V[f[k]], V[f[k + 1]]) for f in F for k in (1, 2)]
stl = "solid c\n" + "".join("facet normal 0 0 0\nouter loop\n" + "".join("vertex %d %d %d\n" % v for v in t) + "endloop\nendfacet\n" for t in T) + "endsolid c\n"
open("corpus/ply_stl/cube_ascii_stl", "wb").write(b"\1" + stl.encode())
b = b"solid binary".ljust(80) + struct.pack("<I", len(T)) + b"".join(struct.pack("<12fH", 0, 0, 0, *[c for v in t for c in v], 0) for t in T)
open("corpus/ply_stl/cube_binary_stl", "wb").write(b"\1" + b)
PY
for d in corpus/*; do echo "$d: $(ls "$d" | wc -l) inputs"; done
# glTF: the shared samples small enough, behind the byte that picks the name (0: .gltf, 1: .glb).
find "$models" \( -name '*.gltf' -o -name '*.glb' \) -size -100k 2>/dev/null | while IFS= read -r g; do
  case "$g" in *.glb) pick='\001' ;; *) pick='\000' ;; esac
  { printf "$pick"; cat "$g"; } > "corpus/gltf/$(echo "$g" | md5sum | cut -c1-12)"
done
