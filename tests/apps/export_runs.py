"""What the export tests share: a small 3D run to export (a standing and a keyframed collider, a body, a surface
with velocities), its PLY files read with numpy, the surge binary run quietly, and a list of failed checks."""
import importlib
import json
import os
import shutil
import subprocess
import sys

DEBIAN_PACKAGES = {"numpy": "python3-numpy", "vtk": "python3-vtk9"}


def require(*names):
    """The modules named, imported; where one is missing, exit 77 (ctest's skip) naming its Debian package."""
    try:
        return [importlib.import_module(name) for name in names]
    except ImportError as missing:
        top = (missing.name or "").split(".")[0]
        print(f"SKIP: {top} is not installed (Debian {DEBIAN_PACKAGES.get(top, top)}; scripts/setup.sh)")
        sys.exit(77)


np, = require("numpy")

SCENE = {
    "name": "export_check", "dimensions": 3,
    "domain": {"min": [0, 0, 0], "max": [0.6, 0.5, 0.4]},
    "particle_spacing": 0.025,
    "fluids": [{"box": {"min": [0, 0, 0], "max": [0.3, 0.25, 0.4]}, "color": [0.9, 0.5, 0.1]}],
    "colliders": [
        {"name": "post", "shape": "cylinder", "position": [0.5, 0.15, 0.2], "radius": 0.04, "height": 0.3},
        {"name": "paddle", "shape": "box", "size": [0.03, 0.2, 0.3], "position": [0.4, 0.2, 0.2],
         "motion": [{"time": 0.0, "position": [0.4, 0.2, 0.2]},
                    {"time": 0.2, "position": [0.45, 0.2, 0.2], "rotation": {"axis": [0, 1, 0], "degrees": 20}}]}],
    "bodies": [{"name": "crate", "shape": "box", "position": [0.15, 0.38, 0.2], "size": [0.08, 0.05, 0.08],
                "density": 400}],
    "surface": {"mesh_velocity": 1},
    "output": {"fps": 25, "frames": 5},
}

def read_ply(path):
    """The vertex properties of a binary little-endian PLY as numpy columns, and its faces (a list of arrays)."""
    with open(path, "rb") as f:
        header = []
        while True:
            line = f.readline().decode("ascii").strip()
            header.append(line)
            if line == "end_header":
                break
        body = f.read()
    types = {"float": "<f4", "uint": "<u4", "uchar": "u1", "int": "<i4", "double": "<f8"}
    elements, current = [], None
    for line in header:
        words = line.split()
        if words[0] == "element":
            current = [words[1], int(words[2]), []]
            elements.append(current)
        elif words[0] == "property":
            current[2].append((words[-1], words[1:-1]))
    columns, faces, at = {}, [], 0
    for name, count, properties in elements:
        if name == "vertex":
            dtype = np.dtype([(p, types[t[0]]) for p, t in properties])
            records = np.frombuffer(body, dtype=dtype, count=count, offset=at)
            at += dtype.itemsize * count
            columns = {p: records[p] for p, _ in properties}
        elif name == "face":
            for _ in range(count):
                n = body[at]
                faces.append(np.frombuffer(body, dtype="<u4", count=n, offset=at + 1))
                at += 1 + 4 * n
    return columns, faces


def surge(binary, *arguments):
    return subprocess.run([binary, *arguments, "--quiet"], capture_output=True, text=True)


def make_run(binary, work):
    """Simulates and surfaces SCENE into work/run (work made anew); returns the run folder, or raises."""
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    scene_path = os.path.join(work, "scene.json")
    with open(scene_path, "w") as f:
        json.dump(SCENE, f)
    run = os.path.join(work, "run")
    for step in (["sim", scene_path, "--out", run], ["surface", run]):
        result = surge(binary, *step)
        if result.returncode != 0:
            raise RuntimeError(f"surge {step[0]} failed: {result.stderr}")
    return run


def frame_ply(run, kind, frame, name=""):
    """The PLY of a frame: run/kind/frame_NNNNN.ply, or run/kind/name/frame_NNNNN.ply for a solid."""
    return os.path.join(run, kind, name, f"frame_{frame:05d}.ply")


class Checks:
    """Failed checks, printed as they fail; the test's exit status at the end."""

    def __init__(self):
        self.failures = []

    def __call__(self, condition, what):
        if not condition:
            self.failures.append(what)
            print("FAIL:", what)

    def status(self):
        print(f"{'FAILED' if self.failures else 'passed'}: {len(self.failures)} failures")
        return 1 if self.failures else 0
