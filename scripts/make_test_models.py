#!/usr/bin/env python3
"""Writes models of the kinds users bring, each in a format variant exporters write, for
scripts/check_scene_models.sh:

  scan_blob.off      a scan: a lumpy closed blob with noise on every vertex, about 10^4 triangles; comment lines
                     before the keyword, a blank line after the counts, comments among the vertices (as scanners
                     and mesh tools export OFF)
  bowl_shell.stl     a thin shell: a hemispherical bowl 1.5 mm thick, 100 mm across, binary STL whose 80-byte
                     header begins with "solid"
  plate.ply          a flat CAD plate 100 x 5 x 60 mm lying on its edge in the file (thin along y), ASCII PLY with
                     normals and a colour per vertex
  bracket.ply        a CAD part with sharp edges: an L-bracket of concave polygon faces, binary big-endian PLY with
                     ushort list counts and int indices
  scan_inward.stl    a scan exported inside out: a lumpy blob of about 5 x 10^3 triangles, every face wound inward
                     (ASCII STL, facet normals pointing in)
  bracket_patch.obj  the L-bracket with two of its faces (an L side and the top of its foot) wound against the others, OBJ

With --big also scan_1e5.ply (binary little-endian, 10^5 triangles) and scan_1e6.stl (binary, 10^6 triangles).

With --hands, the shapes that test a hand's feel (`palpate bench feel --hands`), each closed, instead:

  coarse_ball.off    an icosahedron split once (80 faces): a coarse model felt through its facets
  star_prism.stl     a six-pointed star 20 mm thick: sharp convex ridges and concave creases, as a CAD part has
  fin.ply            a T profile 80 mm long: a 2 mm fin 40 mm tall on a base, thin part and concave corners
  comb.obj           a palm with four 3 mm fingers 3 mm apart, 8 mm thick: thin parts and narrow slots (a hand)
  torus.off          a ring 70 mm across, tube 24 mm: convex outside, saddle inside
  dense_blob.ply     the scan blob at 5 x 10^4 triangles: a patch that covers little of a sphere tool's way

Usage: scripts/make_test_models.py OUT_DIR [--big | --hands]
"""
import argparse
import math
import os
import random
import struct
import sys


def blob(n_lat, n_lon, seed, noise):
    """A closed lumpy blob (radius about 50) as a latitude-longitude grid: vertices and outward triangles."""
    rnd = random.Random(seed)
    verts = [(0.0, 0.0, 40.0)]
    for i in range(1, n_lat):
        th = math.pi * i / n_lat
        for j in range(n_lon):
            ph = 2 * math.pi * j / n_lon
            r = 50.0 * (1 + 0.12 * math.sin(3 * th) * math.cos(2 * ph) + 0.06 * math.sin(5 * ph)) + rnd.gauss(0, noise)
            verts.append((r * math.sin(th) * math.cos(ph), 0.8 * r * math.sin(th) * math.sin(ph), 0.8 * r * math.cos(th)))
    verts.append((0.0, 0.0, -40.0))
    top, bottom = 0, len(verts) - 1
    ring = lambda i, j: 1 + (i - 1) * n_lon + (j % n_lon)
    tris = []
    for j in range(n_lon):
        tris.append((top, ring(1, j), ring(1, j + 1)))
        tris.append((bottom, ring(n_lat - 1, j + 1), ring(n_lat - 1, j)))
    for i in range(1, n_lat - 1):
        for j in range(n_lon):
            a, b, c, d = ring(i, j), ring(i, j + 1), ring(i + 1, j), ring(i + 1, j + 1)
            tris.append((a, c, d))
            tris.append((a, d, b))
    return verts, tris


def write_off_exported(path, verts, tris):
    with open(path, "w") as f:
        for k in range(3):
            f.write("# exported scan, header comment %d\n" % k)
        f.write("OFF\n%d %d 0\n\n" % (len(verts), len(tris)))
        for k, v in enumerate(verts):
            if k == len(verts) // 2:
                f.write("# second half of the vertices\n")
            f.write("%.6f %.6f %.6f\n" % v)
        f.write("\n")
        for t in tris:
            f.write("3 %d %d %d\n" % t)


