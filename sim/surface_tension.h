// Surface tension and adhesion after Akinci, Akinci and Teschner 2013, "Versatile surface tension and adhesion
// for SPH fluids" (solver.surface_tension_model akinci2013), shared by every method: an acceleration each
// method adds where it adds its other non-pressure forces (PBF after its velocity update, DFSPH before its
// density solve, WCSPH to its accelerations), computed at the method's positions with its neighbour lists.
//   colour and normal    c_i = V sum_j W_ij (self included), n_i = h V sum_j grad W_ij (eq. 5), W the cubic
//                        spline of support h, V the rest lattice's volume (c = 1 inside the lattice)
//   cohesion             a_ij = -gamma m C(|x_ij|) x_ij / |x_ij|, C of eq. 2 (in 2D one power of h less)
//   curvature            a_ij = -gamma (n_i - n_j) (eq. 4)
//   a_i = sum_j K_ij (cohesion + curvature), K_ij = 2 / (c_i + c_j) (eq. 6, rho_0 / rho by the colour)
//   adhesion             a_i = -beta rho_0 sum_b V A(|x_ib|) x_ib / |x_ib| (eq. 7) over the lattice continued
//                        beyond each collider or body with adhesion, tabulated by distance as its walls are
// gamma is set from sigma (N/m) by Kirkwood and Buff's formula on the rest lattice (tensionPerGamma): the
// tension of a flat slab of the lattice per unit gamma; beta from `adhesion` a = W_a / (2 sigma), the work of
// adhesion against the fluid's work of cohesion, by the same sums (Young: cos theta = 2 a - 1), times the share
// a drop on a plate measures at the kernel's support (adhesionCalibration).
// Several fluids: each fluid's particles pull together with its own gamma (from its sigma and its particles'
// mass), and their colour and normals count the same fluid's neighbours only, so each fluid sees another as it
// sees air and their interface holds sigma_1 + sigma_2; adhesion pulls each fluid by its own sigma.
// docs/surface-tension.md has the derivation and what it measures. Every loop gathers: the same bytes at any
// thread count. A scene without surface tension or adhesion holds no channel and runs no pass.
#pragma once

#include <cmath>
#include <vector>

#include "core/ply.h"
#include "core/scene.h"
#include "sim/colliders.h"
#include "sim/kernels.h"
#include "sim/measures.h"
#include "sim/neighbor_grid.h"

namespace surge {

// The largest sigma of the scene's fluids (fluids[i].surface_tension), 0 without.
double sceneSurfaceTension(const Scene& scene);
// True if some collider or body has adhesion.
bool sceneHasAdhesion(const Scene& scene);
// The share of beta (from Young's work of adhesion) with which the drop on a plate meets Young's angle, at a
// kernel support of `spacings` particle spacings: measured in 3D at 2 (1), 2.5 (0.75) and 3 (0.9), in 2D at 3.5
// (1.15, PBF's 2D support, in PBF) and 3.75 (0.9, DFSPH's and WCSPH's, in DFSPH); 0 elsewhere, where beta is taken
// whole and, in 3D, surge sim notes it (docs/surface-tension.md, "The adhesion by support", "The calibration's
// lattice", "PBF 2D at 3.5 spacings").
double adhesionCalibration(int dimensions, double spacings);
// The most energy surface tension can release into the fluid of `initial` (the scene's lattice at t = 0): sigma
// times its surface, counted as the lattice cells' faces that have no fluid cell beside them (an upper bound on a
// smooth shape's area). Infinite with emitters, whose jets bring surface of their own; 0 without tension.
double surfaceEnergyBound(const Scene& scene, const ParticleFrame& initial);

template <int Dim>
class SurfaceTension {
 public:
  using VecD = Vec<Dim>;

  SurfaceTension() = default;
  // `mass`: the method's particle mass.
  SurfaceTension(const Scene& scene, float mass);

  // Adhesion comes with surface tension only (it is a share of the fluid's cohesion).
  bool active() const { return gamma_ > 0; }
  float gamma() const { return gamma_; }
  // The capillary step limit (Brackbill, Kothe and Zemach 1992): dt <= sqrt(rho_0 spacing^3 / (2 pi sigma));
  // infinity without surface tension.
  float stableStep() const { return stableStep_; }

