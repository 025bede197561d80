"""Helpers of the Python tests: the `phong` binary, and a PNG reader of their own (zlib and
the PNG filters, independent of phong's encoder)."""

import os
import shutil
import struct
import subprocess
import zlib
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[4]
EXAMPLES = ROOT / "examples" / "scenes"
MODELS = ROOT.parent / "shared" / "models"


def phong_bin() -> str:
    """The `phong` command: $PHONG_BIN, else a built one in target/, else on the PATH."""
    env = os.environ.get("PHONG_BIN")
    if env:
        return env
    for p in (ROOT / "target" / "release" / "phong", ROOT / "target" / "debug" / "phong"):
        if p.exists():
            return str(p)
    found = shutil.which("phong")
    if found:
        return found
    pytest.skip("no phong binary: build it with cargo build --release, or set PHONG_BIN")


def run_phong(*args, check=True):
    """Runs the command; returns the completed process."""
    r = subprocess.run([phong_bin(), *map(str, args)], capture_output=True, text=True)
    if check and r.returncode != 0:
        raise AssertionError(f"phong {' '.join(map(str, args))} failed ({r.returncode}): {r.stderr}")
    return r


def read_png(path) -> np.ndarray:
    """An 8-bit RGB or RGBA PNG (not interlaced) as uint8 (H, W, 4) RGBA."""
    data = Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, header = 8, b"", None
    while pos < len(data):
        (n,) = struct.unpack(">I", data[pos : pos + 4])
        kind = data[pos + 4 : pos + 8]
        body = data[pos + 8 : pos + 8 + n]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    w, h, depth, color, _, _, interlace = header
    assert depth == 8 and interlace == 0 and color in (2, 6), header
    ch = 3 if color == 2 else 4
    raw = zlib.decompress(idat)
    stride = w * ch
    out = np.zeros((h, stride), dtype=np.uint8)
    prev = np.zeros(stride, dtype=np.int32)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = np.frombuffer(raw, dtype=np.uint8, count=stride, offset=y * (stride + 1) + 1).astype(np.int32)
        cur = np.zeros(stride, dtype=np.int32)
        if f == 0:
            cur = line
        elif f == 2:
            cur = (line + prev) & 255
        elif f == 1:
            cur = (np.cumsum(line.reshape(w, ch), axis=0) & 255).reshape(stride).astype(np.int32)
        else:
            for x in range(stride):
                a = cur[x - ch] if x >= ch else 0
                b = prev[x]
                c = prev[x - ch] if x >= ch else 0
                if f == 1:
                    p = a
                elif f == 3:
                    p = (a + b) // 2
                else:  # Paeth
                    pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                    p = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                cur[x] = (line[x] + p) & 255
        out[y] = cur
        prev = cur
    img = out.reshape(h, w, ch)
    if ch == 3:
        img = np.concatenate([img, np.full((h, w, 1), 255, np.uint8)], axis=2)
    return img
