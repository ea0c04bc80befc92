"""What the asset scripts (make_rock_mesh.py, make_bunny_mesh.py) share: centring and scaling a mesh, checking that
it is closed and wound outwards, and writing it as OBJ. Pure Python 3, deterministic."""

import os


def centre_and_scale(vertices):
    """The vertices with their bounding box centred on the origin and its largest extent 1; also the box's low and
    high corners and that extent, before scaling."""
    low = [min(p[k] for p in vertices) for k in range(3)]
    high = [max(p[k] for p in vertices) for k in range(3)]
    centre = [(low[k] + high[k]) / 2 for k in range(3)]
    extent = max(high[k] - low[k] for k in range(3))
    return [tuple((p[k] - centre[k]) / extent for k in range(3)) for p in vertices], low, high, extent


def signed_volume(vertices, faces):
    volume = 0.0
    for a, b, c in faces:
        pa, pb, pc = vertices[a], vertices[b], vertices[c]
        volume += (pa[0] * (pb[1] * pc[2] - pb[2] * pc[1]) - pa[1] * (pb[0] * pc[2] - pb[2] * pc[0]) +
                   pa[2] * (pb[0] * pc[1] - pb[1] * pc[0]))
    return volume / 6.0


def check_closed_edges(faces):
    """Each directed edge once, and its twin once: closed, manifold along edges and consistently wound."""
    edges = {}
    for a, b, c in faces:
        for u, v in ((a, b), (b, c), (c, a)):
            edges[(u, v)] = edges.get((u, v), 0) + 1
    for (u, v), count in edges.items():
        if count != 1 or edges.get((v, u), 0) != 1:
            raise SystemExit("internal error: the mesh is not closed and consistently wound")


def write_obj(path, comments, vertex_lines, faces, low, high, extent, volume):
    """Writes the OBJ (comment lines, then `v` and `f` lines) and prints what was written."""
    if volume <= 0:
        raise SystemExit("internal error: the triangles are wound inwards")
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    lines = ["# " + line for line in comments] + vertex_lines
    lines += ["f %d %d %d" % (a + 1, b + 1, c + 1) for a, b, c in faces]
    with open(path, "w", newline="\n") as f:
        f.write("\n".join(lines) + "\n")
    size = [(high[k] - low[k]) / extent for k in range(3)]
    print("wrote %s (%d vertices, %d triangles, %.3f x %.3f x %.3f, volume %.4f)"
          % (os.path.normpath(path), len(vertex_lines), len(faces), size[0], size[1], size[2], volume))
