#include "sim/viscosity.h"

#include <algorithm>

#include "core/parallel.h"

namespace surge {
namespace {

// Entries of the wall table across the support, as the tank's flat-wall table.
constexpr int kWallTableSize = 64;

template <int Dim>
using Mat = Eigen::Matrix<float, Dim, Dim>;

template <typename VecD>
double dot(const std::vector<VecD>& a, const std::vector<VecD>& b) {
  return parallelSum<double>(0, a.size(), [&](size_t begin, size_t end) {
    double sum = 0;
    for (size_t i = begin; i < end; ++i) sum += double(a[i].dot(b[i]));
    return sum;
  });
}

}  // namespace

double fluidViscosity(const Scene& scene, size_t block) { return scene.fluids[block].viscosity; }

bool sceneHasViscosity(const Scene& scene) {
  for (size_t f = 0; f < scene.fluids.size(); ++f)
    if (fluidViscosity(scene, f) > 0) return true;
  return false;
}

double largestViscosity(const Scene& scene) {
  double most = 0;
  for (size_t f = 0; f < scene.fluids.size(); ++f) most = std::max(most, fluidViscosity(scene, f));
  return most;
}

// The strain's pair blocks (d + 2) x^ x^^T are at most d + 2 times the component-wise identity, and so is its
// operator's largest eigenvalue: a step that bound shorter is as stable (WCSPH's explicit honey rope diverged at
// Morris's).
float explicitViscosityStep(const Scene& scene, float support) {
  const float smoothing = 0.5f * support;
  const float most = static_cast<float>(largestViscosity(scene));  // the rounding keeps the order: the floats' max
  const bool strain = scene.solver.viscosity_operator == "strain";
  return 0.125f * smoothing * smoothing / most / (strain ? scene.dimensions + 2 : 1);
}

bool implicitViscosity(const Scene& scene) {
  const std::string& chosen = scene.solver.viscosity_solver;
  return chosen == "default" ? scene.solver.method != "wcsph" : chosen == "implicit";
}

template <int Dim>
Viscosity<Dim>::Viscosity(const Scene& scene, float support) {
  if (!sceneHasViscosity(scene)) return;
  active_ = true;
  periodic_ = PeriodicDomain<Dim>(scene);
  implicit_ = implicitViscosity(scene);
  strain_ = scene.solver.viscosity_operator == "strain";
  kernel_ = CubicSplineKernel<Dim>(support);
  const float spacing = static_cast<float>(scene.particle_spacing);
  const float smoothing = 0.5f * support;
  eta_ = 0.01f * smoothing * smoothing;
  scale_ = 2.0f * latticeVolume<Dim>(spacing, kernel_);  // 2 V of the component-wise Laplacian
  maxError_ = static_cast<float>(scene.solver.viscosity_max_error);
  maxIterations_ = scene.solver.viscosity_max_iterations;
  for (size_t f = 0; f < scene.fluids.size(); ++f) nu_.push_back(static_cast<float>(fluidViscosity(scene, f)));
  if (!implicit_) stableStep_ = explicitViscosityStep(scene, support);
  wallKeepTangent_ = static_cast<float>(1 - scene.viscous_slip);
  for (const ColliderSettings& c : scene.colliders) keepTangent_.push_back(static_cast<float>(1 - c.viscous_slip));
  for (const BodySettings& b : scene.bodies) keepTangent_.push_back(static_cast<float>(1 - b.solid.viscous_slip));

  // The moments of x grad W^T / (|x|^2 + eta) over the lattice beyond a flat wall at distance d: their trace is
  // the wall's share of sum_b F r^2 / (r^2 + eta).
  const int reach = static_cast<int>(std::ceil(support / spacing)) + 1;
  for (auto* table : {&wallTable_.weight, &wallTable_.gradient, &wallTable_.normalMoment, &wallTable_.tangentMoment})
    table->assign(kWallTableSize + 1, 0.0f);
  wallTable_.scale = kWallTableSize / support;
  const auto none = [](const VecD&) { return 0.0f; };
  const auto damped = [&](const VecD& r) -> VecD {
    return kernel_.gradientFactor(r.norm()) / (r.squaredNorm() + eta_) * r;
  };
  noSlipTable_ = wallTable_;
  for (int t = 0; t <= kWallTableSize; ++t) {
    const float d[1] = {support * t / kWallTableSize};
    double g[3], moments[4];
    TankWalls<Dim>::sumBeyond(1, d, spacing, reach, none, damped, g, moments);
    wallTable_.normalMoment[t] = static_cast<float>(moments[0]);
    wallTable_.tangentMoment[t] = static_cast<float>(moments[1]);
    // Morris et al. 1997's boundary velocities for no slip: a boundary particle d_b beyond the wall moves at
    // -(d_b / d_i) of particle i's velocity along the wall (relative to the wall's), continuing a shear through
    // zero at the wall, so the pair's relative velocity is (1 + d_b / d_i) times i's. Boundary particles at rest
    // instead put the no-slip plane about half a spacing beyond the wall (Poiseuille's peak 12% fast). d_i is
    // at least a particle radius (the walls' clamp), so the factor stays below 1 + support / radius.
    const float di = std::max(d[0], 0.5f * spacing);
    const auto extrapolated = [&](const VecD& r) -> VecD { return (1.0f + (r[0] - d[0]) / di) * damped(r); };
    TankWalls<Dim>::sumBeyond(1, d, spacing, reach, none, extrapolated, g, moments);
    noSlipTable_.normalMoment[t] = static_cast<float>(moments[0]);
    noSlipTable_.tangentMoment[t] = static_cast<float>(moments[1]);
  }
}

template <int Dim>
void Viscosity<Dim>::resize(size_t n) {
  if (!implicit_) return;
  for (auto& channel : warm_) channel.assign(n, 0.0f);
}

template <int Dim>
size_t Viscosity<Dim>::memoryBytes() const {
  size_t bytes = 0;
  for (const auto& chunk : pairFactor_) bytes += chunk.capacity() * sizeof(float);
  for (const auto& chunk : pairAxis_) bytes += chunk.capacity() * sizeof(VecD);
  bytes += (wall_.capacity() + blockInverse_.capacity()) * sizeof(MatD);
  for (const auto* channel : {&wallDrag_, &start_, &residual_, &direction_, &product_, &preconditioned_})
    bytes += channel->capacity() * sizeof(VecD);
  for (const auto& channel : warm_) bytes += channel.capacity() * sizeof(float);
  return bytes;
}

// A wall's share of B_i at distance d along its normal: the weight sum_b 2 V nu F r^2 / (r^2 + eta) from the
// normal moment and the tangential ones, on the normal part of the relative velocity and, kept by
// 1 - viscous_slip, on the tangential part (the no-slip table's extrapolated boundary velocities). The strain's
// form takes (d + 2) times each moment on its own part: sum_b F (r . n)^2 / (r^2 + eta) n n^T and its tangential
// twin, the lattice beyond a flat wall holding no cross terms.
template <int Dim>
typename Viscosity<Dim>::MatD Viscosity<Dim>::wallTensor(float d, const VecD& normal, float keepTangent,
                                                         float nu) const {
  float normalMoment, tangentMoment, noSlipNormal, noSlipTangent;
  wallTable_.moments(d, normalMoment, tangentMoment);
  noSlipTable_.moments(d, noSlipNormal, noSlipTangent);
  const MatD across = normal * normal.transpose();
  const float weight = scale_ * nu * (strain_ ? (Dim + 2) * normalMoment : normalMoment + (Dim - 1) * tangentMoment);
  const float noSlipWeight =
      scale_ * nu * (strain_ ? (Dim + 2) * noSlipTangent : noSlipNormal + (Dim - 1) * noSlipTangent);
  return weight * across + (keepTangent * noSlipWeight) * (MatD::Identity() - across);
}

template <int Dim>
void Viscosity<Dim>::prepare(const std::vector<VecD>& x, const NeighborLists& neighbors, const TankWalls<Dim>& walls,
                             const Colliders<Dim>& colliders, const std::vector<uint8_t>& fluid) {
  const size_t n = x.size();
  sizeForPairs(neighbors, pairFactor_);
  wall_.resize(n);
  wallDrag_.resize(n);
  if (strain_) sizeForPairs(neighbors, pairAxis_);
  const VecD lower = walls.domainMin(), upper = walls.domainMax();
  const float reach = kernel_.radius();
  const bool several = !fluid.empty();
  const bool colliding = !colliders.empty();
  periodic_.withNearestImage([&](const auto& sharedWrap) {
  parallelFor(0, n, [&](size_t b, size_t e) {
    const auto wrap = sharedWrap;  // the thread's own copy (sim/periodic.h)
    for (size_t i = b; i < e; ++i) {
      const VecD xi = x[i];
      const float nuI = nu_[several ? fluid[i] : 0];
      float* c = pairFactor_[i / NeighborLists::kChunk].data() + neighbors.start(i);
      VecD* axis = strain_ ? pairAxis_[i / NeighborLists::kChunk].data() + neighbors.start(i) : nullptr;
      for (const uint32_t* j = neighbors.begin(i); j != neighbors.end(i); ++j, ++c) {
        VecD r = xi - x[*j];
        wrap(r);
        const float nuIJ = several ? 0.5f * (nuI + nu_[fluid[*j]]) : nuI;
        const float squared = r.squaredNorm(), distance = std::sqrt(squared);
        *c = scale_ * nuIJ * kernel_.gradientFactor(distance) * squared / (squared + eta_);
        if (axis) {  // the strain's pair term: (d + 2) c_ij on the pair's axis
          *c = (Dim + 2) * *c;
          *axis++ = distance > 0 ? VecD(r / distance) : VecD::Zero();
        }
      }
      // The boundary (eq. 11's b terms): B_i, the walls' tensors summed, and B_i v_b.
      MatD tensor = MatD::Zero();
      VecD drag = VecD::Zero();
      for (int k = 0; k < Dim; ++k) {
        if (xi[k] - lower[k] < reach) tensor += wallTensor(xi[k] - lower[k], VecD::Unit(k), wallKeepTangent_, nuI);
        if (upper[k] - xi[k] < reach) tensor += wallTensor(upper[k] - xi[k], -VecD::Unit(k), wallKeepTangent_, nuI);
      }
      if (colliding)
        colliders.forEachNear(xi, [&](size_t k, float d, const VecD& normal) {
          const MatD wall = wallTensor(d, normal, keepTangent_[k], nuI);
          tensor += wall;
          drag += wall * colliders.wallVelocity(k, xi);
        });
      wall_[i] = tensor;
      wallDrag_[i] = drag;
    }
  });
  });
}

template <int Dim>
void Viscosity<Dim>::laplacian(const std::vector<VecD>& u, const NeighborLists& neighbors,
                               std::vector<VecD>& out) const {
  out.resize(u.size());
  parallelFor(0, u.size(), [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      const VecD ui = u[i];
      VecD sum = wall_[i] * ui;
      const size_t chunk = i / NeighborLists::kChunk, first = neighbors.start(i);
      const float* c = pairFactor_[chunk].data() + first;
      if (!strain_) {
        for (const uint32_t* j = neighbors.begin(i); j != neighbors.end(i); ++j, ++c) sum += *c * (ui - u[*j]);
      } else {
        const VecD* axis = pairAxis_[chunk].data() + first;
        for (const uint32_t* j = neighbors.begin(i); j != neighbors.end(i); ++j, ++c, ++axis)
          sum += (*c * axis->dot(ui - u[*j])) * *axis;
      }
      out[i] = sum;
    }
  });
}

