#!/usr/bin/env python3
"""Writes scenes/assets/bunny.obj, the rabbit of water of scenes/bunny_splash.json.

Usage:
    python3 scripts/make_bunny_mesh.py [--out PATH] [--cells 30]

Pure Python 3 and deterministic: the same arguments give the same bytes. The rabbit is a smooth union of
ellipsoids (a body with its haunch, a chest, a head with a snout, two long ears tilted back and apart, a round
tail, hind feet and front paws), facing +x with y up. Each ellipsoid's approximate signed distance
(k0 (k0 - 1) / k1, with k0 and k1 the lengths of the point divided by the semi-axes and by their squares) is
blended with the next by a polynomial smooth minimum, and the zero level of the result is surfaced by marching
tetrahedra on a grid of `cells` cubes along the longest side of the shape's box (each cube cut into the six
tetrahedra around its main diagonal, the same cut in every cube, so that neighbouring cubes share their faces'
triangulation). At the default 30 cells: 4900 vertices, 9796 triangles, under 300 KB.

A grid value that lands within a small margin of zero is moved off it, so every vertex lies strictly inside a
crossing edge and is shared by every tetrahedron around that edge: the mesh is then closed and manifold. Each
triangle is wound counter-clockwise seen from outside (normals point out), checked in every tetrahedron against
the direction from its inside corners to its outside ones. The mesh is centred on the origin and scaled so
that its largest extent is 1; the script checks that it is closed, manifold and wound outwards before writing.
"""

import argparse
import math
import os

from obj_mesh import centre_and_scale, check_closed_edges, signed_volume, write_obj


def rotation(axis, degrees):
    """3x3 rotation matrix (rows) about a unit axis."""
    x, y, z = axis
    n = math.sqrt(x * x + y * y + z * z)
    x, y, z = x / n, y / n, z / n
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    t = 1 - c
    return ((t * x * x + c, t * x * y - s * z, t * x * z + s * y),
            (t * x * y + s * z, t * y * y + c, t * y * z - s * x),
            (t * x * z - s * y, t * y * z + s * x, t * z * z + c))


def multiply(a, b):
    return tuple(tuple(sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)) for i in range(3))


IDENTITY = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))

# The parts: (centre, semi-axes, rotation from the part's frame to the rabbit's). Units are arbitrary; the mesh
# is scaled at the end. The ears lean back (about z) by 18 degrees and apart (about x) by 14 degrees each.
PARTS = [
    ((-0.12, 0.34, 0.0), (0.42, 0.33, 0.30), IDENTITY),                  # body and haunch
    ((0.16, 0.42, 0.0), (0.26, 0.30, 0.23), rotation((0, 0, 1), -20)),   # chest
    ((0.36, 0.74, 0.0), (0.21, 0.18, 0.17), rotation((0, 0, 1), -10)),   # head
    ((0.53, 0.69, 0.0), (0.10, 0.09, 0.10), IDENTITY),                   # snout
    ((-0.55, 0.40, 0.0), (0.09, 0.09, 0.09), IDENTITY),                  # tail
    ((-0.08, 0.07, 0.17), (0.22, 0.07, 0.09), IDENTITY),                 # hind feet
    ((-0.08, 0.07, -0.17), (0.22, 0.07, 0.09), IDENTITY),
    ((0.33, 0.09, 0.10), (0.10, 0.09, 0.065), IDENTITY),                 # front paws
    ((0.33, 0.09, -0.10), (0.10, 0.09, 0.065), IDENTITY),
]
for side in (1, -1):
    tilt = multiply(rotation((0, 0, 1), 18), rotation((1, 0, 0), 14 * side))
    # Semi-axes (front to back, length, side to side); the base sits in the back of the head.
    length = 0.27
    along = (tilt[0][1], tilt[1][1], tilt[2][1])  # the ear's long axis in the rabbit's frame
    base = (0.30, 0.84, 0.075 * side)
    centre = tuple(base[k] + length * along[k] for k in range(3))
    PARTS.append((centre, (0.085, length, 0.05), tilt))

BLEND = 0.07  # the smooth minimum's width: how far the fillets between parts reach


