#!/usr/bin/env python3
"""Writes scenes/assets/rock.obj, the boulder of scenes/pour_over_rock.json.

Usage:
    python3 scripts/make_rock_mesh.py [--out PATH] [--subdivisions 3] [--seed 7]

Pure Python 3 and deterministic: the same arguments give the same bytes. The rock is an icosahedron
subdivided `subdivisions` times (20 x 4^n triangles: 1280 at the default 3, 5120 at 4), projected on the unit
sphere and moved along each vertex's direction by a smooth noise (a sum of sinusoids over fixed pseudo-random
directions, from a linear congruential generator seeded by `seed`). It is then squashed into a boulder's
proportions, its bottom is cut flat so that it sits on a floor, and it is centred on the origin and scaled so
that its largest extent is 1.

The radius stays a positive function of the direction throughout (the surface is star-shaped about its first
centre), so the mesh is closed, manifold and free of self-intersections; every triangle is wound
counter-clockwise seen from outside (normals point out). The script checks both before writing.
"""

import argparse
import math
import os

from obj_mesh import centre_and_scale, check_closed_edges, signed_volume, write_obj


class Lcg:
    """Numerical Recipes' 32-bit linear congruential generator: the same numbers on every machine."""

    def __init__(self, seed):
        self.state = (seed * 2654435761 + 12345) & 0xFFFFFFFF

    def uniform(self):
        self.state = (1664525 * self.state + 1013904223) & 0xFFFFFFFF
        return self.state / 4294967296.0


def normalize(p):
    n = math.sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2])
    return (p[0] / n, p[1] / n, p[2] / n)


def icosphere(subdivisions):
    t = (1.0 + math.sqrt(5.0)) / 2.0
    vertices = [normalize(p) for p in (
        (-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0),
        (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
        (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1))]
    faces = [
        (0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11),
        (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6), (7, 1, 8),
        (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9),
        (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(subdivisions):
        midpoints = {}

        def midpoint(a, b):
            key = (min(a, b), max(a, b))
            if key not in midpoints:
                pa, pb = vertices[a], vertices[b]
                vertices.append(normalize(((pa[0] + pb[0]) / 2, (pa[1] + pb[1]) / 2, (pa[2] + pb[2]) / 2)))
                midpoints[key] = len(vertices) - 1
            return midpoints[key]

        refined = []
        for a, b, c in faces:
            ab, bc, ca = midpoint(a, b), midpoint(b, c), midpoint(c, a)
            refined += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = refined
    return vertices, faces


def random_direction(rng):
    while True:
        p = (2 * rng.uniform() - 1, 2 * rng.uniform() - 1, 2 * rng.uniform() - 1)
        n2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2]
        if 1e-4 < n2 <= 1:
            return normalize(p)


def make_noise(seed):
    """A smooth function of a unit direction, about -1..1: octaves of sinusoids along random directions."""
    rng = Lcg(seed)
    waves = []
    for frequency, amplitude, count in ((1.6, 0.5, 5), (3.2, 0.35, 6), (6.4, 0.2, 8)):
        for _ in range(count):
            waves.append((random_direction(rng), frequency, amplitude / math.sqrt(count),
                          2 * math.pi * rng.uniform()))

    def noise(d):
        return sum(a * math.sin(f * (d[0] * w[0] + d[1] * w[1] + d[2] * w[2]) + phase)
                   for w, f, a, phase in waves)

    return noise


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", default=os.path.join(here, "..", "scenes", "assets", "rock.obj"))
    parser.add_argument("--subdivisions", type=int, default=3, help="icosahedron subdivisions (3: 1280 triangles)")
    parser.add_argument("--seed", type=int, default=7, help="seed of the noise")
    args = parser.parse_args()
    if not 0 <= args.subdivisions <= 6:
        parser.error("--subdivisions must be 0..6")

    directions, faces = icosphere(args.subdivisions)
    noise = make_noise(args.seed)
    squash = (1.0, 0.72, 0.85)  # a boulder is wider than it is tall
    floor = -0.45               # the bottom cut flat at this height (in units of the first radius)
    vertices = []
    for d in directions:
        r = 1.0 + 0.25 * noise(d)  # |noise| < 2.6, so r > 0.35: the surface stays star-shaped
        p = (r * d[0] * squash[0], r * d[1] * squash[1], r * d[2] * squash[2])
        if p[1] < floor:
            # The ray from the centre meets the floor first: stay on the ray, so the surface stays star-shaped.
            p = (p[0] * floor / p[1], floor, p[2] * floor / p[1])
        vertices.append(p)

    vertices, low, high, extent = centre_and_scale(vertices)
    check_closed_edges(faces)
    write_obj(args.out,
              ["rock.obj: a procedural boulder made by scripts/make_rock_mesh.py (--subdivisions %d --seed %d)"
               % (args.subdivisions, args.seed),
               "Surge authors, CC0 1.0. %d vertices, %d triangles, closed, outward winding, largest extent 1."
               % (len(vertices), len(faces))],
              ["v %.6f %.6f %.6f" % p for p in vertices], faces, low, high, extent, signed_volume(vertices, faces))

if __name__ == "__main__":
    main()
