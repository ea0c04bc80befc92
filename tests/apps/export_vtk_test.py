"""surge export --format vtk read back by VTK's own reader (Debian python3-vtk9).

A small 3D run with a standing and a keyframed collider, a body and a surface is simulated, surfaced and
exported; every .pvd is parsed as XML (VTK has no .pvd reader; ParaView's is in ParaView), every .vtp it names
read with vtkXMLPolyDataReader, and its values compared with the PLY frames read with numpy: positions,
velocities and ids exactly, time steps, mesh vertex and triangle counts and indices, the moving solids' poses.
Bad input (a format that does not exist, a folder without particles) must give one line, exit 2, and write
nothing. Exit 77 (ctest's skip) where python3-vtk9 or numpy is missing.

Usage: export_vtk_test.py SURGE_BINARY WORK_FOLDER
"""
import os
import shutil
import sys
import xml.etree.ElementTree as ElementTree

from export_runs import SCENE, Checks, frame_ply, make_run, read_ply, require, surge

np, vtk, numpy_support = require("numpy", "vtk", "vtk.util.numpy_support")
vtk_to_numpy = numpy_support.vtk_to_numpy

check = Checks()


def read_vtp(path):
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(path)
    reader.Update()
    check(reader.GetErrorCode() == 0, f"{path}: vtkXMLPolyDataReader error {reader.GetErrorCode()}")
    return reader.GetOutput()


def read_pvd(path):
    """(time, part, name, file) of each DataSet of a .pvd, files made absolute."""
    root = ElementTree.parse(path).getroot()
    check(root.get("type") == "Collection", f"{path}: not a Collection")
    folder = os.path.dirname(path)
    return [(float(d.get("timestep")), int(d.get("part", 0)), d.get("name", ""), os.path.join(folder, d.get("file")))
            for d in root.iter("DataSet")]


