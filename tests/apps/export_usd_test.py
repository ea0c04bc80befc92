"""surge export --format usd: the stage's values against the run, and (where it can) Blender's USD importer.

Two checks of the small 3D run of export_runs.py, chosen by the first argument:
  stage    reads scene.usda's prims and time samples (the subset of USD ASCII surge writes; Debian has no USD
           library) and compares them with the run's PLY files: the stage's metadata (metres, y up, time codes
           and fps), particle positions, velocities and ids exactly, the surface's vertex and triangle counts and
           indices, and each collider and body placed by its translate and orient at every frame onto the mesh
           the simulation wrote for that frame.
  blender  imports scene.usda headless with Blender's bpy.ops.wm.usd_import and checks the frame range, the
           surface's vertex count at a frame and the body's world transform at a frame. Exit 77 (ctest's skip)
           where blender is not installed or was built without USD (Debian 12's blender 3.4.1 is).
Bad input (an unknown format) must give one line and exit 2.

Usage: export_usd_test.py stage|blender SURGE_BINARY WORK_FOLDER
"""
import json
import os
import re
import shutil
import subprocess
import sys

from export_runs import SCENE, Checks, frame_ply, make_run, read_ply, require, surge

np, = require("numpy")

check = Checks()
FRAMES, FPS = SCENE["output"]["frames"], SCENE["output"]["fps"]


def value(text):
    """A USD ASCII value of numbers, tuples and arrays as nested lists (tuples read as lists)."""
    return json.loads(text.replace("(", "[").replace(")", "]"))


def read_stage(path):
    """The stage's metadata, and per prim path its attributes: name -> value, or name -> {time: value}."""
    metadata, prims, stack, samples = {}, {}, [], None
    with open(path) as f:
        lines = f.read().split("\n")
    check(lines[0] == "#usda 1.0", f"first line {lines[0]!r}")
    for line in lines[1:]:
        text = line.strip()
        if not stack and (m := re.match(r'(\w+) = (.*)$', text)):
            metadata[m.group(1)] = m.group(2).strip('"')
        elif m := re.match(r'def \w+ "(\w+)"', text):
            stack.append(m.group(1))
            prims["/" + "/".join(stack)] = {}
        elif text == "}" and samples is not None:
            samples = None
        elif text == "}":
            stack.pop()
        elif samples is not None:
            time, _, rest = text.partition(": ")
            samples[int(time)] = value(rest.rstrip(","))
        elif m := re.match(r'(?:uniform )?[\w\[\]]+ ([\w:]+)\.timeSamples = \{$', text):
            samples = prims["/" + "/".join(stack)].setdefault(m.group(1), {})
        elif m := re.match(r'(?:uniform )?[\w\[\]]+ ([\w:]+) = (\[[^\]]*\])(?: \(.*\))?$', text):
            prims["/" + "/".join(stack)][m.group(1)] = value(m.group(2)) if m.group(1) != "xformOpOrder" else \
                json.loads(m.group(2))
    return metadata, prims


def rotation(w, x, y, z):
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def xyz(ply):
    return np.stack([ply["x"], ply["y"], ply["z"]], axis=1)


def check_stage(run):
    metadata, prims = read_stage(os.path.join(run, "export", "scene.usda"))
    check(metadata.get("metersPerUnit") == "1" and metadata.get("upAxis") == "Y", f"units, axis: {metadata}")
    check((metadata.get("startTimeCode"), metadata.get("endTimeCode"), metadata.get("timeCodesPerSecond")) ==
          ("0", str(FRAMES), str(FPS)), f"time codes: {metadata}")
    root = "/" + SCENE["name"]
    check(metadata.get("defaultPrim") == SCENE["name"], f"defaultPrim {metadata.get('defaultPrim')}")

    particles = prims[root + "/particles"]
    check(sorted(particles["points"]) == list(range(FRAMES + 1)), f"particle samples {sorted(particles['points'])}")
    for frame in range(FRAMES + 1):
        ply, _ = read_ply(frame_ply(run, "particles", frame))
        check(np.array_equal(np.array(particles["points"][frame], dtype=np.float32), xyz(ply)),
              f"particles at {frame}: points")
        velocity = np.stack([ply["vx"], ply["vy"], ply["vz"]], axis=1)
        check(np.array_equal(np.array(particles["velocities"][frame], dtype=np.float32), velocity),
              f"particles at {frame}: velocities")
        check(particles["ids"][frame] == ply["id"].tolist(), f"particles at {frame}: ids")
    check(particles["widths"] == [SCENE["particle_spacing"]], f"widths {particles['widths']}")

    surface = prims[root + "/surface"]
    # The fluid's own colour (fluids[0].color), not the render's water_color.
    check(surface.get("primvars:displayColor") == [SCENE["fluids"][0]["color"]],
          f"surface colour {surface.get('primvars:displayColor')}")
    for frame in range(FRAMES + 1):
        ply, faces = read_ply(frame_ply(run, "surface", frame))
        points = np.array(surface["points"][frame], dtype=np.float32)
        check(points.shape == (len(ply["x"]), 3) and np.array_equal(points, xyz(ply)), f"surface at {frame}: points")
        check(surface["faceVertexCounts"][frame] == [3] * len(faces), f"surface at {frame}: {len(faces)} triangles")
        check(surface["faceVertexIndices"][frame] == np.concatenate(faces).tolist(), f"surface at {frame}: indices")
        velocity = np.stack([ply["vx"], ply["vy"], ply["vz"]], axis=1)
        check(np.array_equal(np.array(surface["velocities"][frame], dtype=np.float32), velocity),
              f"surface at {frame}: velocities")

    # A solid's points taken by its translate and orient at each frame onto the simulation's mesh of that frame.
    for path, kind, name in [("/colliders/paddle", "colliders", "paddle"), ("/bodies/crate", "bodies", "crate")]:
        prim = prims[root + path]
        check(prim.get("xformOpOrder") == ["xformOp:translate", "xformOp:orient"], f"{name}: xformOpOrder")
        local = np.array(prim["points"])
        for frame in range(FRAMES + 1):
            world = local @ rotation(*prim["xformOp:orient"][frame]).T + np.array(prim["xformOp:translate"][frame])
            expected = xyz(read_ply(frame_ply(run, kind, frame, name))[0])
            error = np.abs(world - expected).max()
            check(error < 2e-6, f"{name} at frame {frame}: {error:.2g} m from the simulation's mesh")
    post = prims[root + "/colliders/post"]
    check("xformOpOrder" not in post, "the standing post has a transform")
    check(np.array_equal(np.array(post["points"], dtype=np.float32),
                         xyz(read_ply(os.path.join(run, "colliders", "post.ply"))[0])), "the post's points")
    moved = np.array(prims[root + "/bodies/crate"]["xformOp:translate"][FRAMES]) - \
        np.array(prims[root + "/bodies/crate"]["xformOp:translate"][0])
    check(moved[1] < -0.01, f"the crate fell {-moved[1]:.3f} m in {FRAMES} frames")


