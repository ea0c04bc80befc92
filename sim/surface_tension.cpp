#include "sim/surface_tension.h"

#include <algorithm>
#include <type_traits>
#include <unordered_set>

#include "core/parallel.h"
#include "sim/tank.h"

namespace surge {
namespace {

constexpr int kAdhesionTableSize = 64;


// The lattice offsets o (in spacings) of the sites closer than `support`, o = 0 left out.
template <int Dim>
std::vector<Eigen::Vector3i> latticeOffsets(float spacing, float support) {
  const int reach = static_cast<int>(std::ceil(support / spacing));
  const int zReach = Dim == 3 ? reach : 0;
  std::vector<Eigen::Vector3i> offsets;
  for (int i = -reach; i <= reach; ++i)
    for (int j = -reach; j <= reach; ++j)
      for (int k = -zReach; k <= zReach; ++k) {
        const double r = spacing * std::sqrt(double(i * i + j * j + k * k));
        if ((i || j || k) && r < support) offsets.emplace_back(i, j, k);
      }
  return offsets;
}

// Eq. 2's normalisation, one power of h less in 2D.
float cohesionNormalisation(int dim, float h) { return static_cast<float>(32.0 / (M_PI * std::pow(double(h), 6 + dim))); }

// C(r) / normalisation of eq. 2.
float cohesionShape(float r, float h) {
  if (r <= 0 || r >= h) return 0;
  const float d = h - r, d3 = d * d * d, r3 = r * r * r;
  return 2 * r > h ? d3 * r3 : 2 * d3 * r3 - h * h * h * h * h * h / 64;
}

// A(r) of eq. 7: 0.007 / h^3.25 (-4 r^2 / h + 6 r - 2 h)^(1/4) for h / 2 < r <= h, one power of h less in 2D.
double adhesionKernel(int dim, double r, double h) {
  if (2 * r <= h || r > h) return 0;
  return 0.007 / std::pow(h, dim + 0.25) * std::pow(std::max(-4 * r * r / h + 6 * r - 2 * h, 0.0), 0.25);
}

}  // namespace

double sceneSurfaceTension(const Scene& scene) {
  double most = 0;
  for (const auto& fluid : scene.fluids) most = std::max(most, fluid.surface_tension);
  return most;
}

bool sceneHasAdhesion(const Scene& scene) {
  for (const ColliderSettings& c : scene.colliders)
    if (c.adhesion > 0) return true;
  for (const BodySettings& b : scene.bodies)
    if (b.solid.adhesion > 0) return true;
  return false;
}

double adhesionCalibration(int dimensions, double spacings) {
  if (dimensions == 2) {
    if (std::abs(spacings - 3.5) < 0.05) return 1.15;
    return std::abs(spacings - 3.75) < 0.05 ? 0.9 : 0;
  }
  if (std::abs(spacings - 2) < 0.05) return 1;
  if (std::abs(spacings - 2.5) < 0.05) return 0.75;
  if (std::abs(spacings - 3) < 0.05) return 0.9;
  return 0;
}

double surfaceEnergyBound(const Scene& scene, const ParticleFrame& initial) {
  if (sceneSurfaceTension(scene) <= 0) return 0;
  if (!scene.emitters.empty()) return INFINITY;
  const double spacing = scene.particle_spacing;
  const int dim = scene.dimensions;
  // A block's sites sit at cell centres or, when its edges fall half a spacing off the domain's grid, on cell
  // corners, where floor() would part rounding errors into two cells; a quarter spacing more keeps either lattice
  // (and a jittered start's sites, at most a quarter spacing off theirs) one site a cell.
  auto cell = [&](const Eigen::Vector3f& p) {
    Eigen::Vector3i c = Eigen::Vector3i::Zero();
    for (int k = 0; k < dim; ++k) c[k] = int(std::floor((double(p[k]) - scene.domain.min[k]) / spacing + 0.25));
    return c;
  };
  auto key = [](const Eigen::Vector3i& c) {
    return (uint64_t(uint32_t(c[0]) & 0x1fffff) << 42) | (uint64_t(uint32_t(c[1]) & 0x1fffff) << 21) |
           uint64_t(uint32_t(c[2]) & 0x1fffff);
  };
  // Each fluid's faces against cells not of that fluid (air, or another fluid: each sees the others as air).
  const auto fluidOf = [&](size_t i) { return initial.fluid.empty() ? size_t(0) : size_t(initial.fluid[i]); };
  double energy = 0;
  for (size_t f = 0; f < scene.fluids.size(); ++f) {
    const double sigma = scene.fluids[f].surface_tension;
    if (sigma <= 0 || (f > 0 && initial.fluid.empty())) continue;
    std::unordered_set<uint64_t> cells;
    for (size_t i = 0; i < initial.size(); ++i)
      if (fluidOf(i) == f) cells.insert(key(cell(initial.position[i])));
    size_t faces = 0;
    for (size_t i = 0; i < initial.size(); ++i) {
      if (fluidOf(i) != f) continue;
      const Eigen::Vector3i c = cell(initial.position[i]);
      for (int k = 0; k < dim; ++k)
        for (int side : {-1, 1}) {
          Eigen::Vector3i beside = c;
          beside[k] += side;
          faces += cells.count(key(beside)) == 0;
        }
    }
    energy += sigma * double(faces) * std::pow(spacing, dim - 1);
  }
  return energy;
}

template <int Dim>
SurfaceTension<Dim>::SurfaceTension(const Scene& scene, float mass) {
  const double sigma = sceneSurfaceTension(scene);
  if (sigma <= 0) return;
  const float spacing = static_cast<float>(scene.particle_spacing);
  spacing_ = spacing;
  periodic_ = PeriodicDomain<Dim>(scene);
  support_ = static_cast<float>(scene.solver.kernel_radius);
  kernel_ = CubicSplineKernel<Dim>(support_);
  volume_ = latticeVolume<Dim>(spacing, kernel_);
  mass_ = mass;
  restDensity_ = static_cast<float>(scene.solver.rest_density);
  cohesionScale_ = cohesionNormalisation(Dim, support_);
  gamma_ = static_cast<float>(sigma / tensionPerGamma(spacing, support_, mass));
  stableStep_ = static_cast<float>(std::sqrt(scene.solver.rest_density * std::pow(spacing, 3) / (2 * M_PI * sigma)));
  // Each fluid's own gamma and particle mass (ParticleSolver's mass ratios); one fluid keeps the above.
  const bool several = scene.severalFluids();
  std::vector<double> fluidSigma, density;
  for (size_t f = 0; f < (several ? scene.fluids.size() : 1); ++f) {
    const double sigmaF = several ? scene.fluids[f].surface_tension : sigma;
    fluidSigma.push_back(sigmaF);
    density.push_back(several ? scene.fluids[f].rest_density : scene.solver.rest_density);
    const float m = several ? mass * static_cast<float>(scene.fluids[f].rest_density / scene.referenceDensity()) : mass;
    fluidMass_.push_back(m);
    fluidGamma_.push_back(several ? (sigmaF > 0 ? static_cast<float>(sigmaF / tensionPerGamma(spacing, support_, m)) : 0.0f)
                                  : gamma_);
    if (several && sigmaF > 0)
      stableStep_ = std::min(stableStep_, static_cast<float>(std::sqrt(density.back() * std::pow(spacing, 3) /
                                                                       (2 * M_PI * sigmaF))));
  }

  // Adhesion: the flat wall's sum of V A along its normal, tabulated by distance, and each solid's beta.
  std::vector<double> adhesion;
  for (const ColliderSettings& c : scene.colliders) adhesion.push_back(c.adhesion);
  for (const BodySettings& b : scene.bodies) adhesion.push_back(b.solid.adhesion);
  adhesive_ = std::any_of(adhesion.begin(), adhesion.end(), [](double a) { return a > 0; });
  if (!adhesive_) return;
  // The lattice beyond a flat wall (TankWalls::sumBeyond), each site pulling with V A(r) along r.
  const int reach = static_cast<int>(std::ceil(support_ / spacing)) + 1;
  adhesionTable_.assign(kAdhesionTableSize + 1, 0.0f);
  adhesionScale_ = kAdhesionTableSize / support_;
  for (int t = 0; t <= kAdhesionTableSize; ++t) {
    const float d[1] = {support_ * t / kAdhesionTableSize};
    double pull[3];
    TankWalls<Dim>::sumBeyond(
        1, d, spacing, reach, [](const VecD&) { return 0.0f; },
        [&](const VecD& r) -> VecD {
          const float length = r.norm();
          return float(volume_ * adhesionKernel(Dim, length, support_) / length) * r;
        },
        pull);
    adhesionTable_[t] = static_cast<float>(pull[0]);
  }
  // beta from a = W_a / (2 sigma); a fluid's work per beta scales with its m rho_0 (adhesionWorkPerBeta).
  const double measured = adhesionCalibration(Dim, support_ / spacing);
  const double workPerBeta = adhesionWorkPerBeta() / (measured > 0 ? measured : 1);
  for (size_t f = 0; f < fluidMass_.size(); ++f) {
    const double work = several ? workPerBeta * (double(fluidMass_[f]) * density[f]) / (double(mass_) * restDensity_)
                                : workPerBeta;
    const float rho = several ? static_cast<float>(density[f]) : restDensity_;
    pull_.emplace_back();
    for (double a : adhesion) pull_.back().push_back(static_cast<float>(a * 2 * fluidSigma[f] / work) * rho);
  }
}

template <int Dim>
float SurfaceTension<Dim>::cohesion(float r) const {
  return cohesionScale_ * cohesionShape(r, support_);
}

template <int Dim>
float SurfaceTension<Dim>::wallAdhesion(float d) const {
  const float u = std::max(d, 0.0f) * adhesionScale_;
  if (!(u < kAdhesionTableSize)) return 0;
  const int t = static_cast<int>(u);
  const float f = u - t;
  return (1 - f) * adhesionTable_[t] + f * adhesionTable_[t + 1];
}

template <int Dim>
double SurfaceTension<Dim>::adhesionWorkPerBeta() const {
  // Layers at d_k = spacing (k + 1/2), one particle a column of area spacing^(d-1) each; pulled to the wall by
  // m rho_0 wallAdhesion(d) per unit beta. The work per area is sum_k m rho_0 integral_{d_k}^h wallAdhesion.
  const double spacing = spacing_;
  const int steps = 4 * kAdhesionTableSize;
  double work = 0;
  for (double dk = 0.5 * spacing; dk < support_; dk += spacing) {
    const double du = (support_ - dk) / steps;
    double integral = 0;
    for (int s = 0; s < steps; ++s) integral += du * wallAdhesion(static_cast<float>(dk + (s + 0.5) * du));
    work += mass_ * restDensity_ * integral;
  }
  return work / std::pow(spacing, Dim - 1);
}

template <int Dim>
double SurfaceTension<Dim>::tensionPerGamma(float spacing, float support, float mass) {
  const CubicSplineKernel<Dim> kernel(support);
  const double volume = latticeVolume<Dim>(spacing, kernel);
  const double scale = cohesionNormalisation(Dim, support);
  const std::vector<Eigen::Vector3i> offsets = latticeOffsets<Dim>(spacing, support);
  const int reach = static_cast<int>(std::ceil(support / spacing));
  const int layers = 4 * reach + 2;
  // Each layer's colour and normal (along y, the slab's normal).
  std::vector<double> colour(layers, volume * kernel.value(0)), normal(layers, 0.0);
  for (int l = 0; l < layers; ++l)
    for (const Eigen::Vector3i& o : offsets) {
      if (l + o[1] < 0 || l + o[1] >= layers) continue;
      const double r = spacing * o.cast<double>().norm();
      colour[l] += volume * kernel.value(float(r));
      normal[l] += support * volume * kernel.gradientFactor(float(r)) * (-spacing * o[1]);  // x_i - x_j = -o
    }
  double virial = 0;
  for (int l = 0; l < layers; ++l)
    for (const Eigen::Vector3i& o : offsets) {
      const int m = l + o[1];
      if (m < 0 || m >= layers) continue;
      const Eigen::Vector3d r = -double(spacing) * o.cast<double>();
      const double length = r.norm();
      const double k = 2 / (colour[l] + colour[m]);
      Eigen::Vector3d force = -(mass * scale * cohesionShape(float(length), support) / length) * r;
      force[1] -= normal[l] - normal[m];
      force *= mass * k;
      const double tangential = Dim == 3 ? 0.5 * (r[0] * force[0] + r[2] * force[2]) : r[0] * force[0];
      virial += r[1] * force[1] - tangential;
    }
  return virial / (4 * std::pow(double(spacing), Dim - 1));
}

template <int Dim>
template <bool kSeveral, typename Wrap>
void SurfaceTension<Dim>::colourAndNormals(const std::vector<VecD>& x, const NeighborLists& neighbors,
                                           const std::vector<uint8_t>& fluid, const Wrap& sharedWrap) {
  const size_t n = x.size();
  colour_.resize(n);
  normal_.resize(n);
  const float self = volume_ * kernel_.value(0);
  parallelFor(0, n, [&](size_t b, size_t e) {
    const auto wrap = sharedWrap;  // the thread's own copy (sim/periodic.h)
    for (size_t i = b; i < e; ++i) {
      float c = self;
      VecD normal = VecD::Zero();
      for (const uint32_t* j = neighbors.begin(i); j != neighbors.end(i); ++j) {
        if (kSeveral && fluid[*j] != fluid[i]) continue;  // another fluid counts as air
        VecD r = x[i] - x[*j];
        wrap(r);
        const SphKernelPair k = kernel_.pair(r.norm());
        c += volume_ * k.value;
        normal += k.gradientFactor * r;
      }
      colour_[i] = c;
      normal_[i] = (support_ * volume_) * normal;
    }
  });
}

template <int Dim>
void SurfaceTension<Dim>::addPairVirials(const std::vector<VecD>& x, const NeighborLists& neighbors,
                                         const std::vector<uint8_t>& fluid, const VirialBall<Dim>& ball,
                                         std::vector<double>& virial) {
  const auto passes = [&](auto severalFluids) {
    constexpr bool several = decltype(severalFluids)::value;
    periodic_.withNearestImage([&](const auto& sharedWrap) {
      colourAndNormals<several>(x, neighbors, fluid, sharedWrap);
      parallelFor(0, x.size(), [&](size_t b, size_t e) {
        const auto wrap = sharedWrap;
        for (size_t i = b; i < e; ++i) {
          const size_t f = several ? fluid[i] : 0;
          const float m = fluidMass_[f];
          double sum = 0;
          for (const uint32_t* j = neighbors.begin(i); j != neighbors.end(i); ++j) {
            if (several && fluid[*j] != f) continue;
            VecD r = x[i] - x[*j];
            wrap(r);
            sum += double(ball.halfInside(x[i], r)) * double(r.dot(pairTerm(i, *j, r, m)));  // x_ij . a_ij / gamma
          }
          virial[i] += 0.5 * sum * fluidGamma_[f] * m;
        }
      });
    });
  };
  if (fluid.empty())
    passes(std::false_type{});
  else
    passes(std::true_type{});
}

template <int Dim>
void SurfaceTension<Dim>::computeAccelerations(const std::vector<VecD>& x, const NeighborLists& neighbors,
                                               Colliders<Dim>& colliders, float impulseScale,
                                               const std::vector<uint8_t>& fluid) {
  const size_t n = x.size();
  accel_.resize(n);
  // One fluid compiles without the fluid checks (its loops as they were before several fluids).
  const auto passes = [&](auto severalFluids) {
  constexpr bool several = decltype(severalFluids)::value;
  periodic_.withNearestImage([&](const auto& sharedWrap) {
  colourAndNormals<several>(x, neighbors, fluid, sharedWrap);
  parallelFor(0, n, [&](size_t b, size_t e) {
    const auto wrap = sharedWrap;  // the thread's own copy (sim/periodic.h)
    for (size_t i = b; i < e; ++i) {
      const size_t f = several ? fluid[i] : 0;
      const float m = fluidMass_[f];
      VecD a = VecD::Zero();
      for (const uint32_t* j = neighbors.begin(i); j != neighbors.end(i); ++j) {
        if (several && fluid[*j] != f) continue;
        VecD r = x[i] - x[*j];
        wrap(r);
        a += pairTerm(i, *j, r, m);
      }
      a *= fluidGamma_[f];
      if (adhesive_)
        colliders.forEachNear(x[i], [&](size_t c, float d, const VecD& wallNormal) {
          if (pull_[f][c] <= 0) return;
          const VecD pull = (-pull_[f][c] * wallAdhesion(d)) * wallNormal;  // eq. 7, to the wall
          a += pull;
          colliders.addImpulse(i, c, (m * impulseScale) * pull, x[i]);
        });
      accel_[i] = a;
    }
  });
  });
  };
  if (fluid.empty())
    passes(std::false_type{});
  else
    passes(std::true_type{});
}

template <int Dim>
void SurfaceTension<Dim>::kick(std::vector<VecD>& v, float dt, const std::vector<float>& massRatio) {
  const bool several = !massRatio.empty();
  work_ += parallelSum<double>(0, v.size(), [&](size_t b, size_t e) {
    double work = 0;
    for (size_t i = b; i < e; ++i) {
      const VecD dv = dt * accel_[i];
      const double w = double(accel_[i].dot(v[i] + 0.5f * dv));
      work += several ? w * massRatio[i] : w;
      v[i] += dv;
    }
    return work;
  }) * double(mass_) * dt;
}

template <int Dim>
void SurfaceTension<Dim>::addTo(std::vector<VecD>& a) const {
  parallelFor(0, a.size(), [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) a[i] += accel_[i];
  });
}

template <int Dim>
void SurfaceTension<Dim>::addWork(const std::vector<VecD>& v, float dt, const std::vector<float>& massRatio) {
  const bool several = !massRatio.empty();
  work_ += parallelSum<double>(0, v.size(), [&](size_t b, size_t e) {
    double work = 0;
    for (size_t i = b; i < e; ++i) {
      const double w = double(accel_[i].dot(v[i]));
      work += several ? w * massRatio[i] : w;
    }
    return work;
  }) * double(mass_) * dt;
}

template <int Dim>
size_t SurfaceTension<Dim>::memoryBytes() const {
  return (normal_.capacity() + accel_.capacity()) * sizeof(VecD) + colour_.capacity() * sizeof(float);
}

template class SurfaceTension<2>;
template class SurfaceTension<3>;

}  // namespace surge