def main():
    binary, work = sys.argv[1], os.path.join(sys.argv[2], "export_vtk_test")
    run = make_run(binary, work)

    # Bad input: one line naming the flag or the folder, exit 2, nothing written.
    result = surge(binary, "export", run, "--format", "obj")
    check(result.returncode == 2 and "--format" in result.stderr and result.stderr.count("\n") == 1,
          f"unknown format: exit {result.returncode}, stderr {result.stderr!r}")
    check(not os.path.exists(os.path.join(run, "export")), "unknown format wrote export/")
    bare = os.path.join(work, "bare")
    os.makedirs(bare)
    shutil.copy(os.path.join(run, "scene.json"), bare)
    result = surge(binary, "export", bare, "--format", "vtk")
    check(result.returncode == 2 and "particles" in result.stderr and result.stderr.count("\n") == 1,
          f"folder without particles: exit {result.returncode}, stderr {result.stderr!r}")
    check(os.listdir(bare) == ["scene.json"], f"folder without particles: wrote {os.listdir(bare)}")

    result = surge(binary, "export", run, "--format", "vtk")
    check(result.returncode == 0, f"export failed: {result.stderr}")
    export = os.path.join(run, "export")
    check(sorted(f for f in os.listdir(export) if f.endswith(".pvd")) ==
          ["bodies.pvd", "colliders.pvd", "particles.pvd", "surface.pvd"], f"pvd files: {os.listdir(export)}")
    leftovers = [os.path.join(d, f) for d, _, files in os.walk(export) for f in files if ".tmp" in f]
    check(not leftovers, f"temporaries left: {leftovers}")
    frames = SCENE["output"]["frames"]
    fps = SCENE["output"]["fps"]

    # Particles: every property of the PLY, values exact.
    particles = read_pvd(os.path.join(export, "particles.pvd"))
    check([t for t, _, _, _ in particles] == [f / fps for f in range(frames + 1)],
          f"particle time steps {[t for t, _, _, _ in particles]}")
    for frame, (_, _, _, vtp) in enumerate(particles):
        ply, _ = read_ply(frame_ply(run, "particles", frame))
        data = read_vtp(vtp)
        n = len(ply["x"])
        check(data.GetNumberOfPoints() == n and data.GetNumberOfVerts() == n,
              f"frame {frame}: {data.GetNumberOfPoints()} points, {data.GetNumberOfVerts()} vertex cells, not {n}")
        points = vtk_to_numpy(data.GetPoints().GetData())
        check(np.array_equal(points, np.stack([ply["x"], ply["y"], ply["z"]], axis=1)), f"frame {frame}: positions")
        velocity = vtk_to_numpy(data.GetPointData().GetArray("velocity"))
        check(np.array_equal(velocity, np.stack([ply["vx"], ply["vy"], ply["vz"]], axis=1)),
              f"frame {frame}: velocities")
        ids = data.GetPointData().GetArray("id")
        check(ids is not None and ids.GetDataTypeAsString() == "unsigned int" and
              np.array_equal(vtk_to_numpy(ids), ply["id"]), f"frame {frame}: ids")
    check(np.abs(vtk_to_numpy(read_vtp(particles[-1][3]).GetPointData().GetArray("velocity"))).max() > 0.1,
          "the last frame's water is still")

    # Surfaces: vertex and triangle counts, the triangles' indices, velocities where the PLY has them.
    surfaces = read_pvd(os.path.join(export, "surface.pvd"))
    check(len(surfaces) == frames + 1, f"{len(surfaces)} surface frames")
    for frame, (time, _, _, vtp) in enumerate(surfaces):
        ply, faces = read_ply(frame_ply(run, "surface", frame))
        data = read_vtp(vtp)
        check(time == frame / fps, f"surface frame {frame} at {time}")
        check(data.GetNumberOfPoints() == len(ply["x"]) and data.GetNumberOfPolys() == len(faces),
              f"surface frame {frame}: {data.GetNumberOfPoints()} vertices, {data.GetNumberOfPolys()} triangles, "
              f"not {len(ply['x'])}, {len(faces)}")
        cells = vtk_to_numpy(data.GetPolys().GetConnectivityArray())
        check(np.array_equal(cells, np.concatenate(faces)), f"surface frame {frame}: triangles")
        points = vtk_to_numpy(data.GetPoints().GetData())
        check(np.array_equal(points, np.stack([ply["x"], ply["y"], ply["z"]], axis=1)), f"surface {frame}: points")
        check("vx" in ply, f"surface frame {frame}: no velocities in the PLY (surface.mesh_velocity is 1)")
        if "vx" in ply:
            velocity = vtk_to_numpy(data.GetPointData().GetArray("velocity"))
            check(np.array_equal(velocity, np.stack([ply["vx"], ply["vy"], ply["vz"]], axis=1)),
                  f"surface frame {frame}: velocities")

    # Colliders and bodies: a part each, every frame, in the pose of that frame.
    colliders = read_pvd(os.path.join(export, "colliders.pvd"))
    check(sorted({(p, n) for _, p, n, _ in colliders}) == [(0, "post"), (1, "paddle")], "collider parts")
    check(len(colliders) == 2 * (frames + 1), f"{len(colliders)} collider entries")
    for time, _, name, vtp in colliders:
        frame = round(time * fps)
        moving = name == "paddle"
        source = frame_ply(run, "colliders", frame, name) if moving else \
            os.path.join(run, "colliders", name + ".ply")
        ply, faces = read_ply(source)
        points = vtk_to_numpy(read_vtp(vtp).GetPoints().GetData())
        check(np.array_equal(points, np.stack([ply["x"], ply["y"], ply["z"]], axis=1)), f"{name} at frame {frame}")
    paddle = {round(t * fps): v for t, _, n, v in colliders if n == "paddle"}
    moved = vtk_to_numpy(read_vtp(paddle[frames]).GetPoints().GetData()).mean(axis=0) - \
        vtk_to_numpy(read_vtp(paddle[0]).GetPoints().GetData()).mean(axis=0)
    check(abs(moved[0] - 0.05) < 1e-4, f"the paddle's centre moved {moved}, not 0.05 m along x")
    bodies = read_pvd(os.path.join(export, "bodies.pvd"))
    check([(round(t * fps), n) for t, _, n, _ in bodies] == [(f, "crate") for f in range(frames + 1)],
          "body entries")
    for time, _, name, vtp in bodies:
        frame = round(time * fps)
        ply, faces = read_ply(frame_ply(run, "bodies", frame, name))
        data = read_vtp(vtp)
        check(data.GetNumberOfPolys() == 12, f"crate at frame {frame}: {data.GetNumberOfPolys()} triangles")
        check(np.array_equal(vtk_to_numpy(data.GetPoints().GetData()),
                             np.stack([ply["x"], ply["y"], ply["z"]], axis=1)), f"crate at frame {frame}")

    return check.status()


if __name__ == "__main__":
    sys.exit(main())
