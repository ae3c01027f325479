# SPDX-License-Identifier: BSD-3-Clause
"""Compares two meshes as ply_triangles prints them (a triangle a line, 9 hexadecimal floats):
equal up to the order of the triangles and of the vertices within each, within a tolerance.

    mesh_match.py A.txt B.txt [EXPR] [--vertices] [--tolerance T]

EXPR (a Python expression of x, y, z; default "(x, y, z)") maps each vertex of A into B's
coordinates first. With --vertices, the distinct vertices of the two are compared instead of the
triangles (one surface split into triangles otherwise). Exits 0 when every triangle (or
vertex) of each has one of the other within T (default 1e-4) in every coordinate, matched one to
one; else 1, printing the first one that has none."""
import itertools
import sys


def read(path, expr):
    triangles = []
    with open(path) as f:
        for line in f:
            v = [float.fromhex(s) for s in line.split()[:9]]
            corners = []
            for i in (0, 3, 6):
                x, y, z = v[i:i + 3]
                corners.append(tuple(eval(expr, {}, {"x": x, "y": y, "z": z})))
            triangles.append(tuple(corners))
    return triangles


def cell(point, size):
    return tuple(int(c // size) for c in point)


def close(p, q, tolerance):
    return all(abs(u - v) <= tolerance for u, v in zip(p, q))


def same_triangle(s, t, tolerance):
    """Whether the corners of s and t pair up within the tolerance, in some order."""
    return any(all(close(s[i], t[j], tolerance) for i, j in zip(range(3), order))
               for order in itertools.permutations(range(3)))


def centroid(t):
    return tuple(sum(c[k] for c in t) / 3 for k in range(3))


def matched(a, b, tolerance, where, same):
    """Whether each item of a has its own item of b (same()), and none is left; where(item) is
    the point the search looks it up by."""
    size = 100 * tolerance  # the grid the search looks up: a cell and its neighbours
    grid = {}
    for item in b:
        grid.setdefault(cell(where(item), size), []).append(item)
    for item in a:
        key, found = cell(where(item), size), None
        for step in itertools.product((-1, 0, 1), repeat=3):
            near = grid.get(tuple(k + s for k, s in zip(key, step)), [])
            for i, other in enumerate(near):
                if same(item, other, tolerance):
                    found = near.pop(i)
                    break
            if found:
                break
        if not found:
            print("mesh_match: no match for %r" % (item,))
            return False
    return True


def main():
    args = sys.argv[1:]
    vertices = "--vertices" in args
    tolerance = 1e-4
    if "--tolerance" in args:
        tolerance = float(args[args.index("--tolerance") + 1])
        del args[args.index("--tolerance"):args.index("--tolerance") + 2]
    args = [a for a in args if a != "--vertices"]
    expr = args[2] if len(args) > 2 else "(x, y, z)"
    a, b = read(args[0], expr), read(args[1], "(x, y, z)")
    if vertices:
        # the cells that share a vertex compute it to the same bits (src/engine/mc.h)
        a = sorted({p for t in a for p in t})
        b = sorted({p for t in b for p in t})
        where, same = (lambda p: p), close
    else:
        where, same = centroid, same_triangle
    if len(a) != len(b) or not a:
        print("mesh_match: %d and %d %s" % (len(a), len(b),
                                             "vertices" if vertices else "triangles"))
        return 1
    return 0 if matched(a, b, tolerance, where, same) else 1


if __name__ == "__main__":
    sys.exit(main())