  // The accelerations at positions x (neighbour lists of radius h, in x's order), kept for the calls below.
  // `colliders`: for the adhesion; its impulses are recorded as m a `impulseScale` (dt for a velocity change,
  // 1 for a force the caller integrates). `fluid`: each particle's fluid block (empty: one fluid).
  void computeAccelerations(const std::vector<VecD>& x, const NeighborLists& neighbors, Colliders<Dim>& colliders,
                            float impulseScale, const std::vector<uint8_t>& fluid);
  // v_i += dt a_i, counting the work sum m a . (v + dt a / 2) dt; `massRatio`: each particle's mass over the
  // method's (empty: one fluid).
  void kick(std::vector<VecD>& v, float dt, const std::vector<float>& massRatio);
  const std::vector<VecD>& accelerations() const { return accel_; }
  // a_i += the accelerations (WCSPH), and the work over a step dt at velocities v (addWork).
  void addTo(std::vector<VecD>& a) const;
  void addWork(const std::vector<VecD>& v, float dt, const std::vector<float>& massRatio);
  // The work the forces did on the fluid since the last call (J; J/m in 2D): the surface energy they release.
  double takeWork() {
    const double w = work_;
    work_ = 0;
    return w;
  }
  size_t memoryBytes() const;
  // Adds to `virial` each particle's half of the virial of the model's pair forces at x, (1/2) sum_j x_ij . m
  // a_ij (cohesion and curvature; adhesion left out), each pair's half counted by its share inside `ball`: the
  // model's share of the mechanical pressure (FluidSolver::virialPressureWithin). Overwrites the colour and
  // normals the accelerations were computed with.
  void addPairVirials(const std::vector<VecD>& x, const NeighborLists& neighbors, const std::vector<uint8_t>& fluid,
                      const VirialBall<Dim>& ball, std::vector<double>& virial);

  // Kirkwood and Buff: sigma = (1 / 4A) sum_i sum_j (r_n F_n - r_t F_t) over the pairs of a column of a slab of
  // the rest lattice with two free faces (A the column's area, n across the slab, t along it), for gamma = 1.
  static double tensionPerGamma(float spacing, float support, float mass);
  // The work of adhesion per unit beta: the energy per area to pull a half-space of the rest lattice, its first
  // layer half a spacing from a flat wall, off that wall.
  double adhesionWorkPerBeta() const;

 private:
  PeriodicDomain<Dim> periodic_;  // domain.periodic: pairs take their nearest image
  float cohesion(float r) const;  // C(r) of eq. 2
  // colour_ and normal_ at x (eq. 5), counting the particle's own fluid only with several.
  template <bool kSeveral, typename Wrap>
  void colourAndNormals(const std::vector<VecD>& x, const NeighborLists& neighbors, const std::vector<uint8_t>& fluid,
                        const Wrap& sharedWrap);
  // Particle i's pair term from j at offset r, before gamma: K_ij ((n_j - n_i) - m C(|r|) r / |r|) (eq. 6, 4, 1).
  VecD pairTerm(size_t i, size_t j, const VecD& r, float m) const {
    const float length = r.norm();
    VecD pair = normal_[j] - normal_[i];                                            // eq. 4
    if (length > 1e-6f * support_) pair -= (m * cohesion(length) / length) * r;  // eq. 1
    return (2.0f / (colour_[i] + colour_[j])) * pair;                              // eq. 6's K_ij
  }
  float wallAdhesion(float d) const;  // sum_b V A(|x - x_b|) along the normal, a wall at d (table)

  CubicSplineKernel<Dim> kernel_{1.0f};
  float gamma_ = 0, mass_ = 0, volume_ = 0, spacing_ = 0, support_ = 0, restDensity_ = 0, stableStep_ = INFINITY;
  float cohesionScale_ = 0;
  bool adhesive_ = false;
  // By fluid block (one entry for one fluid): gamma, the particles' mass, and per collider (bodies after the
  // colliders) eq. 7's beta rho_0, 0 none.
  std::vector<float> fluidGamma_, fluidMass_;
  std::vector<std::vector<float>> pull_;
  std::vector<float> adhesionTable_;
  float adhesionScale_ = 0;        // table entries per metre
  std::vector<float> colour_;
  std::vector<VecD> normal_, accel_;
  double work_ = 0;
};

extern template class SurfaceTension<2>;
extern template class SurfaceTension<3>;

}  // namespace surge
