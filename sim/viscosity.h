// Laminar viscosity of a fluid of kinematic viscosity nu (fluids[i].viscosity, m^2/s), shared by every method
// the way surface tension is (sim/surface_tension.h): a change of velocity each method applies where it applies
// its other non-pressure forces (DFSPH before its density solve, PBF after its velocity update), with the
// method's positions and neighbour lists.
//
// The solve is Weiler, Koschier, Brand and Bender 2018's, "A physically consistent implicit viscosity solver for
// SPH fluids"; its operator here is the Laplacian of velocity component by component (Morris et al. 1997's
// form, the one of Weiler's eq. 6 before their eq. 8 turns it into a tensor), over the rest lattice's volume V
// and the cubic spline of the method's support h:
//   nu lap v_i = 2 sum_j V nu_ij F_ij |x_ij|^2 / (|x_ij|^2 + 0.01 (h/2)^2) (v_i - v_j)
//              + 2 nu_i V sum_b F_ib |x_ib|^2 / (|x_ib|^2 + 0.01 (h/2)^2) (v_i - v_b)
// with grad W_ij = F_ij x_ij (F <= 0) and nu_ij the mean of the pair's fluids. Not eq. 8's 2 (d + 2)
// sum_j V (v_ij . x_ij) x_ij F_ij / (|x_ij|^2 + eta): that sum rests on the lattice's fourth moment, which at
// h = 2 spacings is 0.66 of its integral for a shear along a lattice axis and 1.35 at 45 degrees (a shear wave
// decayed at 0.64 of nu's rate); the component-wise sum rests on the second moment, 1.01 of its integral in
// every direction (docs/viscosity.md). solver.viscosity_operator strain takes eq. 8's pair term instead,
//   (d + 2) sum_j V nu_ij F_ij |x_ij|^2 / (|x_ij|^2 + eta) x^_ij x^_ij^T (v_i - v_j),   x^ = x / |x|,
// on each pair's stretching alone: a free surface then carries no traction, so a rope creeps at Trouton's rate,
// buckles and coils, where the component-wise sum lets it squash (docs/viscosity.md). The boundary b is the tank's
// walls and the colliders and bodies as the rest lattice continued beyond them (sim/tank.h), its sum tabulated by the
// distance to a locally flat wall and applied to the normal part of v_i - v_b and, scaled by (1 - viscous_slip), the
// tangential part: 0 is no-slip against the wall's own velocity v_b, 1 free slip.
//
// `implicit` (solver.viscosity_solver, the default for PBF and DFSPH): backward Euler, eq. 12,
//   (I - dt nu lap) v = v*,
// solved matrix-free by conjugate gradients preconditioned by the 2x2 or 3x3 diagonal blocks (block Jacobi: the
// walls' slip couples a particle's components),
// started from v* plus the last step's change (carried between frames, so --resume is exact), stopped when
// |r| <= solver.viscosity_max_error |b - A v*| (the paper's relative residual taken against the step's viscous
// change rather than |b|, so a fluid's uniform motion does not loosen it; the .cpp) or after
// viscosity_max_iterations.
// The matrix is symmetric (one volume V, nu_ij symmetric) and positive definite, so no step limit.
// `explicit` (Morris 1997, WCSPH's default): v += dt nu lap v, stable for dt <= 0.125 (h/2)^2 / nu (and d + 2
// times shorter with the strain's operator).
// Every loop gathers and every dot product is a parallelSum: the same bytes at any thread count. A scene
// without viscosity holds no channel and runs no pass.
#pragma once

#include <cmath>
#include <functional>
#include <vector>

#include "core/scene.h"
#include "sim/colliders.h"
#include "sim/kernels.h"
#include "sim/neighbor_grid.h"
#include "sim/tank.h"

namespace surge {

// nu of fluid block `block` (fluids[i].viscosity). WCSPH's solver.kinematic_viscosity, every fluid's when none
// gives its own, is WCSPH's own pair term (sim/wcsph_solver.h), not this solver's.
double fluidViscosity(const Scene& scene, size_t block);
// True if some fluid has a viscosity.
bool sceneHasViscosity(const Scene& scene);
// The largest of the fluids' nu (0 without viscosity).
double largestViscosity(const Scene& scene);
// solver.viscosity_solver: implicit, explicit, or by default explicit for WCSPH and implicit for the others.
bool implicitViscosity(const Scene& scene);
// The explicit solve's step limit with a kernel of this support: 0.125 (h/2)^2 / nu for the largest nu, d + 2
// times shorter with the strain's operator (Viscosity::stableStep when explicit, and WCSPH's note).
float explicitViscosityStep(const Scene& scene, float support);

template <int Dim>
class Viscosity {
 public:
  using VecD = Vec<Dim>;
  using MatD = Eigen::Matrix<float, Dim, Dim>;

