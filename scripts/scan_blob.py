#!/usr/bin/env python3
"""Writes a scan-like closed blob as OBJ: a geodesic sphere of 20 n^2 triangles (each icosahedron face cut into
n^2), its radius varied by a few smooth lumps and its vertices jittered along and across the surface as a scanner's
noise would, so the triangles are irregular and none line up with a lattice plane.

    scripts/scan_blob.py N_TRIANGLES OUT.obj [--seed S]

N_TRIANGLES is rounded to the nearest 20 n^2 (50k -> n = 50, 200k -> n = 100). Deterministic for a seed.
"""
import argparse
import math
import random
import sys


def icosahedron():
    t = (1.0 + 5.0 ** 0.5) / 2.0
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
         (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6),
         (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10),
         (8, 6, 7), (9, 8, 1)]
    return v, f


def normalize(p):
    n = math.sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2])
    return (p[0] / n, p[1] / n, p[2] / n)


def geodesic(n):
    """Vertices on the unit sphere and triangles: each face split into n^2, shared points merged by key."""
    base_v, base_f = icosahedron()
    base_v = [normalize(p) for p in base_v]
    index = {}
    verts = []
    tris = []

    def vid(a, b, c, i, j):
        # point i/n along a->b and j/n along a->c; keyed on its exact barycentric position over sorted corners
        w = {a: n - i - j, b: i, c: j}
        key = tuple(sorted((k, w[k]) for k in w if w[k] > 0))
        if key not in index:
            p = [0.0, 0.0, 0.0]
            for k, wk in key:
                for d in range(3):
                    p[d] += wk * base_v[k][d] / n
            index[key] = len(verts)
            verts.append(normalize(p))
        return index[key]

    for a, b, c in base_f:
        for i in range(n):
            for j in range(n - i):
                tris.append((vid(a, b, c, i, j), vid(a, b, c, i + 1, j), vid(a, b, c, i, j + 1)))
                if i + j < n - 1:
                    tris.append((vid(a, b, c, i + 1, j), vid(a, b, c, i + 1, j + 1), vid(a, b, c, i, j + 1)))
    return verts, tris


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("triangles", metavar="N_TRIANGLES", type=int, help="about how many triangles (at least 80)")
    ap.add_argument("out", metavar="OUT.obj", help="the OBJ to write (written whole or not at all)")
    ap.add_argument("--seed", type=int, default=1, help="the lumps' and the noise's seed (default 1)")
    args = ap.parse_args()
    if args.triangles < 1:
        ap.error("N_TRIANGLES must be a positive number, not %d" % args.triangles)
    target, out, seed = args.triangles, args.out, args.seed
    rng = random.Random(seed)
    n = max(2, round(math.sqrt(target / 20.0)))
    verts, tris = geodesic(n)
    lumps = [(normalize((rng.gauss(0, 1), rng.gauss(0, 1), rng.gauss(0, 1))), rng.uniform(-0.12, 0.18),
              rng.uniform(0.3, 0.8)) for _ in range(7)]
    edge = 1.1 / n  # mean edge length on the unit sphere
    out_v = []
    for p in verts:
        r = 1.0
        for c, amp, width in lumps:
            d = 1.0 - (p[0] * c[0] + p[1] * c[1] + p[2] * c[2])
            r += amp * math.exp(-d / (width * width))
        r *= 1.0 + 0.004 * rng.gauss(0, 1)  # depth noise
        q = [p[d] * r + 0.25 * edge * rng.uniform(-1, 1) for d in range(3)]  # jitter along the surface
        out_v.append((q[0], q[1] * 0.85, q[2] * 0.75))
    tmp = out + ".tmp"
    with open(tmp, "w") as f:
        f.write("# scan-like blob, %d triangles, seed %d\n" % (len(tris), seed))
        for p in out_v:
            f.write("v %.6f %.6f %.6f\n" % p)
        for t in tris:
            f.write("f %d %d %d\n" % (t[0] + 1, t[1] + 1, t[2] + 1))
    import os
    os.replace(tmp, out)
    print("%s: %d vertices, %d triangles" % (out, len(out_v), len(tris)))


if __name__ == "__main__":
    main()