def ellipsoid_distance(p, centre, radii, rot):
    d = (p[0] - centre[0], p[1] - centre[1], p[2] - centre[2])
    # Into the part's frame: the transpose of the rotation.
    q = (rot[0][0] * d[0] + rot[1][0] * d[1] + rot[2][0] * d[2],
         rot[0][1] * d[0] + rot[1][1] * d[1] + rot[2][1] * d[2],
         rot[0][2] * d[0] + rot[1][2] * d[1] + rot[2][2] * d[2])
    # Quilez's approximation k0 (k0 - 1) / k1: close to the Euclidean distance near the surface, unlike the
    # normalised radius, which would let the smooth minimum swell a long thin part (an ear) along its length.
    k0 = math.sqrt((q[0] / radii[0]) ** 2 + (q[1] / radii[1]) ** 2 + (q[2] / radii[2]) ** 2)
    k1 = math.sqrt((q[0] / radii[0] ** 2) ** 2 + (q[1] / radii[1] ** 2) ** 2 + (q[2] / radii[2] ** 2) ** 2)
    if k1 == 0:
        return -min(radii)
    return k0 * (k0 - 1.0) / k1


def smooth_min(a, b, k):
    h = max(k - abs(a - b), 0.0) / k
    return min(a, b) - h * h * k * 0.25


def field(p):
    value = None
    for centre, radii, rot in PARTS:
        d = ellipsoid_distance(p, centre, radii, rot)
        value = d if value is None else smooth_min(value, d, BLEND)
    return value


def bounding_box():
    low, high = [math.inf] * 3, [-math.inf] * 3
    for centre, radii, rot in PARTS:
        for k in range(3):
            # The extent of a rotated ellipsoid along axis k: sqrt(sum_j (R_kj r_j)^2).
            # Grown by the blend width: the smooth minimum reaches up to a quarter of it beyond the parts.
            half = math.sqrt(sum((rot[k][j] * (radii[j] + BLEND)) ** 2 for j in range(3)))
            low[k] = min(low[k], centre[k] - half)
            high[k] = max(high[k], centre[k] + half)
    return low, high


# The six tetrahedra of a cube around its diagonal from corner 0 to corner 7 (corner bits: x 1, y 2, z 4): one
# for each order in which the path from 0 to 7 steps along the axes.
TETRAHEDRA = []
for order in ((0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)):
    corner, tet = 0, [0]
    for axis in order:
        corner |= 1 << axis
        tet.append(corner)
    TETRAHEDRA.append(tuple(tet))


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def marching_tetrahedra(cells):
    low, high = bounding_box()
    size = max(high[k] - low[k] for k in range(3))
    h = size / cells
    origin = [low[k] - 1.5 * h for k in range(3)]
    counts = [int(math.ceil((high[k] - low[k]) / h)) + 3 for k in range(3)]  # cubes per axis, a margin outside
    margin = 1e-3 * h
    values = {}
    for i in range(counts[0] + 1):
        for j in range(counts[1] + 1):
            for k in range(counts[2] + 1):
                f = field((origin[0] + i * h, origin[1] + j * h, origin[2] + k * h))
                if abs(f) < margin:
                    f = margin if f >= 0 else -margin  # off zero: every vertex strictly inside its edge
                values[(i, j, k)] = f

    def point(g):
        return (origin[0] + g[0] * h, origin[1] + g[1] * h, origin[2] + g[2] * h)

    vertices, index_of_edge, faces = [], {}, []

    def vertex(a, b):
        key = (a, b) if a < b else (b, a)
        if key not in index_of_edge:
            fa, fb = values[a], values[b]
            t = fa / (fa - fb)
            pa, pb = point(a), point(b)
            vertices.append((pa[0] + t * (pb[0] - pa[0]), pa[1] + t * (pb[1] - pa[1]), pa[2] + t * (pb[2] - pa[2])))
            index_of_edge[key] = len(vertices) - 1
        return index_of_edge[key]

    def emit(triangle, inside, outside):
        # Wind it so that its normal points from the tetrahedron's inside corners to its outside ones.
        a, b, c = (vertices[v] for v in triangle)
        normal = cross(sub(b, a), sub(c, a))
        pi = [sum(point(g)[k] for g in inside) / len(inside) for k in range(3)]
        po = [sum(point(g)[k] for g in outside) / len(outside) for k in range(3)]
        if dot(normal, sub(po, pi)) < 0:
            triangle = (triangle[0], triangle[2], triangle[1])
        faces.append(triangle)

    for i in range(counts[0]):
        for j in range(counts[1]):
            for k in range(counts[2]):
                cube = [(i + (c & 1), j + (c >> 1 & 1), k + (c >> 2 & 1)) for c in range(8)]
                signs = [values[g] < 0 for g in cube]
                if all(signs) or not any(signs):
                    continue
                for tet in TETRAHEDRA:
                    corners = [cube[c] for c in tet]
                    inside = [g for g in corners if values[g] < 0]
                    outside = [g for g in corners if values[g] >= 0]
                    if len(inside) in (0, 4):
                        continue
                    if len(inside) == 1 or len(outside) == 1:
                        apex, others = (inside[0], outside) if len(inside) == 1 else (outside[0], inside)
                        emit((vertex(apex, others[0]), vertex(apex, others[1]), vertex(apex, others[2])),
                             inside, outside)
                    else:
                        a, b = inside
                        c, d = outside
                        # The quad ac, ad, bd, bc (in that order around it), cut along ac-bd.
                        ac, ad, bd, bc = vertex(a, c), vertex(a, d), vertex(b, d), vertex(b, c)
                        emit((ac, ad, bd), inside, outside)
                        emit((ac, bd, bc), inside, outside)
    return vertices, faces