  Viscosity() = default;
  // `support`: the method's neighbour radius.
  Viscosity(const Scene& scene, float support);

  bool active() const { return active_; }
  bool implicit() const { return implicit_; }
  // Explicit: 0.125 (h/2)^2 / nu of the most viscous fluid (Morris et al. 1997); implicit: infinity.
  float stableStep() const { return stableStep_; }
  // CG iterations of the last implicit solve (0 explicit).
  int lastIterations() const { return iterations_; }

  // v at positions x (the neighbour lists of the method's support, in x's order), for a step dt; the drag on
  // each collider and body recorded on `colliders` as impulses. `fluid`: each particle's fluid block, and
  // `massRatio` its mass over `mass` (both empty: one fluid).
  void apply(const std::vector<VecD>& x, std::vector<VecD>& v, const NeighborLists& neighbors,
             const TankWalls<Dim>& walls, Colliders<Dim>& colliders, const std::vector<uint8_t>& fluid, float mass,
             const std::vector<float>& massRatio, float dt);

  // The implicit solve's warm start (its last change of velocity), one channel a component; none explicit.
  void forEachCarriedChannel(const std::function<void(std::vector<float>&)>& visit) {
    if (implicit_)
      for (auto& channel : warm_) visit(channel);
  }
  void resize(size_t n);
  size_t memoryBytes() const;

 private:
  PeriodicDomain<Dim> periodic_;  // domain.periodic: pairs take their nearest image
  // Per pair c_ij = 2 V nu_ij F_ij |x_ij|^2 / (|x_ij|^2 + eta), grad W_ij = F_ij x_ij; per particle the wall
  // tensor B_i (its share of the operator) and B_i v_b.
  void prepare(const std::vector<VecD>& x, const NeighborLists& neighbors, const TankWalls<Dim>& walls,
               const Colliders<Dim>& colliders, const std::vector<uint8_t>& fluid);
  // A wall's share of B_i for a particle of viscosity nu at distance d along the wall's normal.
  MatD wallTensor(float d, const VecD& normal, float keepTangent, float nu) const;
  void recordColliderDrag(const std::vector<VecD>& x, const std::vector<VecD>& v, Colliders<Dim>& colliders,
                          const std::vector<uint8_t>& fluid, float mass, const std::vector<float>& massRatio,
                          float dt) const;
  // out_i = sum_j c_ij (u_i - u_j) + B_i u_i: nu lap u with the walls at rest.
  void laplacian(const std::vector<VecD>& u, const NeighborLists& neighbors, std::vector<VecD>& out) const;
  int solveImplicit(const std::vector<VecD>& x, std::vector<VecD>& v, const NeighborLists& neighbors, float dt);

  bool active_ = false, implicit_ = false;
  CubicSplineKernel<Dim> kernel_{1.0f};
  float scale_ = 0, eta_ = 0, stableStep_ = INFINITY, maxError_ = 0.01f;
  int maxIterations_ = 100, iterations_ = 0;
  std::vector<float> nu_;          // by fluid block
  std::vector<float> keepTangent_;  // by collider (bodies after the colliders): 1 - viscous_slip
  float wallKeepTangent_ = 1;       // the tank's
  FlatWallTable wallTable_;         // the moments of sum_b x_ib grad W_ib^T / (|x_ib|^2 + eta), by distance
  FlatWallTable noSlipTable_;       // the same with each b's share times Morris's 1 + d_b / d_i (the tangential part)
  std::vector<std::vector<float>> pairFactor_;  // c_ij ((d + 2) c_ij with strain), parallel to the lists
  // solver.viscosity_operator strain: the unit x_ij of every pair, parallel to the lists.
  bool strain_ = false;
  std::vector<std::vector<VecD>> pairAxis_;
  std::vector<MatD> wall_, blockInverse_;
  std::vector<VecD> wallDrag_;  // B_i v_b
  std::vector<VecD> start_, residual_, direction_, product_, preconditioned_;
  std::vector<float> warm_[Dim];
};

extern template class Viscosity<2>;
extern template class Viscosity<3>;

}  // namespace surge
