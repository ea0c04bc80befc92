// The `surge` Python module (pybind11): a simulation stepped a frame at a time with its particles as NumPy arrays
// over the solver's own memory, a particle frame read as a dict of arrays, and the surface and render stages run
// on a folder. The same libraries and the same frame loop as the `surge` command (sim/simulation.h,
// SimulationRun), so a run from Python writes the same bytes as `surge sim`. docs/python.md has a study.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <optional>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/files.h"
#include "core/parallel.h"
#include "core/ply.h"
#include "core/progress.h"
#include "core/scene.h"
#include "geometry/collider_shape.h"
#include "render/renderer.h"
#include "sim/simulation.h"
#include "surface/surfacer.h"

namespace py = pybind11;

namespace surge {
namespace {

class Simulation {
 public:
  Simulation(const std::string& scenePath, const std::vector<std::string>& overrides,
             const std::optional<std::string>& out, bool resume, int threads)
      : threads_(threads) {
    const Scene scene = loadScene(scenePath, overrides);
    dir_ = out ? fs::path(*out) : fs::path("out") / scene.name;
    const ThreadLimit limit(threads_);
    const std::shared_ptr<const ColliderShapes> shapes = buildColliderShapes(scene);
    checkSimulationStart(scene, shapes);
    prepareSimulationFolder(scene, dir_, resume);
    run_ = SimulationRun::start(scene, shapes, dir_, resume);
  }

  bool stepFrame() {
    const ThreadLimit limit(threads_);
    py::gil_scoped_release unlocked;  // other Python threads go on while the frame runs
    return run_->stepFrame();
  }

  // Views of the solver's memory, kept alive by `self`; a step reorders and moves them, so they hold until the
  // next step_frame().
  py::array positions(py::object self) const { return vectors(run_->positions(), self); }
  py::array velocities(py::object self) const { return vectors(run_->velocities(), self); }
  py::array ids(py::object self) const {
    return py::array_t<uint32_t>({py::ssize_t(run_->size())}, {py::ssize_t(sizeof(uint32_t))}, run_->ids(), self);
  }

  double pressureWithin(const std::vector<double>& centre, double radius) const {
    if (int(centre.size()) != run_->dimensions())
      throw py::value_error("pressure_within: centre has " + std::to_string(centre.size()) + " values, the scene " +
                            std::to_string(run_->dimensions()) + " dimensions");
    if (!(radius > 0)) throw py::value_error("pressure_within: radius must be above 0");
    const ThreadLimit limit(threads_);
    return run_->pressureWithin(centre, radius);
  }

  int frame() const { return run_->frame(); }
  double time() const { return run_->time(); }
  int dimensions() const { return run_->dimensions(); }
  std::string folder() const { return dir_.string(); }

 private:
  py::array vectors(const float* data, py::object self) const {
    const py::ssize_t n = py::ssize_t(run_->size()), d = run_->dimensions();
    return py::array_t<float>({n, d}, {py::ssize_t(d * sizeof(float)), py::ssize_t(sizeof(float))}, data, self);
  }

  int threads_ = 0;
  fs::path dir_;
  std::unique_ptr<SimulationRun> run_;
};

// Every property of a particle frame as a NumPy array of its own type (core/ply.h, readVertexColumns).
py::dict readFrame(const std::string& path) {
  py::dict columns;
  for (const PlyColumn& column : readVertexColumns(path)) {
    const std::string& t = column.type;
    const py::dtype type = t == "float" || t == "float32" ? py::dtype::of<float>()
                           : t == "double" || t == "float64" ? py::dtype::of<double>()
                           : t == "uint" || t == "uint32"    ? py::dtype::of<uint32_t>()
                           : t == "int" || t == "int32"      ? py::dtype::of<int32_t>()
                           : t == "uchar" || t == "uint8"    ? py::dtype::of<uint8_t>()
                           : t == "ushort" || t == "uint16"  ? py::dtype::of<uint16_t>()
                                                             : py::dtype::of<double>();
    py::array values(py::dtype::of<double>(), {py::ssize_t(column.values.size())}, column.values.data());
    columns[py::str(column.name)] = values.attr("astype")(type);
  }
  return columns;
}

FrameRange rangeOf(const std::string& frames) { return frames.empty() ? FrameRange{} : FrameRange::parse(frames); }

Scene sceneOf(const std::string& folder, const std::vector<std::string>& overrides) {
  const fs::path path = fs::path(folder) / "scene.json";
  if (!fs::exists(path)) throw InputError(folder, "scene.json", "missing: not an output folder of surge sim");
  return loadScene(path, overrides);
}

}  // namespace
}  // namespace surge