// Collider k's share of particle i's change, dt B_ik (v_i - v_b), is the impulse it gave i: recorded on k (its
// drag in colliders.csv, a body's coupling, and the work a moving solid does for the energy ledger), at the
// velocities the change was taken at (the solved ones implicit, the old ones explicit).
template <int Dim>
void Viscosity<Dim>::recordColliderDrag(const std::vector<VecD>& x, const std::vector<VecD>& v,
                                        Colliders<Dim>& colliders, const std::vector<uint8_t>& fluid, float mass,
                                        const std::vector<float>& massRatio, float dt) const {
  const bool several = !fluid.empty();
  parallelFor(0, x.size(), [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      const VecD xi = x[i];
      const float nuI = nu_[several ? fluid[i] : 0];
      const float m = several ? mass * massRatio[i] : mass;
      colliders.forEachNear(xi, [&](size_t k, float d, const VecD& normal) {
        const VecD relative = v[i] - colliders.wallVelocity(k, xi);
        colliders.addImpulse(i, k, (m * dt) * (wallTensor(d, normal, keepTangent_[k], nuI) * relative), xi);
        // The strain's traction that the component-wise operator leaves out, mu (grad u)^T n, is -mu Omega x n at
        // a rigid no-slip wall: a turning collider takes it, over each particle's share of its wetted area, the
        // particle's volume over the support (the fluid within the support of a wall is its area times the
        // support). The fluid does not: inside it the term cancels between neighbours (div u = 0;
        // docs/viscosity.md). Not a body: given explicitly, a light body's spin would overshoot. Not with the
        // strain's operator, for which it was not derived (not measured there).
        if (!strain_ && keepTangent_[k] > 0 && k < colliders.firstBody() && colliders.turning(k)) {
          const float share = m * dt * nuI * keepTangent_[k] / kernel_.radius();  // dt mu V / h
          colliders.addImpulseOnSolid(i, k, share * colliders.spinAcross(k, normal), xi - d * normal);
        }
      });
    }
  });
}

