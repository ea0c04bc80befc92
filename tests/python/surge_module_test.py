"""The `surge` Python module (issue 36): a run from Python writes the same bytes as `surge sim`, its arrays are
views of the solver's memory that agree with the frames, read_frame gives each property its own type, and the
surface and render stages run on a folder. Run by ctest with PYTHONPATH at build/python (tests/CMakeLists.txt)."""
import os
import subprocess

import numpy as np
import pytest

import surge

SOURCE = os.environ["SURGE_SOURCE_DIR"]
BINARY = os.environ["SURGE_BINARY"]
SCENE = os.path.join(SOURCE, "scenes", "dam_break_2d.json")


def frames(folder):
    return sorted(os.listdir(os.path.join(folder, "particles")))


@pytest.mark.parametrize("method", ["pbf", "dfsph"])
def test_a_run_from_python_writes_the_same_bytes_as_surge_sim(tmp_path, method):
    sets = ["output.frames=4", f"solver.method={method}"]
    cli = tmp_path / "cli"
    subprocess.run([BINARY, "sim", SCENE, "--quiet", "--out", str(cli)] + sum((["--set", s] for s in sets), []),
                   check=True)
    sim = surge.Simulation(SCENE, sets, out=str(tmp_path / "py"))
    assert sim.frame == 0 and sim.time == 0.0
    steps = 0
    while sim.step_frame():
        steps += 1
    assert steps == 4 and sim.frame == 4
    assert sim.time == pytest.approx(4 / 30)
    assert sim.step_frame() is False
    assert frames(cli) == frames(tmp_path / "py")
    for name in frames(cli):
        assert (cli / "particles" / name).read_bytes() == (tmp_path / "py" / "particles" / name).read_bytes(), name
    for name in os.listdir(cli / "solver") if (cli / "solver").exists() else []:
        assert (cli / "solver" / name).read_bytes() == (tmp_path / "py" / "solver" / name).read_bytes(), name


def test_the_arrays_are_views_of_the_solver_and_match_the_frame(tmp_path):
    sim = surge.Simulation(SCENE, ["output.frames=2"], out=str(tmp_path))
    sim.step_frame()
    x, v, ids = sim.positions(), sim.velocities(), sim.ids()
    assert x.shape == (len(ids), 2) and v.shape == x.shape
    assert x.dtype == np.float32 and ids.dtype == np.uint32
    assert not x.flags["OWNDATA"] and not ids.flags["OWNDATA"]
    assert np.shares_memory(x, sim.positions())  # no copy: the same memory each time
    frame = surge.read_frame(str(tmp_path / "particles" / "frame_00001.ply"))
    assert frame["x"].dtype == np.float32 and frame["id"].dtype == np.uint32
    assert set(["x", "y", "z", "vx", "vy", "vz", "id"]) <= set(frame)
    np.testing.assert_array_equal(frame["x"], x[:, 0])
    np.testing.assert_array_equal(frame["y"], x[:, 1])
    np.testing.assert_array_equal(frame["vy"], v[:, 1])
    np.testing.assert_array_equal(frame["id"], ids)
    assert np.all(frame["z"] == 0)
    # The water has started to fall and run: it moves, and no particle is lost or doubled.
    assert np.abs(v).max() > 0.1
    assert len(np.unique(ids)) == len(ids)


