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
Usage: scripts/make_test_models.py OUT_DIR [--big]
"""
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


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    out = sys.argv[1]
    big = "--big" in sys.argv[2:]
    os.makedirs(out, exist_ok=True)
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
