// A fourth fluid method that exists only for the tests: particles fall freely under gravity (symplectic Euler,
// no pressure) and stop at the tank's walls. It is what a new method costs: this file and one
// registerFluidMethod line (tests/sim/ballistic_method_test.cpp); the particle core does the rest.
#pragma once

#include <memory>

#include "sim/fluid_solver.h"
#include "sim/particle_solver.h"

namespace surge {

template <int Dim>
class BallisticSolver final : public ParticleSolver<Dim> {
 public:
  explicit BallisticSolver(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes = nullptr)
      : ParticleSolver<Dim>(scene, std::move(shapes), sphRestLattice<Dim>(scene)),
        kernel_(sphKernel<Dim>(scene)),
        substeps_(scene.solver.substeps) {}

  int fixedSubsteps() const override { return substeps_; }
  float stableTimeStep() override { return INFINITY; }
  void beginFrame(double) override {}
  long step(float dt, double time) override {
    const auto external = this->externalForces(dt, time);
    for (size_t i = 0; i < this->size(); ++i) external.kick(this->x_[i], this->v_[i]);
    driftAgainstSolids(this->x_, this->v_, dt, this->mass_, this->massRatio_, this->colliders_, this->walls_);
    return this->endStep();
  }
  FluidMeasures measure() override {
    this->reorderByCell(this->x_);
    this->findNeighborsOf(this->x_, kernel_.radius());
    return kernel_.visit([&](const auto& kernel) {
      return this->measureWith([&](float r2) { return kernel.value(std::sqrt(r2)); });
    });
  }
  int lastIterations() const override { return 0; }

 private:
  void resizeChannels(size_t) override {}

  SphKernel<Dim> kernel_;
  int substeps_;
};

inline const FluidMethod kBallisticMethod = {
    "ballistic", "free fall, for the tests", &makeMethod<BallisticSolver, 2>, &makeMethod<BallisticSolver, 3>, 100,
    200, [](const Scene& scene) { return std::max(1, scene.solver.substeps); }, nullptr, nullptr, nullptr};

}  // namespace surge