def write_stl_binary(path, verts, tris, header):
    with open(path, "wb") as f:
        f.write(header.encode().ljust(80, b" ")[:80])
        f.write(struct.pack("<I", len(tris)))
        for t in tris:
            f.write(struct.pack("<3f", 0, 0, 0))
            for i in t:
                f.write(struct.pack("<3f", *verts[i]))
            f.write(b"\0\0")


def write_ply_binary(path, verts, polys, big):
    e = ">" if big else "<"
    with open(path, "wb") as f:
        f.write(("ply\nformat %s 1.0\ncomment made by make_test_models.py\nelement vertex %d\n"
                 "property float x\nproperty float y\nproperty float z\nproperty uchar quality\n"
                 "element face %d\nproperty list ushort int vertex_indices\nend_header\n"
                 % ("binary_big_endian" if big else "binary_little_endian", len(verts), len(polys))).encode())
        for v in verts:
            f.write(struct.pack(e + "3fB", v[0], v[1], v[2], 7))
        for p in polys:
            f.write(struct.pack(e + "H%di" % len(p), len(p), *p))


def bowl(n_lat, n_lon, radius, thickness):
    """A closed hemispherical shell: outer and inner surfaces joined at the rim (z = 0), opening up."""
    verts, tris = [], []
    def surf(r, flip):
        base = len(verts)
        verts.append((0.0, 0.0, -r))
        for i in range(1, n_lat + 1):
            th = 0.5 * math.pi * i / n_lat
            for j in range(n_lon):
                ph = 2 * math.pi * j / n_lon
                verts.append((r * math.sin(th) * math.cos(ph), r * math.sin(th) * math.sin(ph), -r * math.cos(th)))
        ring = lambda i, j: base + 1 + (i - 1) * n_lon + (j % n_lon)
        out = []
        for j in range(n_lon):
            out.append((base, ring(1, j + 1), ring(1, j)))
        for i in range(1, n_lat):
            for j in range(n_lon):
                a, b, c, d = ring(i, j), ring(i, j + 1), ring(i + 1, j), ring(i + 1, j + 1)
                out += [(a, b, d), (a, d, c)]
        tris.extend([(t[0], t[2], t[1]) for t in out] if flip else out)
        return ring
    outer = surf(radius, False)
    inner = surf(radius - thickness, True)
    for j in range(n_lon):
        a, b, c, d = outer(n_lat, j), outer(n_lat, j + 1), inner(n_lat, j), inner(n_lat, j + 1)
        tris += [(a, d, c), (a, b, d)]
    return verts, tris


def plate_ascii_ply(path, sx, sy, sz, n):
    """A box sx x sy x sz centred at the origin, each face split n x n, as ASCII PLY quads with normals."""
    verts, quads = [], []
    for axis in range(3):
        u, w = (axis + 1) % 3, (axis + 2) % 3
        size = (sx, sy, sz)
        for side in (-1, 1):
            base = len(verts)
            for b in range(n + 1):
                for a in range(n + 1):
                    p = [0.0, 0.0, 0.0]
                    p[axis] = side * size[axis] / 2
                    p[u] = size[u] * (a / n - 0.5)
                    p[w] = size[w] * (b / n - 0.5)
                    nrm = [0, 0, 0]
                    nrm[axis] = side
                    verts.append((p, nrm))
            for b in range(n):
                for a in range(n):
                    q = [base + b * (n + 1) + a, base + b * (n + 1) + a + 1, base + (b + 1) * (n + 1) + a + 1,
                         base + (b + 1) * (n + 1) + a]
                    quads.append(q if side > 0 else q[::-1])
    with open(path, "w") as f:
        f.write("ply\nformat ascii 1.0\ncomment CAD plate %g x %g x %g mm\nelement vertex %d\n"
                "property float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\n"
                "property float nz\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
                "element face %d\nproperty list uchar int vertex_indices\nend_header\n" % (sx, sy, sz, len(verts), len(quads)))
        for p, nrm in verts:
            f.write("%g %g %g %d %d %d 200 200 210\n" % (p[0], p[1], p[2], nrm[0], nrm[1], nrm[2]))
        for q in quads:
            f.write("4 %d %d %d %d\n" % tuple(q))


