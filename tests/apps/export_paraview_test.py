"""surge export --format vtk opened by ParaView itself (pvpython's PVDReader), where ParaView is installed.

The VTK test reads the .pvd files as XML and each .vtp with VTK's reader; this one asks ParaView's own reader of
the series: its time steps (frame / fps), the particle and surface point counts at the last one against the PLY
frames, and the colliders as a multiblock of one block a collider. Exit 77 (ctest's skip) where pvpython is not
installed: Debian's paraview and python3-paraview are not in scripts/setup.sh (440 MB; docs/exchange-formats.md).

Usage: export_paraview_test.py SURGE_BINARY WORK_FOLDER
"""
import json
import os
import shutil
import subprocess
import sys

from export_runs import SCENE, Checks, frame_ply, make_run, read_ply, surge

check = Checks()

PARAVIEW_SCRIPT = r'''
import json, sys
from paraview import servermanager
from paraview.simple import PVDReader
found = {}
for kind in ("particles", "surface", "colliders", "bodies"):
    reader = PVDReader(FileName=sys.argv[1] + "/" + kind + ".pvd")
    times = list(reader.TimestepValues)
    reader.UpdatePipeline(times[-1])
    data = servermanager.Fetch(reader)
    blocks = data.GetNumberOfBlocks() if data.IsA("vtkMultiBlockDataSet") else 0
    points = sum(data.GetBlock(b).GetNumberOfPoints() for b in range(blocks)) if blocks else data.GetNumberOfPoints()
    found[kind] = {"times": times, "class": data.GetClassName(), "blocks": blocks, "points": points}
print("SURGE_JSON " + json.dumps(found))
'''


def main():
    pvpython = shutil.which("pvpython")
    if not pvpython:
        print("SKIP: pvpython is not installed (Debian paraview and python3-paraview, not in scripts/setup.sh)")
        return 77
    binary, work = sys.argv[1], os.path.join(sys.argv[2], "export_paraview_test")
    run = make_run(binary, work)
    result = surge(binary, "export", run, "--format", "vtk")
    if result.returncode != 0:
        print(f"surge export failed: {result.stderr}")
        return 1
    script = os.path.join(work, "open_series.py")
    with open(script, "w") as f:
        f.write(PARAVIEW_SCRIPT)
    result = subprocess.run([pvpython, script, os.path.join(run, "export")], capture_output=True, text=True,
                            timeout=300)
    found = [json.loads(line[11:]) for line in result.stdout.split("\n") if line.startswith("SURGE_JSON ")]
    check(len(found) == 1, f"pvpython said: {result.stdout[-2000:]} {result.stderr[-2000:]}")
    if not found:
        return check.status()
    found = found[0]
    frames, fps = SCENE["output"]["frames"], SCENE["output"]["fps"]
    times = [f / fps for f in range(frames + 1)]
    for kind in ("particles", "surface", "colliders", "bodies"):
        check(found[kind]["times"] == times, f"{kind}: ParaView's time steps {found[kind]['times']}, not {times}")
    for kind in ("particles", "surface"):
        expected = len(read_ply(frame_ply(run, kind, frames))[0]["x"])
        check(found[kind]["points"] == expected, f"{kind} at the last frame: {found[kind]['points']}, not {expected}")
    check(found["colliders"]["class"] == "vtkMultiBlockDataSet" and found["colliders"]["blocks"] == 2,
          f"colliders: {found['colliders']}, not a multiblock of the post and the paddle")
    expected = sum(len(read_ply(path)[0]["x"]) for path in (os.path.join(run, "colliders", "post.ply"),
                                                            frame_ply(run, "colliders", frames, "paddle")))
    check(found["colliders"]["points"] == expected, f"colliders' points {found['colliders']['points']}, not {expected}")
    return check.status()


if __name__ == "__main__":
    sys.exit(main())
