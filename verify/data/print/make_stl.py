#!/usr/bin/env python3
"""Write the two test models as ASCII STL files (no extra packages).

cube.stl:     20 x 20 x 20 mm cube, corner at the origin.
cylinder.stl: diameter 20 mm, height 20 mm, 64 side facets, axis along Z,
              base centred on (10, 10, 0).
PrusaSlicer re-centres the parts on the bed anyway (default --center 100,100).
"""
import math
import sys


def write_ascii_stl(path, name, tris):
    with open(path, "w") as f:
        f.write("solid %s\n" % name)
        for a, b, c in tris:
            ux, uy, uz = (b[i] - a[i] for i in range(3))
            vx, vy, vz = (c[i] - a[i] for i in range(3))
            n = (uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx)
            ln = math.sqrt(sum(x * x for x in n)) or 1.0
            f.write("  facet normal %.9e %.9e %.9e\n" % tuple(x / ln for x in n))
            f.write("    outer loop\n")
            for v in (a, b, c):
                f.write("      vertex %.9e %.9e %.9e\n" % v)
            f.write("    endloop\n  endfacet\n")
        f.write("endsolid %s\n" % name)


def cube(s=20.0):
    p = [(x, y, z) for z in (0.0, s) for y in (0.0, s) for x in (0.0, s)]
    # vertex index = x_bit + 2*y_bit + 4*z_bit; quads listed counter-clockwise
    # seen from outside
    quads = [(0, 2, 3, 1),  # bottom z=0
             (4, 5, 7, 6),  # top z=s
             (0, 1, 5, 4),  # y=0
             (2, 6, 7, 3),  # y=s
             (0, 4, 6, 2),  # x=0
             (1, 3, 7, 5)]  # x=s
    tris = []
    for a, b, c, d in quads:
        tris.append((p[a], p[b], p[c]))
        tris.append((p[a], p[c], p[d]))
    return tris


def cylinder(d=20.0, h=20.0, n=64, cx=10.0, cy=10.0):
    r = d / 2.0
    ring = [(cx + r * math.cos(2 * math.pi * i / n),
             cy + r * math.sin(2 * math.pi * i / n)) for i in range(n)]
    tris = []
    for i in range(n):
        x0, y0 = ring[i]
        x1, y1 = ring[(i + 1) % n]
        # side (outward normal)
        tris.append(((x0, y0, 0.0), (x1, y1, 0.0), (x1, y1, h)))
        tris.append(((x0, y0, 0.0), (x1, y1, h), (x0, y0, h)))
        # bottom (normal -Z) and top (normal +Z)
        tris.append(((cx, cy, 0.0), (x1, y1, 0.0), (x0, y0, 0.0)))
        tris.append(((cx, cy, h), (x0, y0, h), (x1, y1, h)))
    return tris


if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 else "."
    write_ascii_stl(out + "/cube.stl", "cube20", cube())
    write_ascii_stl(out + "/cylinder.stl", "cylinder20", cylinder())
