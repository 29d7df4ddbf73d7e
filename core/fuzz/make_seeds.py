#!/usr/bin/env python3
"""Writes the hand-made seeds of corpus/solve/ (the byte layout is in
solve_case.hpp). One valid query per family pair class, plus bad poses, so
the fuzzer starts from inputs that reach the solver, not only validation."""
import os
import struct

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus", "solve")
SPECIAL = {"0": 0, "nan": 2, "inf": 3, "1e-300": 5, "1e300": 6, "-1": 7, "1": 12}


def real(v):
    """A sensible value in [0.05, 20] (tag 100 + u16), or a special one by name."""
    if isinstance(v, str):
        return bytes([SPECIAL[v]])
    u = round((v - 0.05) / 19.95 * 65535)
    return bytes([100]) + struct.pack("<H", max(0, min(65535, u)))


def vec(x, y, z):  # vec3() subtracts 10 from each component
    return real(x + 10) + real(y + 10) + real(z + 10)


def sphere(R): return bytes([0]) + real(R)
def se(a, b, c, n): return bytes([1]) + real(a) + real(b) + real(c) + real(n)
def sec(R, h, n): return bytes([2]) + real(R) + real(h) + real(n)
def cone(Rb, Rt, a, b, beta): return bytes([3]) + real(Rb) + real(Rt) + real(a) + real(b) + real(beta)
def box(h, beta): return bytes([5, 0]) + b"".join(real(x) for x in h) + bytes([0]) + real(beta)


def verts(vs, beta):
    return bytes([6, len(vs)]) + b"".join(vec(*v) for v in vs) + real(beta) + real(1.0)


def pose(q=(10.9, 10.1, 10.3, 9.8), p=(1.5, 0.4, -0.7), rmode=1):
    return bytes([rmode]) + b"".join(real(x) for x in q) + bytes([1]) + vec(*p)


TET = [(1, 1, 1), (1, -1, -1), (-1, 1, -1), (-1, -1, 1)]
seeds = {
    "sphere_sphere": sphere(1.0) + sphere(0.5) + pose() + b"\0",
    "se_sec": se(0.5, 1.0, 1.5, 8.0) + sec(1.0, 2.0, 8.0) + pose() + b"\0",
    "cone_box": cone(1.0, 1.5, 1.5, 1.5, 20.0) + box([1, 1, 0.5, 0.5, 2, 2], 10.0) + pose() + b"\0",
    "hull_se": verts(TET, 20.0) + se(1.2, 0.7, 0.9, 2.5) + pose(p=(0.3, 0.2, 0.1)) + b"\0",
    "reflection": sphere(1.0) + sphere(1.0) + bytes([2]) + b"".join(real(x) for x in (10.9, 10.1, 10.3, 9.8)) + bytes([1, 1]) + vec(1, 1, 1) + b"\0",
    "concentric": se(0.5, 1.0, 1.5, 8.0) + cone(1.0, 1.5, 1.5, 1.5, 20.0) + bytes([0, 0]) + b"\0",
    "tiny_r": se(0.5, 1.0, 1.5, 3.0) + sec(1.0, 2.0, 4.0) + bytes([0, 2]) + vec(1, 2, 3) + struct.pack("<H", 20) + b"\0",
    "options": sphere(1.0) + se(1, 2, 3, 2) + pose() + bytes([0x7f]) + b"\x40" * 60,
}
os.makedirs(OUT, exist_ok=True)
for name, data in seeds.items():
    with open(os.path.join(OUT, "seed_" + name), "wb") as f:
        f.write(data)