template <int Dim>
void Viscosity<Dim>::apply(const std::vector<VecD>& x, std::vector<VecD>& v, const NeighborLists& neighbors,
                           const TankWalls<Dim>& walls, Colliders<Dim>& colliders,
                           const std::vector<uint8_t>& fluid, float mass, const std::vector<float>& massRatio,
                           float dt) {
  prepare(x, neighbors, walls, colliders, fluid);
  if (implicit_) {
    iterations_ = solveImplicit(x, v, neighbors, dt);
    if (!colliders.empty()) recordColliderDrag(x, v, colliders, fluid, mass, massRatio, dt);
    return;
  }
  // Explicit (Morris et al. 1997): v += dt (nu lap v - B v_b).
  if (!colliders.empty()) recordColliderDrag(x, v, colliders, fluid, mass, massRatio, dt);
  laplacian(v, neighbors, product_);
  parallelFor(0, v.size(), [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) v[i] += dt * (product_[i] - wallDrag_[i]);
  });
  iterations_ = 0;
}

// Eq. 12, (I - dt nu lap) v = v* - dt B v_b, by preconditioned conjugate gradients on A = I - dt (nu lap).
template <int Dim>
int Viscosity<Dim>::solveImplicit(const std::vector<VecD>& x, std::vector<VecD>& v, const NeighborLists& neighbors,
                                  float dt) {
  const size_t n = x.size();
  start_.assign(v.begin(), v.end());  // v*
  residual_.resize(n);
  direction_.resize(n);
  preconditioned_.resize(n);
  blockInverse_.resize(n);
  // The diagonal blocks of A: I - dt (sum_j c_ij P_ij + B_i), P the identity or, with the strain's operator, the
  // pair's projection x^ x^^T; inverted (block Jacobi).
  parallelFor(0, n, [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      const size_t chunk = i / NeighborLists::kChunk, first = neighbors.start(i);
      MatD pairs = MatD::Zero();
      const float* c = pairFactor_[chunk].data() + first;
      if (!strain_) {
        float sum = 0;
        for (const uint32_t* j = neighbors.begin(i); j != neighbors.end(i); ++j, ++c) sum += *c;
        pairs = sum * MatD::Identity();
      } else {
        const VecD* axis = pairAxis_[chunk].data() + first;
        for (const uint32_t* j = neighbors.begin(i); j != neighbors.end(i); ++j, ++c, ++axis)
          pairs += *c * (*axis * axis->transpose());
      }
      const MatD block = wall_[i] + pairs;
      blockInverse_[i] = (MatD::Identity() - dt * block).inverse();
      v[i] = start_[i];  // the start: v* plus the last step's change
      for (int k = 0; k < Dim; ++k) v[i][k] += warm_[k][i];
    }
  });
  // The stopping rule: |r| <= viscosity_max_error |r*|, r* = b - A v* = dt (nu lap v* - B v_b), the residual of
  // the velocities before the solve: the size of the step's viscous change. Measured against |b| (Weiler's
  // relative residual) it would not be Galilean invariant: a channel flowing at 0.1 m/s whose viscous change is
  // 0.005 m/s a step took last step's change as good enough, and Poiseuille's start-up overshot its steady peak
  // by 15% (docs/viscosity.md). Floored at 1e-5 |b|, the rounding of float velocities.
  const double initial = parallelSum<double>(0, n, [&](size_t b, size_t e) {
    double sum = 0;
    for (size_t i = b; i < e; ++i) sum += double(start_[i].squaredNorm());
    return sum;
  });
  laplacian(start_, neighbors, preconditioned_);  // scratch: nu lap v*
  const double change = parallelSum<double>(0, n, [&](size_t b, size_t e) {
    double sum = 0;
    for (size_t i = b; i < e; ++i) sum += double((dt * (preconditioned_[i] - wallDrag_[i])).squaredNorm());
    return sum;
  });
  const double limit = std::max(double(maxError_) * double(maxError_) * change, 1e-10 * initial);
  // r = b - A v, b = v* - dt B v_b.
  laplacian(v, neighbors, product_);
  parallelFor(0, n, [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      residual_[i] = start_[i] - dt * wallDrag_[i] - (v[i] - dt * product_[i]);
      preconditioned_[i] = blockInverse_[i] * residual_[i];
      direction_[i] = preconditioned_[i];
    }
  });
  double rz = dot(residual_, preconditioned_);
  int iterations = 0;
  while (iterations < maxIterations_ && dot(residual_, residual_) > limit) {
    laplacian(direction_, neighbors, product_);
    parallelFor(0, n, [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) product_[i] = direction_[i] - dt * product_[i];  // A p
    });
    const double curvature = dot(direction_, product_);
    if (!(curvature > 0)) break;
    const float alpha = static_cast<float>(rz / curvature);
    parallelFor(0, n, [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) {
        v[i] += alpha * direction_[i];
        residual_[i] -= alpha * product_[i];
        preconditioned_[i] = blockInverse_[i] * residual_[i];
      }
    });
    const double next = dot(residual_, preconditioned_);
    const float beta = static_cast<float>(next / rz);
    rz = next;
    parallelFor(0, n, [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) direction_[i] = preconditioned_[i] + beta * direction_[i];
    });
    ++iterations;
  }
  // The change of this step starts the next.
  parallelFor(0, n, [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i)
      for (int k = 0; k < Dim; ++k) warm_[k][i] = v[i][k] - start_[i][k];
  });
  return iterations;
}

template class Viscosity<2>;
template class Viscosity<3>;

}  // namespace surge