def test_surface_and_render_run_on_a_folder(tmp_path):
    sim = surge.Simulation(SCENE, ["output.frames=1"], out=str(tmp_path))
    sim.step_frame()
    surge.surface(str(tmp_path), frames="1:1")
    assert (tmp_path / "surface" / "frame_00001.ply").stat().st_size > 1000
    assert (tmp_path / "surface" / "frame_00001.vdb").stat().st_size > 1000
    surge.render(str(tmp_path), frames="1:1", renderer="gl")
    png = (tmp_path / "frames" / "frame_00001.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"


def test_bad_input_names_the_file_or_key(tmp_path):
    with pytest.raises(ValueError, match="missing.json"):
        surge.Simulation(str(tmp_path / "missing.json"))
    with pytest.raises(ValueError, match="solver.iterations"):
        surge.Simulation(SCENE, ["solver.iterations=-3"], out=str(tmp_path / "bad"))
    with pytest.raises(ValueError, match="scene.json"):
        surge.surface(str(tmp_path / "nothing_here"))


def test_a_resume_goes_on_only_with_the_physics_it_started_with(tmp_path):
    # As `surge sim --resume`: the folder's scene must have the same physics; more frames may be asked for.
    sim = surge.Simulation(SCENE, ["output.frames=1"], out=str(tmp_path))
    while sim.step_frame():
        pass
    with pytest.raises(ValueError, match="solver.iterations"):
        surge.Simulation(SCENE, ["output.frames=2", "solver.iterations=3"], out=str(tmp_path), resume=True)
    sim = surge.Simulation(SCENE, ["output.frames=2"], out=str(tmp_path), resume=True)
    assert sim.frame == 1
    while sim.step_frame():
        pass
    assert frames(tmp_path) == ["frame_00000.ply", "frame_00001.ply", "frame_00002.ply"]


COLUMN = """{"name": "column", "dimensions": 2, "domain": {"min": [0, 0], "max": [0.2, 0.4]},
  "particle_spacing": 0.01, "fluids": [{"box": {"min": [0, 0], "max": [0.2, 0.3]}}], "gravity": [0, -9.81],
  "solver": {"method": "dfsph"}, "output": {"fps": 300, "frames": 300}}"""


@pytest.mark.parametrize("method", ["dfsph", "wcsph"])
def test_pressure_within_a_column_carries_the_weight_above(tmp_path, method):
    # A 2D column 0.3 m deep, 0.2 m wide, from a lattice at rest: at rest the pressure at height y carries the
    # weight of the water above it, g m N(above y) / width, and a disc's mean pressure is its centre's where the
    # pressure is linear in y. The column rings (its start holds no pressure; WCSPH's breathes by +-36%), so the
    # check is on the mean over 1/3 to 1 s, every 1/300 s: measured 0.991 and 1.001 (DFSPH), 0.994 and 0.995
    # (WCSPH) at 0.24 and 0.2 m deep. 3%: the ringing's unfinished cycles move such means by about 1% (sampled
    # 30 times a second against rho g times the depth below the top particle, DFSPH's read 1.005 and 1.004,
    # WCSPH's 1.03 over 1 s and 1.01 over 2 s). Seen failing without DFSPH's divergence solve's pressure (0.969).
    scene = tmp_path / "column.json"
    scene.write_text(COLUMN)
    sim = surge.Simulation(str(scene), [f"solver.method={method}"], out=str(tmp_path / "run"))
    mass = 1000 * 0.01 ** 2  # kg per metre of depth
    ratios = []
    while sim.step_frame():
        if sim.time <= 1 / 3:
            continue
        y = sim.positions()[:, 1]
        ratios.append([sim.pressure_within([0.1, h], 0.04) / (9.81 * mass * np.count_nonzero(y > h) / 0.2)
                       for h in (0.06, 0.1)])
    mean = np.mean(ratios, axis=0)
    print(method, mean)
    assert mean == pytest.approx([1, 1], abs=0.03)


def test_pressure_within_leaves_the_run_as_it_was(tmp_path):
    # Asking between frames changes no byte of the frames; PBF has no pressures; a centre of the wrong length is
    # a ValueError.
    sets = ["output.frames=3", "solver.method=wcsph"]
    quiet = surge.Simulation(SCENE, sets, out=str(tmp_path / "quiet"))
    asked = surge.Simulation(SCENE, sets, out=str(tmp_path / "asked"))
    while quiet.step_frame():
        asked.step_frame()
        assert asked.pressure_within([0.5, 0.3], 0.1) > 0
    assert frames(tmp_path / "quiet") == frames(tmp_path / "asked")
    for name in frames(tmp_path / "quiet"):
        assert (tmp_path / "quiet" / "particles" / name).read_bytes() == \
            (tmp_path / "asked" / "particles" / name).read_bytes(), name
    pbf = surge.Simulation(SCENE, ["output.frames=1"], out=str(tmp_path / "pbf"))
    assert np.isnan(pbf.pressure_within([0.5, 0.3], 0.1))
    with pytest.raises(ValueError, match="centre"):
        asked.pressure_within([0.5, 0.3, 0.0], 0.1)
