#!/usr/bin/env python3
"""Mutated models through the whole command line: every OBJ, MTL, glTF and GLB under 400 KB in
SHARED (../shared/models), and five small PLY and STL files written here, each mutated N times
(truncated, bytes flipped, a line deleted or duplicated, a number replaced by nan, inf, -1, 1e39,
4294967296 and others, bytes inserted, CRLF line ends) and rendered at 64×48 by PHONG. A render
must exit 0 or 2 (an error) within 30 s: anything else (a panic's 101, a signal, a hang) is
printed and its input kept in WORK as badN_NAME.

    fuzz/mutate_models.py PHONG SEED N [SHARED] [WORK]
"""
import os, random, shutil, subprocess, sys, struct
PH = sys.argv[1]
random.seed(int(sys.argv[2]))
N = int(sys.argv[3])
src = sys.argv[4] if len(sys.argv) > 4 else '../shared/models'
scratch = sys.argv[5] if len(sys.argv) > 5 else '/tmp/phong-mutate'
work = os.path.join(scratch, 'models')
shutil.rmtree(work, ignore_errors=True)
shutil.copytree(src, work)
# Synthetic PLY and STL seeds.
def ply_ascii():
    return b"""ply
format ascii 1.0
comment made by fuzz
element vertex 4
property float x
property float y
property float z
property float nx
property float ny
property float nz
property uchar red
property uchar green
property uchar blue
property float s
property float t
element face 2
property list uchar int vertex_indices
end_header
0 0 0 0 0 1 255 0 0 0 0
1 0 0 0 0 1 0 255 0 1 0
1 1 0 0 0 1 0 0 255 1 1
0 1 0 0 0 1 255 255 255 0 1
3 0 1 2
4 0 2 3 0
"""
def ply_bin(be=False):
    e = '>' if be else '<'
    h = ("ply\nformat %s 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 2\nproperty list uchar uint vertex_indices\nend_header\n" % ('binary_big_endian' if be else 'binary_little_endian')).encode()
    v = b''.join(struct.pack(e+'fff', *p) for p in [(0,0,0),(1,0,0),(1,1,0),(0,1,0)])
    f = struct.pack(e+'BIII',3,0,1,2)+struct.pack(e+'BIII',3,0,2,3)
    return h+v+f
def stl_ascii():
    return b"""solid t
facet normal 0 0 1
 outer loop
  vertex 0 0 0
  vertex 1 0 0
  vertex 1 1 0
 endloop
endfacet
facet normal 0 0 1
 outer loop
  vertex 0 0 0
  vertex 1 1 0
  vertex 0 1 0
 endloop
endfacet
endsolid t
"""
def stl_bin():
    h = b'solid but binary'.ljust(80, b' ')
    tris = [((0,0,1),(0,0,0),(1,0,0),(1,1,0)),((0,0,1),(0,0,0),(1,1,0),(0,1,0))]
    body = b''.join(struct.pack('<12fH', *[c for v in t for c in v], 0) for t in tris)
    return h+struct.pack('<I', len(tris))+body
os.makedirs(work+'/synth', exist_ok=True)
for name, data in [('a.ply',ply_ascii()),('le.ply',ply_bin()),('be.ply',ply_bin(True)),('a.stl',stl_ascii()),('b.stl',stl_bin())]:
    open(work+'/synth/'+name,'wb').write(data)
seeds = []
for root, _, files in os.walk(work):
    for f in files:
        p = os.path.join(root, f)
        if f.rsplit('.',1)[-1].lower() in ('obj','gltf','glb','ply','stl','mtl') and os.path.getsize(p) < 400_000:
            seeds.append(p)
def mutate(data):
    k = random.randrange(7)
    if k == 0 and len(data) > 1:
        return data[:random.randrange(len(data))], 'truncate'
    if k == 1:
        b = bytearray(data)
        for _ in range(random.randint(1, 8)):
            if b: b[random.randrange(len(b))] = random.randrange(256)
        return bytes(b), 'flip'
    lines = data.split(b'\n')
    if k == 2 and len(lines) > 2:
        i = random.randrange(len(lines)); del lines[i]; return b'\n'.join(lines), 'delline'
    if k == 3:
        i = random.randrange(len(lines)); lines.insert(random.randrange(len(lines)+1), lines[i]); return b'\n'.join(lines), 'dupline'
    if k == 4:
        import re
        toks = list(re.finditer(rb'-?\d+(\.\d+)?(e-?\d+)?', data))
        if toks:
            m = random.choice(toks)
            rep = random.choice([b'nan', b'inf', b'-1', b'0', b'99999999', b'1e39', b'-2147483649', b'4294967296', b'', b'1.5'])
            return data[:m.start()] + rep + data[m.end():], 'number'
    if k == 5:
        b = bytearray(data)
        i = random.randrange(len(b)+1)
        return bytes(b[:i]) + bytes(random.randrange(256) for _ in range(random.randint(1,16))) + bytes(b[i:]), 'insert'
    return data.replace(b'\n', b'\r\n'), 'crlf'
bad = 0
for s in seeds:
    data = open(s,'rb').read()
    for n in range(N):
        m, how = mutate(data)
        open(s, 'wb').write(m)
        target = s
        if s.endswith('.mtl'):
            # render every obj in the same dir
            objs = [os.path.join(os.path.dirname(s), f) for f in os.listdir(os.path.dirname(s)) if f.endswith('.obj')]
            if not objs: continue
            target = random.choice(objs)
        try:
            r = subprocess.run([PH, 'render', target, '-o', os.path.join(scratch, 'out.png'), '--width', '64', '--height', '48'], capture_output=True, timeout=30)
            rc = r.returncode
            err = r.stderr.decode(errors='replace')
        except subprocess.TimeoutExpired:
            rc, err = 'TIMEOUT', ''
        if rc not in (0, 2):
            bad += 1
            keep = os.path.join(scratch, 'bad%d_%s' % (bad, os.path.basename(s)))
            open(keep, 'wb').write(m)
            print('BAD', rc, how, s, target, '->', keep, err.strip().splitlines()[-3:] if err else '')
            sys.stdout.flush()
        open(s, 'wb').write(data)
print('seeds', len(seeds), 'bad', bad)
