#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Writes the seed and regression inputs of tests/fuzz/corpus/ (run from the repository root).
The query inputs follow the byte reader of fuzz_query.c (fuzz_common.h): each value is encoded
as a raw big-endian double (selector 192) or an int (selector 0 + 4 bytes), so the seeds say
exactly which finding of issue 11 they replay."""
import os, random, struct

OUT = "tests/fuzz/corpus"

def u8(v): return bytes([v & 255])
def u32(v): return struct.pack(">I", v & 0xFFFFFFFF)
def dbl(x): return u8(192) + struct.pack(">d", x)
def vec(x, y, z): return dbl(x) + dbl(y) + dbl(z)
def fint(v, lo): return u8(0) + u32(v - lo)  # fz_int(lo, hi): lo + u32 % range

def motion(pos=None, quat=(1, 0, 0, 0), center=(0, 0, 0), v=(0, 0, 0), w=(0, 0, 0)):
    b = u8(1 if pos is not None else 0)
    if pos is not None: b += vec(*pos) + dbl(quat[0]) + dbl(quat[1]) + dbl(quat[2]) + dbl(quat[3])
    return b + vec(*center) + vec(*v) + vec(*w)

def params(method=0, budget=None):  # budget None: the default (mask bit 32)
    b = u8(32 if budget is None else 0) + u8(method)
    if budget is not None: b += u8(24) + u32(budget)
    return b

def query(sdf, method=0, entry=0, sm=None, bm=None, t0=0.0, t1=1.0, tri=((0, 0, 0.5), (0.1, 0, 0.5), (0, 0.1, 0.5)),
          budget=None, capacity=8):
    b = sdf + params(method, budget) + u8(entry) + u8(1 if sm is not None else 0)
    b += sm if sm is not None else motion()
    b += bm if bm is not None else motion(v=(0, 0, -1))
    b += dbl(t0) + dbl(t1)
    for p in tri: b += vec(*p)
    for p in tri: b += vec(p[0], p[1], p[2] - 1.0)  # linear end
    for i in range(12): b += dbl([0, 0, 0.5, 0.3, 0, 0.5, 0, 0.3, 0.5, 0, 0, 0.8][i])
    for i in range(12): b += dbl([0, 0, -0.5, 0.3, 0, -0.5, 0, 0.3, -0.5, 0, 0, -0.2][i])
    return b + u8(capacity)

def analytic(kind, *vals):  # make_sdf case 0, then make_analytic's kind and values
    return u8(0) + u8(kind) + b"".join(dbl(v) for v in vals)

SPHERE = analytic(0, 0.3)
TORUS = analytic(3, 0.5, 0.2)
CYLINDER = analytic(5, 0.5, 0.3)

def write(target, name, data):
    os.makedirs(os.path.join(OUT, target), exist_ok=True)
    with open(os.path.join(OUT, target, name), "wb") as f: f.write(data)

# ---- fuzz_query: seeds (every SDF kind and entry point) and the findings ----
for e in range(4):
    for m in range(4):
        write("fuzz_query", f"seed-sphere-entry{e}-method{m}", query(SPHERE, method=m, entry=e))
write("fuzz_query", "seed-csg", u8(1) + u8(0) + u8(0) + dbl(0.3) + u8(1) + vec(0.2, 0.2, 0.2) + params() + query(b"")[0:0]
      + u8(0) + u8(0) + motion() + motion(v=(0, 0, -1)) + dbl(0) + dbl(1) + vec(0, 0, .5) + vec(.1, 0, .5) + vec(0, .1, .5)
      + vec(0, 0, -.5) + vec(.1, 0, -.5) + vec(0, .1, -.5) + b"".join(dbl(0.1 * i) for i in range(24)) + u8(4))
write("fuzz_query", "seed-transformed-grid", u8(2) + u8(1) + vec(0.1, 0, 0) + dbl(1) + dbl(0) + dbl(0) + dbl(0) + dbl(1.5)
      + query(b"")[0:0] + params() + u8(0) + u8(0) + motion() + motion(v=(0, 0, -1), w=(0, 3, 0)) + dbl(0) + dbl(1)
      + vec(0, 0, .5) + vec(.1, 0, .5) + vec(0, .1, .5) + vec(0, 0, -.5) + vec(.1, 0, -.5) + vec(0, .1, -.5)
      + b"".join(dbl(0.1 * i) for i in range(24)) + u8(4))
write("fuzz_query", "seed-callback", u8(3) + dbl(0.3) + dbl(0.05) + dbl(10) + params(3) + u8(2) + u8(0) + motion()
      + motion(v=(0, 0, -1)) + dbl(0) + dbl(1) + vec(0, 0, .5) + vec(.1, 0, .5) + vec(0, .1, .5) + vec(0, 0, -.5)
      + vec(.1, 0, -.5) + vec(0, .1, -.5) + b"".join(dbl(0.1 * i) for i in range(24)) + u8(4))
write("fuzz_query", "seed-grid", u8(4) + params(0) + u8(2) + u8(1) + motion(w=(0, 0, 2)) + motion(v=(0, 0, -1), w=(1, 0, 0))
      + dbl(0) + dbl(1) + vec(0, 0, .5) + vec(.1, 0, .5) + vec(0, .1, .5) + vec(0, 0, -.5) + vec(.1, 0, -.5) + vec(0, .1, -.5)
      + b"".join(dbl(0.1 * i) for i in range(24)) + u8(4))
# finding: 1e90 rad/s (14.8 s FWGSS, > 600 s CERTIFIED); and the same spin at the 1e6 rad limit with the default budget
for m in (0, 3):
    write("fuzz_query", f"finding-spin-1e90-method{m}", query(SPHERE, method=m, bm=motion(v=(0, 0, -1), w=(0, 0, 1e90))))
    write("fuzz_query", f"finding-spin-1e6-method{m}", query(SPHERE, method=m, bm=motion(v=(0, 0, -1), w=(0, 0, 0.99e6))))
# finding: |w| ~ 1e154 overflows the rotation vector (NaN poses; CSG let a NaN point touch)
csg = u8(1) + u8(0) + u8(0) + dbl(0.3) + u8(1) + vec(0.2, 0.2, 0.2)
write("fuzz_query", "finding-w-1e154-csg", query(csg, bm=motion(v=(0, 0, -1), w=(1e154, 1e154, 0)), t1=1e-160))
# finding: t0 = -1e308, t1 = 1e308 (t1 - t0 = inf)
write("fuzz_query", "finding-interval-overflow", query(SPHERE, t0=-1e308, t1=1e308))
# finding: torus / cylinder at |p| ~ 1.3e154 (sqrt(x^2 + y^2) overflowed)
far = ((1.3e154, 1.3e154, 0), (1.3e154, 1.3e154, 1), (1.3e154, 1.3e154 + 1, 0))
write("fuzz_query", "finding-torus-far", query(TORUS, tri=far))
write("fuzz_query", "finding-cylinder-far", query(CYLINDER, tri=far))
far2 = ((1e149, 1e149, 0), (1e149, 1e149, 1), (1e149, 1e149 + 1e135, 0))
write("fuzz_query", "finding-torus-1e149", query(TORUS, tri=far2))
# finding: a transformed SDF with scale 1e-200 (NaN at every point)
write("fuzz_query", "finding-transform-scale-1e-200", u8(2) + u8(0) + u8(0) + dbl(0.3) + vec(0, 0, 0) + dbl(1) + dbl(0) + dbl(0)
      + dbl(0) + dbl(1e-200) + params() + u8(0) + u8(0) + motion() + motion(v=(0, 0, -1)) + dbl(0) + dbl(1)
      + vec(0, 0, .5) + vec(.1, 0, .5) + vec(0, .1, .5) + vec(0, 0, -.5) + vec(.1, 0, -.5) + vec(0, .1, -.5)
      + b"".join(dbl(0.1 * i) for i in range(24)) + u8(4))
random.seed(11)
for i in range(8):
    write("fuzz_query", f"seed-random-{i}", bytes(random.randrange(256) for _ in range(600)))

# ---- fuzz_cdf: a real file and the findings ----
box = open("data/sdf/upstream/box.cdf", "rb").read()
write("fuzz_cdf", "seed-box.cdf", box)
res = struct.unpack("<3I", box[48:60])
b = bytearray(box)
for i in range(3):
    lo, hi = -1e308, 1e308
    h = hi / res[i] * 2.0
    struct.pack_into("<d", b, 8 * i, lo); struct.pack_into("<d", b, 24 + 8 * i, hi)
    struct.pack_into("<d", b, 60 + 8 * i, h); struct.pack_into("<d", b, 84 + 8 * i, 1.0 / h)
write("fuzz_cdf", "finding-domain-1e308.cdf", bytes(b))
b = bytearray(box); struct.pack_into("<d", b, 140, 1e154)
write("fuzz_cdf", "finding-node-1e154.cdf", bytes(b))
e = bytearray(box[:124])
struct.pack_into("<3I", e, 48, 1, 1, 1)
for i in range(3):
    lo, hi = struct.unpack_from("<d", e, 8 * i)[0], struct.unpack_from("<d", e, 24 + 8 * i)[0]
    struct.pack_into("<d", e, 60 + 8 * i, hi - lo); struct.pack_into("<d", e, 84 + 8 * i, 1.0 / (hi - lo))
struct.pack_into("<QQ", e, 108, 1, 1)
e += struct.pack("<QQQQQQI", 1, 0, 1, 0, 1, 1, 0xFFFFFFFF)
write("fuzz_cdf", "finding-empty-node-array.cdf", bytes(e))

# ---- fuzz_cases ----
write("fuzz_cases", "seed-example.cases", open("data/cases/example.cases", "rb").read())
write("fuzz_cases", "finding-spin-1e90.cases", b"sdfccd-cases 1\nsdf ball sphere 0.2\nmesh tri triangle -0.05 0 0 0.05 0 0 0 0.08 0\n"
      b"case spin ball tri 0.016667 0 0 0.3 1 0 0 0 0 0 -1 0 0 1e90\n")
write("fuzz_cases", "finding-directory.cases", b"sdfccd-cases 1\nsdf g grid /tmp\nmesh m file /tmp\n")

# ---- fuzz_mesh: the first byte picks obj (< 200), stl (< 228) or off ----
write("fuzz_mesh", "seed-pyramid.obj", b"\x00" + open("data/meshes/pyramid.obj", "rb").read())
write("fuzz_mesh", "seed-quad.obj", b"\x03v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nf -1 -2 -3\n")
write("fuzz_mesh", "seed-tri.stl", b"\xc8solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
      b"endloop\nendfacet\nendsolid t\n")
write("fuzz_mesh", "seed-tet.off", b"\xe4OFF\n4 4 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n")