def write_stl_ascii(path, verts, tris):
    with open(path, "w") as f:
        f.write("solid scan_inward\n")
        for t in tris:
            a, b, c = (verts[i] for i in t)
            u = [b[k] - a[k] for k in range(3)]
            w = [c[k] - a[k] for k in range(3)]
            n = (u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0])
            f.write("facet normal %g %g %g\n outer loop\n" % n)
            for v in (a, b, c):
                f.write("  vertex %.6f %.6f %.6f\n" % v)
            f.write(" endloop\nendfacet\n")
        f.write("endsolid scan_inward\n")


def write_obj(path, verts, polys):
    with open(path, "w") as f:
        f.write("# made by make_test_models.py\n")
        for v in verts:
            f.write("v %g %g %g\n" % v)
        for p in polys:
            f.write("f " + " ".join(str(i + 1) for i in p) + "\n")


def bracket():
    """An L-bracket 80 x 60 x 40 mm, 8 mm thick: two concave L faces and six rectangles (sharp 90-degree edges)."""
    L = [(0, 0), (80, 0), (80, 8), (8, 8), (8, 60), (0, 60)]  # in x-z, counter-clockwise seen from -y
    verts = [(x, 0.0, z) for x, z in L] + [(x, 40.0, z) for x, z in L]
    n = len(L)
    polys = [list(range(n)), [n + i for i in reversed(range(n))]]
    for i in range(n):
        j = (i + 1) % n
        polys.append([i, n + i, n + j, j])
    return verts, polys


