#include "sim/fluid_solver.h"

#include <algorithm>

#include "core/errors.h"
#include "sim/dfsph_solver.h"
#include "sim/pbf_solver.h"
#include "sim/solver_defaults.h"
#include "sim/wcsph_solver.h"

namespace surge {
namespace {

// The registry: one line a method.
std::vector<FluidMethod>& registry() {
  static std::vector<FluidMethod> methods = {
      kPbfMethod,
      kWcsphMethod,
      kDfsphMethod,
  };
  return methods;
}

// What core's scene reader knows of a method (core/scene.h, SolverMethodEntry).
SolverMethodEntry catalogEntry(const FluidMethod& method) {
  return {method.name, method.description, method.declareKeys, method.surfaceTensionSupport2d};
}

// The scene reader learns the methods' names and resolves their defaults wherever the simulator is linked
// (core/scene.h).
bool installInSceneReader() {
  solverDefaults() = &resolveSolverDefaults;
  for (const FluidMethod& method : registry()) solverMethodCatalog().push_back(catalogEntry(method));
  return true;
}
[[maybe_unused]] const bool kInstalled = installInSceneReader();

}  // namespace

const FluidMethod& fluidMethod(const std::string& name, const std::string& source) {
  for (const FluidMethod& method : registry())
    if (name == method.name) return method;
  throw InputError(source, "solver.method", "no solver is registered as \"" + name + "\"");
}

void registerFluidMethod(const FluidMethod& method) {
  for (const FluidMethod& known : registry())
    if (std::string(known.name) == method.name)
      throw std::logic_error(std::string("registerFluidMethod: \"") + method.name + "\" is registered already");
  registry().push_back(method);
  solverMethodCatalog().push_back(catalogEntry(method));
}

void unregisterFluidMethod(const std::string& name) {
  auto& methods = registry();
  methods.erase(std::remove_if(methods.begin(), methods.end(), [&](const FluidMethod& m) { return name == m.name; }),
                methods.end());
  auto& catalog = solverMethodCatalog();
  catalog.erase(std::remove_if(catalog.begin(), catalog.end(),
                               [&](const SolverMethodEntry& entry) { return entry.name == name; }),
                catalog.end());
}

template <int Dim>
std::unique_ptr<FluidSolver<Dim>> makeFluidSolver(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes) {
  const FluidMethod& method = fluidMethod(scene.solver.method, scene.source);
  if constexpr (Dim == 2) return method.make2(scene, std::move(shapes));
  else return method.make3(scene, std::move(shapes));
}

std::vector<std::string> fluidSolverMethods() {
  std::vector<std::string> methods;
  for (const FluidMethod& method : registry()) methods.push_back(method.name);
  return methods;
}

template std::unique_ptr<FluidSolver<2>> makeFluidSolver<2>(const Scene&, std::shared_ptr<const ColliderShapes>);
template std::unique_ptr<FluidSolver<3>> makeFluidSolver<3>(const Scene&, std::shared_ptr<const ColliderShapes>);

}  // namespace surge
