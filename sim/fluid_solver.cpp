#include "sim/fluid_solver.h"

#include "core/errors.h"
#include "sim/dfsph_solver.h"
#include "sim/pbf_solver.h"
#include "sim/wcsph_solver.h"

namespace surge {
namespace {

template <int Dim>
using MakeSolver = std::unique_ptr<FluidSolver<Dim>> (*)(const Scene&, std::shared_ptr<const ColliderShapes>);

template <template <int> class Method, int Dim>
std::unique_ptr<FluidSolver<Dim>> make(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes) {
  return std::make_unique<Method<Dim>>(scene, std::move(shapes));
}

template <int Dim>
struct Registration {
  const char* method;
  MakeSolver<Dim> make;
};

// The registry: one line a method.
template <int Dim>
const Registration<Dim> kMethods[] = {
    {"pbf", &make<PbfSolver, Dim>},
    {"wcsph", &make<WcsphSolver, Dim>},
    {"dfsph", &make<DfsphSolver, Dim>},
};

}  // namespace

template <int Dim>
std::unique_ptr<FluidSolver<Dim>> makeFluidSolver(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes) {
  for (const Registration<Dim>& registration : kMethods<Dim>)
    if (scene.solver.method == registration.method) return registration.make(scene, std::move(shapes));
  throw InputError(scene.source, "solver.method", "no solver is registered as \"" + scene.solver.method + "\"");
}

std::vector<std::string> fluidSolverMethods() {
  std::vector<std::string> methods;
  for (const Registration<3>& registration : kMethods<3>) methods.push_back(registration.method);
  return methods;
}

template std::unique_ptr<FluidSolver<2>> makeFluidSolver<2>(const Scene&, std::shared_ptr<const ColliderShapes>);
template std::unique_ptr<FluidSolver<3>> makeFluidSolver<3>(const Scene&, std::shared_ptr<const ColliderShapes>);

}  // namespace surge