def icosphere(radius, splits):
    """An icosahedron split `splits` times, pushed out to the sphere: vertices and outward triangles."""
    t = (1 + 5 ** 0.5) / 2
    verts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
             (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    tris = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6),
            (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10),
            (8, 6, 7), (9, 8, 1)]
    for _ in range(splits):
        mid, out = {}, []
        def m(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                verts.append(tuple((verts[a][k] + verts[b][k]) / 2 for k in range(3)))
                mid[key] = len(verts) - 1
            return mid[key]
        for a, b, c in tris:
            ab, bc, ca = m(a, b), m(b, c), m(c, a)
            out += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        tris = out
    verts = [tuple(radius * x / math.sqrt(sum(y * y for y in v)) for x in v) for v in verts]
    return verts, tris


def ear_clip(poly):
    """Triangles of a simple counter-clockwise polygon (list of (x, y)), by ear clipping."""
    idx = list(range(len(poly)))
    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    def inside(p, a, b, c):
        return cross(a, b, p) >= 0 and cross(b, c, p) >= 0 and cross(c, a, p) >= 0
    tris = []
    while len(idx) > 3:
        for k in range(len(idx)):
            i, j, l = idx[k - 1], idx[k], idx[(k + 1) % len(idx)]
            a, b, c = poly[i], poly[j], poly[l]
            if cross(a, b, c) <= 0:
                continue
            if any(inside(poly[q], a, b, c) for q in idx if q not in (i, j, l)):
                continue
            tris.append((i, j, l))
            idx.pop(k)
            break
        else:
            raise ValueError("not a simple counter-clockwise polygon")
    tris.append(tuple(idx))
    return tris


def extrude(poly, depth):
    """The counter-clockwise polygon (x, z) swept along y over [0, depth]: a closed prism, outward triangles."""
    n = len(poly)
    verts = [(x, 0.0, z) for x, z in poly] + [(x, depth, z) for x, z in poly]
    caps = ear_clip(poly)
    # the polygon is counter-clockwise seen from -y (x right, z up): the y = 0 cap faces -y as listed
    tris = [(a, b, c) for a, b, c in caps] + [(a + n, c + n, b + n) for a, b, c in caps]
    for i in range(n):
        j = (i + 1) % n
        tris += [(i, i + n, j + n), (i, j + n, j)]
    return verts, tris


def torus(big_r, r, n_u, n_v):
    verts = []
    for i in range(n_u):
        u = 2 * math.pi * i / n_u
        for j in range(n_v):
            v = 2 * math.pi * j / n_v
            verts.append(((big_r + r * math.cos(v)) * math.cos(u), (big_r + r * math.cos(v)) * math.sin(u), r * math.sin(v)))
    tris = []
    for i in range(n_u):
        for j in range(n_v):
            a, b = i * n_v + j, ((i + 1) % n_u) * n_v + j
            c, d = i * n_v + (j + 1) % n_v, ((i + 1) % n_u) * n_v + (j + 1) % n_v
            tris += [(a, b, d), (a, d, c)]
    return verts, tris


def hand_shapes(out):
    v, t = icosphere(50.0, 1)
    write_off_exported(os.path.join(out, "coarse_ball.off"), v, t)
    star = []
    for k in range(12):
        a = math.pi * k / 6
        rr = 50.0 if k % 2 == 0 else 22.0
        star.append((rr * math.cos(a), rr * math.sin(a)))
    v, t = extrude(star, 20.0)
    write_stl_ascii(os.path.join(out, "star_prism.stl"), v, t)
    tee = [(-20, 0), (20, 0), (20, 10), (1, 10), (1, 50), (-1, 50), (-1, 10), (-20, 10)]
    v, t = extrude(tee, 80.0)
    write_ply_binary(os.path.join(out, "fin.ply"), v, t, big=False)
    comb = [(-25, 0), (25, 0), (25, 80), (22, 80), (22, 40), (19, 40), (19, 80), (16, 80), (16, 40), (13, 40),
            (13, 80), (10, 80), (10, 40), (7, 40), (7, 80), (4, 80), (4, 40), (-25, 40)]
    v, t = extrude(comb, 8.0)
    write_obj(os.path.join(out, "comb.obj"), v, t)
    v, t = torus(35.0, 12.0, 48, 24)
    write_off_exported(os.path.join(out, "torus.off"), v, t)
    v, t = blob(160, 158, 5, 0.3)
    write_ply_binary(os.path.join(out, "dense_blob.ply"), v, t, big=False)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], epilog=__doc__.split("\n\n", 1)[1],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out_dir", metavar="OUT_DIR", help="folder to write the models into (made if missing)")
    group = ap.add_mutually_exclusive_group()
    group.add_argument("--big", action="store_true", help="also the 10^5 and 10^6 triangle scans")
    group.add_argument("--hands", action="store_true", help="the shapes for bench feel --hands instead")
    args = ap.parse_args()
    out = args.out_dir
    big = args.big
    os.makedirs(out, exist_ok=True)
    if args.hands:
        hand_shapes(out)
        return
    v, t = blob(71, 72, 1, 0.4)
    write_off_exported(os.path.join(out, "scan_blob.off"), v, t)
    v, t = bowl(24, 96, 50.0, 1.5)
    write_stl_binary(os.path.join(out, "bowl_shell.stl"), v, t, "solid bowl_shell exported as binary")
    plate_ascii_ply(os.path.join(out, "plate.ply"), 100.0, 5.0, 60.0, 16)
    v, p = bracket()
    write_ply_binary(os.path.join(out, "bracket.ply"), v, p, big=True)
    p = [q[::-1] if k in (1, 4) else q for k, q in enumerate(p)]  # the L at y = 40 and the top of the foot (z = 8)
    write_obj(os.path.join(out, "bracket_patch.obj"), v, p)
    v, t = blob(50, 50, 4, 0.4)
    write_stl_ascii(os.path.join(out, "scan_inward.stl"), v, [(a, c, b) for a, b, c in t])
    if big:
        v, t = blob(224, 224, 2, 0.3)
        write_ply_binary(os.path.join(out, "scan_1e5.ply"), v, t, big=False)
        v, t = blob(708, 708, 3, 0.2)
        write_stl_binary(os.path.join(out, "scan_1e6.stl"), v, t, "scan 1e6")


if __name__ == "__main__":
    main()