PYBIND11_MODULE(surge, m) {
  using namespace surge;
  m.doc() = "Surge: particle fluids from a scene file (PBF, DFSPH, WCSPH), surfaced with OpenVDB and rendered";
  // Bad input (a scene, a file, a key) is a ValueError with the command's one line; a failure while running
  // (a diverged simulation) a RuntimeError.
  py::register_exception<InputError>(m, "InputError", PyExc_ValueError);

  py::class_<Simulation>(m, "Simulation")
      .def(py::init<const std::string&, const std::vector<std::string>&, const std::optional<std::string>&, bool, int>(),
           py::arg("scene_path"), py::arg("overrides") = std::vector<std::string>{}, py::arg("out") = py::none(),
           py::arg("resume") = false, py::arg("threads") = 0,
           "Sets the scene up as `surge sim` does (overrides as --set takes them, key.path=value), writing frame 0 "
           "into `out` (default out/<scene name>)")
      .def("step_frame", &Simulation::stepFrame, "Simulates and writes the next frame; False after the last")
      .def("positions", [](py::object self) { return self.cast<const Simulation&>().positions(self); },
           "(n, dimensions) float32 view of the particles' positions, in the solver's order, until the next step")
      .def("velocities", [](py::object self) { return self.cast<const Simulation&>().velocities(self); },
           "(n, dimensions) float32 view of the velocities, in the order of positions()")
      .def("ids", [](py::object self) { return self.cast<const Simulation&>().ids(self); },
           "(n,) uint32 view of the particles' ids (each keeps its id for life), in the order of positions()")
      .def("pressure_within", &Simulation::pressureWithin, py::arg("centre"), py::arg("radius"),
           "Irving and Kirkwood's mechanical pressure in the ball (a disc in 2D) of `radius` about `centre` at the "
           "newest frame: every pair force's virial by the share of its segment inside, plus the momentum flux of "
           "the particles inside relative to their mean, over d times the ball's volume (Pa; N/m in 2D; NaN for "
           "PBF, which has no pressures). Asking does not change the run")
      .def_property_readonly("frame", &Simulation::frame, "the newest frame written")
      .def_property_readonly("time", &Simulation::time, "its time in seconds")
      .def_property_readonly("dimensions", &Simulation::dimensions)
      .def_property_readonly("folder", &Simulation::folder, "where the frames go");

  m.def("read_frame", &readFrame, py::arg("ply_path"),
        "A particle frame (particles/frame_NNNNN.ply) as a dict of NumPy arrays, one per property");
  m.def(
      "surface",
      [](const std::string& folder, const std::string& frames, const std::vector<std::string>& overrides) {
        const Scene scene = sceneOf(folder, overrides);
        py::gil_scoped_release unlocked;
        Progress quiet;
        checkOutputFolder(folder);
        surfaceFrames(folder, scene, rangeOf(frames), quiet, false);
      },
      py::arg("folder"), py::arg("frames") = "", py::arg("overrides") = std::vector<std::string>{},
      "The surface stage on a run's folder (`surge surface`): surface/frame_NNNNN.vdb and .ply; frames as 'A:B'");
  m.def(
      "render",
      [](const std::string& folder, const std::string& frames, const std::string& renderer,
         const std::vector<std::string>& overrides) {
        const Scene scene = sceneOf(folder, overrides);
        py::gil_scoped_release unlocked;
        Progress quiet;
        checkOutputFolder(folder);
        RenderOptions options;
        options.renderer = renderer;
        renderFrames(folder, scene, rangeOf(frames), quiet, options);
      },
      py::arg("folder"), py::arg("frames") = "", py::arg("renderer") = "",
      py::arg("overrides") = std::vector<std::string>{},
      "The render stage on a run's folder (`surge render`): frames/frame_NNNNN.png, by the path tracer ('embree', "
      "3D's default) or the rasteriser ('gl', 2D's)");
}