BLENDER_SCRIPT = r'''
import bpy, json, sys
path, frame = sys.argv[sys.argv.index("--") + 1], int(sys.argv[-1])
if not hasattr(bpy.app.build_options, "usd") or not bpy.app.build_options.usd:
    print("SURGE_NO_USD"); sys.exit(0)
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.wm.usd_import(filepath=path)
scene = bpy.context.scene
scene.frame_set(frame)
graph = bpy.context.evaluated_depsgraph_get()
found = {"frame_start": scene.frame_start, "frame_end": scene.frame_end, "fps": scene.render.fps, "objects": {}}
for obj in bpy.data.objects:
    if obj.type != "MESH":
        continue
    mesh = obj.evaluated_get(graph).to_mesh()
    found["objects"][obj.name] = {"vertices": len(mesh.vertices), "polygons": len(mesh.polygons),
                                  "world": [list(row) for row in obj.matrix_world]}
print("SURGE_JSON " + json.dumps(found))
'''


def check_blender(run, work):
    blender = shutil.which("blender")
    if not blender:
        print("SKIP: blender is not installed (Debian 12's blender 3.4.1 has no USD importer either)")
        return 77
    script = os.path.join(work, "import_stage.py")
    with open(script, "w") as f:
        f.write(BLENDER_SCRIPT)
    frame = 3
    result = subprocess.run([blender, "-b", "--factory-startup", "--python", script, "--",
                             os.path.join(run, "export", "scene.usda"), str(frame)],
                            capture_output=True, text=True, timeout=300)
    if "SURGE_NO_USD" in result.stdout:
        print("SKIP: this blender was built without USD (bpy.app.build_options.usd is off, as in Debian 12's "
              "blender 3.4.1): no bpy.ops.wm.usd_import")
        return 77
    found = [json.loads(line[11:]) for line in result.stdout.split("\n") if line.startswith("SURGE_JSON ")]
    check(len(found) == 1, f"blender said: {result.stdout[-2000:]} {result.stderr[-2000:]}")
    if not found:
        return check.status()
    found = found[0]
    check((found["frame_start"], found["frame_end"], found["fps"]) == (0, FRAMES, FPS), f"frame range {found}")
    ply, faces = read_ply(frame_ply(run, "surface", frame))
    surface = found["objects"].get("surface", {})
    check(surface.get("vertices") == len(ply["x"]) and surface.get("polygons") == len(faces),
          f"surface at frame {frame}: {surface.get('vertices')} vertices, not {len(ply['x'])}")
    # Blender turns a y-up stage z-up: its world is ours turned 90 degrees about x.
    y_to_z = np.array([[1, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, 0], [0, 0, 0, 1]])
    crate = found["objects"].get("crate")
    check(crate is not None, f"no crate among {list(found['objects'])}")
    if crate:
        _, prims = read_stage(os.path.join(run, "export", "scene.usda"))
        prim = prims["/" + SCENE["name"] + "/bodies/crate"]
        expected = np.eye(4)
        expected[:3, :3] = rotation(*prim["xformOp:orient"][frame])
        expected[:3, 3] = prim["xformOp:translate"][frame]
        error = np.abs(np.array(crate["world"]) - y_to_z @ expected).max()
        check(error < 1e-5, f"the crate's world transform at frame {frame} is {error:.2g} off")
    return check.status()


def main():
    mode, binary = sys.argv[1], sys.argv[2]
    work = os.path.join(sys.argv[3], f"export_usd_test_{mode}")
    run = make_run(binary, work)
    result = surge(binary, "export", run, "--format", "usda")
    check(result.returncode == 2 and "--format" in result.stderr and result.stderr.count("\n") == 1,
          f"unknown format: exit {result.returncode}, stderr {result.stderr!r}")
    result = surge(binary, "export", run, "--format", "usd")
    check(result.returncode == 0 and os.listdir(os.path.join(run, "export")) == ["scene.usda"],
          f"export: exit {result.returncode}, {result.stderr}")
    if mode == "blender":
        return check_blender(run, work)
    check_stage(run)
    return check.status()


if __name__ == "__main__":
    sys.exit(main())