def check_closed_manifold(vertices, faces):
    check_closed_edges(faces)
    # Manifold at vertices too: the triangles around each vertex form a single fan.
    around = {}
    for a, b, c in faces:
        for u, v, w in ((a, b, c), (b, c, a), (c, a, b)):
            around.setdefault(u, {})[v] = w  # the edge u-v is followed, around u, by u-w
    for u, next_of in around.items():
        start = next(iter(next_of))
        v, steps = start, 0
        while True:
            v = next_of[v]
            steps += 1
            if v == start:
                break
        if steps != len(next_of):
            raise SystemExit("internal error: the mesh is not manifold at a vertex")
    if len(around) != len(vertices):
        raise SystemExit("internal error: a vertex belongs to no triangle")
    # One piece: every triangle reachable from the first across edges.
    owner = {}
    for t, (a, b, c) in enumerate(faces):
        for u, v in ((a, b), (b, c), (c, a)):
            owner[(u, v)] = t
    seen, stack = {0}, [0]
    while stack:
        a, b, c = faces[stack.pop()]
        for u, v in ((a, b), (b, c), (c, a)):
            t = owner[(v, u)]
            if t not in seen:
                seen.add(t)
                stack.append(t)
    if len(seen) != len(faces):
        raise SystemExit("internal error: the mesh is in more than one piece")


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", default=os.path.join(here, "..", "scenes", "assets", "bunny.obj"))
    parser.add_argument("--cells", type=int, default=30, help="grid cubes along the longest side (30)")
    args = parser.parse_args()
    if not 8 <= args.cells <= 200:
        parser.error("--cells must be 8..200")

    vertices, faces = marching_tetrahedra(args.cells)

    vertices, low, high, extent = centre_and_scale(vertices)
    check_closed_manifold(vertices, faces)
    write_obj(args.out,
              ["bunny.obj: a rabbit (a smooth union of ellipsoids) made by scripts/make_bunny_mesh.py (--cells %d)"
               % args.cells,
               "Surge authors, CC0 1.0. %d vertices, %d triangles, closed, outward winding, largest extent 1, "
               "facing +x, y up." % (len(vertices), len(faces))],
              ["v %.5f %.5f %.5f" % tuple(0.0 if abs(c) < 5e-6 else c for c in p) for p in vertices], faces, low, high,
              extent, signed_volume(vertices, faces))

if __name__ == "__main__":
    main()
