// What every method shares about the rest lattice and the tank:
//  - latticeSums: sums of a kernel and of its squared gradient over the rest lattice around an interior
//    particle, to choose the particle mass (the rest lattice has exactly rho_0) and scale PBF's epsilon;
//  - TankWalls: the tank's walls as the rest lattice continued beyond them (after the boundary particles of
//    Akinci et al. 2012, summed once, up front, into tables against the distance to the wall), so a particle
//    of the rest lattice next to a wall has rho_0 as an interior one does and is pushed off the wall by the
//    density it sees; and the collision response that keeps particle centres a particle radius inside.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "sim/kernels.h"

namespace surge {

// Over the lattice points r = spacing (i, j, k) with |r| < support, including r = 0: sum of weight(r) and of
// |gradient(r)|^2, where weight and gradient are the kernel's W and grad W as functions of the offset vector.
template <int Dim, typename Weight, typename Gradient>
void latticeSums(float spacing, float support, Weight weight, Gradient gradient, double* weightSum,
                 double* gradientSquaredSum) {
  const int reach = static_cast<int>(std::ceil(support / spacing));
  const int zReach = Dim == 3 ? reach : 0;
  double w = 0, g = 0;
  for (int i = -reach; i <= reach; ++i)
    for (int j = -reach; j <= reach; ++j)
      for (int k = -zReach; k <= zReach; ++k) {
        Vec<Dim> r;
        r[0] = i * spacing;
        r[1] = j * spacing;
        if constexpr (Dim == 3) r[2] = k * spacing;
        w += weight(r);
        g += gradient(r).squaredNorm();
      }
  *weightSum = w;
  *gradientSquaredSum = g;
}

// The particle volume of the rest lattice through the cubic spline: V sum W = 1 at an interior site.
template <int Dim>
float latticeVolume(float spacing, const CubicSplineKernel<Dim>& kernel) {
  double weight = 0, unused = 0;
  latticeSums<Dim>(
      spacing, kernel.radius(), [&](const Vec<Dim>& r) { return kernel.value(r.norm()); },
      [&](const Vec<Dim>& r) -> Vec<Dim> { return kernel.gradientFactor(r.norm()) * r; }, &weight, &unused);
  return static_cast<float>(1.0 / weight);
}

// One flat wall's share at distance d from a particle: the kernel weight sum over the lattice beyond it, and the
// magnitude of the gradient sum, which points from the particle towards the wall. Zero beyond the support; a
// negative d reads as 0. The tank tabulates it; colliders (sim/colliders.h) use it for every shape, taking the
// wall locally flat.
//
// Two moments of the gradient serve WCSPH's hydrostatic boundary pressure (sim/colliders.h): with r = p_i - p_b,
// n the wall's normal and e a unit vector along the wall, normalMoment = sum_b (r . n) (grad W . n) and
// tangentMoment = sum_b (r . e) (grad W . e), the same for every e along the wall's lattice axes; both <= 0.
struct FlatWallTable {
  std::vector<float> weight, gradient, normalMoment, tangentMoment;
  float scale = 0;  // table entries per metre

  void lookup(float d, float& w, float& g) const {
    w = at(weight, d);
    g = at(gradient, d);
  }
  void moments(float d, float& normal, float& tangent) const {
    normal = at(normalMoment, d);
    tangent = at(tangentMoment, d);
  }
  // sum_b (g . (x_b - x_i)) grad W(x_i - x_b) over the wall's lattice at d along its normal n (pointing from the
  // wall to the particle): the hydrostatic continuation of pressure into the wall (Colliders::hydrostaticSum).
  template <typename VecD>
  VecD hydrostaticSum(float d, const VecD& n, const VecD& g) const {
    float normal, tangent;
    moments(d, normal, tangent);
    const float gn = g.dot(n);
    return -(gn * normal) * n - tangent * (g - gn * n);
  }

 private:
  float at(const std::vector<float>& table, float d) const {
    const float u = std::max(d, 0.0f) * scale;
    const int size = static_cast<int>(table.size()) - 1;
    if (!(u < size)) return 0;  // also NaN
    const int t = static_cast<int>(u);
    const float f = u - t;
    return (1 - f) * table[t] + f * table[t + 1];
  }
};

template <int Dim>
class TankWalls {
 public:
  using VecD = Vec<Dim>;

  // weight(r) and gradient(r): the kernel's W and grad_{p_i} W for the offset r = p_i - p_b.
  template <typename Weight, typename Gradient>
  TankWalls(const VecD& domainMin, const VecD& domainMax, float spacing, float support, Weight weight,
            Gradient gradient)
      : domainMin_(domainMin), domainMax_(domainMax) {
    const float particleRadius = 0.5f * spacing;
    clampMin_ = domainMin + VecD::Constant(particleRadius);
    clampMax_ = domainMax - VecD::Constant(particleRadius);
    // Beyond the kernel's support (with a margin over the tables' rounding) no wall reaches a particle.
    interiorMin_ = domainMin + VecD::Constant(1.001f * support);
    interiorMax_ = domainMax - VecD::Constant(1.001f * support);
    // A particle at distance d from a wall sees lattice layers at d + spacing / 2 + k spacing beyond it,
    // tangentially aligned with the particle. The walls' normals are taken along axes 0, 1, 2 here.
    const int reach = static_cast<int>(std::ceil(support / spacing)) + 1;
    const auto beyond = [&](int walls, const float* d, double* g, double* moments = nullptr) {
      return sumBeyond(walls, d, spacing, reach, weight, gradient, g, moments);
    };
    for (auto* table : {&flat_.weight, &flat_.gradient, &flat_.normalMoment, &flat_.tangentMoment})
      table->assign(kTableSize + 1, 0.0f);
    flat_.scale = kTableSize / support;
    for (int t = 0; t <= kTableSize; ++t) {
      const float d[1] = {support * t / kTableSize};
      double g[3], moments[4];
      flat_.weight[t] = static_cast<float>(beyond(1, d, g, moments));
      flat_.gradient[t] = static_cast<float>(-g[0]);  // g[0] <= 0: towards the wall
      flat_.normalMoment[t] = static_cast<float>(moments[0]);
      flat_.tangentMoment[t] = static_cast<float>(moments[1]);
    }
    // Along an edge where two walls meet, both walls' lattices hold the quarter beyond both: tabulate that
    // quarter (distances dA, dB to the two walls) so add() can count it once.
    edgeScale_ = kEdgeTableSize / support;
    edge_.assign((kEdgeTableSize + 1) * (kEdgeTableSize + 1), EdgeEntry{});
    for (int ta = 0; ta <= kEdgeTableSize; ++ta)
      for (int tb = 0; tb <= kEdgeTableSize; ++tb) {
        const float d[2] = {support * ta / kEdgeTableSize, support * tb / kEdgeTableSize};
        double g[3], m[4];
        const double w = beyond(2, d, g, m);
        edge_[ta * (kEdgeTableSize + 1) + tb] = {float(w), float(-g[0]), float(-g[1]),
                                                 {float(m[0]), float(m[1]), float(m[2]), float(m[3])}};
      }
    // Where three walls meet (3D): each wall added the eighth beyond all three, each of the three edges took
    // it away; tabulate it (distances to the three walls) so add() counts it once again.
    if constexpr (Dim == 3) {
      constexpr int n = kEdgeTableSize + 1;
      corner_.assign(size_t(n) * n * n, CornerEntry{});
      for (int ta = 0; ta < n; ++ta)
        for (int tb = 0; tb < n; ++tb)
          for (int tc = 0; tc < n; ++tc) {
            const float d[3] = {support * ta / kEdgeTableSize, support * tb / kEdgeTableSize,
                                support * tc / kEdgeTableSize};
            double g[3];
            const double w = beyond(3, d, g);
            corner_[(size_t(ta) * n + tb) * n + tc] = {float(w), {float(-g[0]), float(-g[1]), float(-g[2])}};
          }
    }
  }

  // Adds the walls' share of sum_b W(p - p_b) to `weight` and of sum_b grad W(p - p_b) to `gradient`.
  void add(const VecD& p, float& weight, VecD& gradient) const {
    // Edges: the quarter beyond two walls was added by each face; take it away once. Corners: the eighth beyond
    // three walls was added three times and taken away three times; add it once (inclusion-exclusion).
    const bool nearAWall = forEachFaceAndEdge(
        p,
        [&](int k, int side, float d) {
          const float u = std::max(d, 0.0f) * flat_.scale;
          if (!(u < kTableSize)) return;  // also skips NaN
          const int t = static_cast<int>(u);
          const float f = u - t;
          weight += (1 - f) * flat_.weight[t] + f * flat_.weight[t + 1];
          const float g = (1 - f) * flat_.gradient[t] + f * flat_.gradient[t + 1];
          gradient[k] += side == 0 ? -g : g;  // grad_{p_i} points towards the wall
        },
        [&](const int axes[2], const int sides[2], const float d[2]) {
          float w, ga, gb;
          if (!edgeTerms(d[0], d[1], w, ga, gb)) return;
          weight -= w;
          gradient[axes[0]] -= sides[0] == 0 ? -ga : ga;
          gradient[axes[1]] -= sides[1] == 0 ? -gb : gb;
        });
    if constexpr (Dim == 3)
      if (nearAWall) addCorners(p, weight, gradient);
  }

  // The walls' share of sum_b (g . (x_b - x_i)) grad W(x_i - x_b), the pressure continued hydrostatically into
  // the lattice beyond them: faces less the edges' quarters, as add() counts them (a corner's eighth has no
  // tabulated moments and is left out). WCSPH's colliders sum the same flat and edge moments (Colliders::
  // hydrostaticSum); its tank walls mirror the fluid instead (sim/wcsph_solver.cpp), and tests/sim/tank_test.cpp
  // holds the moments to the lattice through this sum.
  VecD hydrostaticSum(const VecD& p, const VecD& g) const {
    VecD sum = VecD::Zero();
    forEachFaceAndEdge(
        p, [&](int k, int, float d) { sum += flat_.hydrostaticSum(d, VecD(VecD::Unit(k)), g); },
        [&](const int axes[2], const int sides[2], const float d[2]) {
          const float towards[2] = {sides[0] ? 1.0f : -1.0f, sides[1] ? 1.0f : -1.0f};
          sum -= edgeHydrostaticSum(d[0], d[1], axes, towards, g);
        });
    return sum;
  }

  // The quarter beyond two perpendicular walls at distances da and db, lying along towards[0] on axis axes[0]
  // and towards[1] on axes[1] (+1 or -1): its sum_b (g . (x_b - x_i)) grad W = -M g, with
  // M = sum_b (W'(r) / r) r r^T (r = x_i - x_b) from the edge table's moments. Zero beyond the support.
  template <typename Vector>
  Vector edgeHydrostaticSum(float da, float db, const int axes[2], const float towards[2], const Vector& g) const {
    constexpr int n = Vector::RowsAtCompileTime;
    float e[4];
    if (!edgeMoments(da, db, e)) return Vector::Zero();
    Eigen::Matrix<float, n, n> m = Eigen::Matrix<float, n, n>::Identity() * e[2];  // along the edge
    m(axes[0], axes[0]) = e[0];
    m(axes[1], axes[1]) = e[1];
    // The table's r points away from the quarter on both axes; here r_a has the sign -towards[a].
    m(axes[0], axes[1]) = m(axes[1], axes[0]) = towards[0] * towards[1] * e[3];
    return -(m * g);
  }

  // The walls closer to p than `reach` (both of an axis in a tank thinner than twice it): their axes and the
  // coordinates of their planes; returns how many (WCSPH's mirror images, sim/wcsph_solver.cpp).
  int nearPlanes(const VecD& p, float reach, int axes[2 * Dim], float planes[2 * Dim]) const {
    int count = 0;
    for (int k = 0; k < Dim; ++k)
      for (int side = 0; side < 2; ++side) {
        if ((side == 0 ? p[k] - domainMin_[k] : domainMax_[k] - p[k]) >= reach) continue;
        axes[count] = k;
        planes[count++] = side == 0 ? domainMin_[k] : domainMax_[k];
      }
    return count;
  }

  // The share of one flat wall at distance d (the table above): see FlatWallTable.
  const FlatWallTable& flatWall() const { return flat_; }

  // A flat boundary at distance d with unit normal n (into the fluid; a collider's face) meets the tank: where
  // it stands square on a wall within the support (|n . axis| < 0.2), the quarter of lattice beyond both was
  // counted by each; subtracts it once (the edge table above, as add() does where two walls meet), from weight
  // and from gradient. Other angles are left as they are (docs/colliders.md).
  void subtractOverlap(const VecD& p, float d, const VecD& n, float& weight, VecD& gradient) const {
    if (!(std::max(d, 0.0f) * edgeScale_ < kEdgeTableSize)) return;
    for (int k = 0; k < Dim; ++k) {
      if (std::abs(n[k]) >= 0.2f) continue;
      for (int side = 0; side < 2; ++side) {
        const float dw = side == 0 ? p[k] - domainMin_[k] : domainMax_[k] - p[k];
        float w, ga, gb;
        if (!edgeTerms(dw, d, w, ga, gb)) continue;
        weight -= w;
        VecD wallNormal = VecD::Zero();
        wallNormal[k] = side == 0 ? 1.0f : -1.0f;
        // The quarter's gradient points towards both boundaries: -ga along the wall's normal, -gb along n.
        gradient += ga * wallNormal + gb * n;
      }
    }
  }

  // The lattice beyond two perpendicular walls at distances da and db (the quarter beyond both; the tables
  // above): its weight sum w and its gradient's magnitudes towards each wall, ga and gb. False (and nothing
  // written) when either wall is beyond the support.
  bool edgeTerms(float da, float db, float& w, float& ga, float& gb) const {
    int t, t2;
    float f, f2;
    if (!edgeCell(da, db, t, t2, f, f2)) return false;
    auto at = [&](int a, int b) { return edge_[a * (kEdgeTableSize + 1) + b]; };
    const EdgeEntry e00 = at(t, t2), e01 = at(t, t2 + 1), e10 = at(t + 1, t2), e11 = at(t + 1, t2 + 1);
    auto blend = [&](float EdgeEntry::*field) {
      return (1 - f) * ((1 - f2) * e00.*field + f2 * e01.*field) + f * ((1 - f2) * e10.*field + f2 * e11.*field);
    };
    w = blend(&EdgeEntry::weight);
    ga = blend(&EdgeEntry::gradientA);
    gb = blend(&EdgeEntry::gradientB);
    return true;
  }

  // The same quarter's moments (EdgeEntry::moments), bilinear in the table; false beyond the support.
  bool edgeMoments(float da, float db, float m[4]) const {
    int t, t2;
    float f, f2;
    if (!edgeCell(da, db, t, t2, f, f2)) return false;
    auto at = [&](int a, int b) -> const EdgeEntry& { return edge_[a * (kEdgeTableSize + 1) + b]; };
    for (int k = 0; k < 4; ++k)
      m[k] = (1 - f) * ((1 - f2) * at(t, t2).moments[k] + f2 * at(t, t2 + 1).moments[k]) +
             f * ((1 - f2) * at(t + 1, t2).moments[k] + f2 * at(t + 1, t2 + 1).moments[k]);
    return true;
  }

  // The lattice beyond three perpendicular walls at distances d[0..2] (3D; the eighth beyond all three): its
  // weight sum w and its gradient's magnitudes towards each wall. False when any wall is beyond the support.
  bool cornerTerms(const float d[3], float& w, float g[3]) const {
    constexpr int n = kEdgeTableSize + 1;
    int t[3];
    float f[3];
    for (int k = 0; k < 3; ++k) {
      const float u = std::max(d[k], 0.0f) * edgeScale_;
      if (!(u < kEdgeTableSize)) return false;  // also NaN
      t[k] = static_cast<int>(u);
      f[k] = u - t[k];
    }
    w = 0;
    g[0] = g[1] = g[2] = 0;
    for (int c = 0; c < 8; ++c) {
      float s = 1;
      int index[3];
      for (int k = 0; k < 3; ++k) {
        const int up = (c >> k) & 1;
        s *= up ? f[k] : 1 - f[k];
        index[k] = t[k] + up;
      }
      const CornerEntry& entry = corner_[(size_t(index[0]) * n + index[1]) * n + index[2]];
      w += s * entry.weight;
      for (int k = 0; k < 3; ++k) g[k] += s * entry.gradient[k];
    }
    return true;
  }

  // The clamp below as a bound on a velocity: over a move of dt from p, v may take the particle no further than
  // the clamp allows (a particle already beyond it may still stand still). DFSPH bounds every velocity its
  // solvers compute this way, so that they predict the move the clamp will allow.
  void boundVelocity(const VecD& p, VecD& v, float dt) const {
    for (int k = 0; k < Dim; ++k) {
      const float lowest = (clampMin_[k] - p[k]) / dt, highest = (clampMax_[k] - p[k]) / dt;
      v[k] = std::min(std::max(v[k], std::min(lowest, 0.0f)), std::max(highest, 0.0f));
    }
  }

  // Collision response: projects p back to a particle radius inside the tank. NaN stays NaN (comparisons with
  // NaN are false), so a diverged particle is reported rather than hidden at a wall. Returns the axes moved
  // as bits, so that a solver can stop the velocity into the wall.
  int clamp(VecD& p) const {
    int moved = 0;
    for (int k = 0; k < Dim; ++k) {
      if (p[k] < clampMin_[k]) {
        p[k] = clampMin_[k];
        moved |= 1 << k;
      } else if (p[k] > clampMax_[k]) {
        p[k] = clampMax_[k];
        moved |= 1 << k;
      }
    }
    return moved;
  }

  const VecD& domainMin() const { return domainMin_; }
  const VecD& domainMax() const { return domainMax_; }

  bool contains(const VecD& p) const {
    return (p.array() >= domainMin_.array()).all() && (p.array() <= domainMax_.array()).all();
  }

  // Over the lattice beyond `walls` walls whose normals are axes 0 .. walls-1, at distances d[a] from the
  // particle (layers d[a] + spacing / 2 + i spacing, i >= 0, on those axes; every tangential offset within
  // `reach` on the others): returns the sum of weight(r) and writes the sum of gradient(r) to g, and, if asked,
  // the moments sum r_0 gradient_0(r), sum r_1 gradient_1(r), sum r_2 gradient_2(r) (3D) and
  // sum r_0 gradient_1(r) (= sum r_1 gradient_0(r): the gradient is along r).
  template <typename Weight, typename Gradient>
  static double sumBeyond(int walls, const float* d, float spacing, int reach, const Weight& weight,
                          const Gradient& gradient, double* g, double* moments = nullptr) {
    const float particleRadius = 0.5f * spacing;
    int lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (int a = 0; a < Dim; ++a) {
      lo[a] = a < walls ? 0 : -reach;
      hi[a] = reach;
    }
    double w = 0, normalMoment = 0, tangentMoment = 0, thirdMoment = 0, crossMoment = 0;
    g[0] = g[1] = g[2] = 0;
    for (int i = lo[0]; i <= hi[0]; ++i)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int k = lo[2]; k <= hi[2]; ++k) {
          const int index[3] = {i, j, k};
          VecD r;
          for (int a = 0; a < Dim; ++a)
            r[a] = a < walls ? d[a] + particleRadius + index[a] * spacing : index[a] * spacing;
          w += weight(r);
          const VecD gr = gradient(r);
          for (int a = 0; a < Dim; ++a) g[a] += gr[a];
          normalMoment += r[0] * gr[0];
          tangentMoment += r[1] * gr[1];
          if constexpr (Dim == 3) thirdMoment += r[2] * gr[2];
          crossMoment += r[0] * gr[1];
        }
    if (moments) {
      moments[0] = normalMoment;
      moments[1] = tangentMoment;
      moments[2] = thirdMoment;
      moments[3] = crossMoment;
    }
    return w;
  }

 private:

  // Calls face(k, side, d) for each wall (axis k, side 0 at domainMin, 1 at domainMax) at distance d from p,
  // then edge(axes, sides, d) for each pair of walls on distinct axes, in the order add() has always summed
  // them; false (and no call) for a particle farther than the support from every wall. Each call decides for
  // itself what is beyond the support (the tables read 0 there).
  template <typename Face, typename Edge>
  bool forEachFaceAndEdge(const VecD& p, Face&& face, Edge&& edge) const {
    if ((p.array() > interiorMin_.array()).all() && (p.array() < interiorMax_.array()).all()) return false;
    float d[Dim][2];
    for (int k = 0; k < Dim; ++k) {
      d[k][0] = p[k] - domainMin_[k];
      d[k][1] = domainMax_[k] - p[k];
    }
    for (int k = 0; k < Dim; ++k)
      for (int side = 0; side < 2; ++side) face(k, side, d[k][side]);
    for (int k = 0; k < Dim; ++k)
      for (int k2 = k + 1; k2 < Dim; ++k2)
        for (int both = 0; both < 4; ++both) {
          const int axes[2] = {k, k2}, sides[2] = {both & 1, both >> 1};
          const float at[2] = {d[k][sides[0]], d[k2][sides[1]]};
          edge(axes, sides, at);
        }
    return true;
  }

  // Where distances da and db fall in the edge table: the cell (t, t2) and the fractions (f, f2) across it;
  // false when either is beyond the support (or NaN).
  bool edgeCell(float da, float db, int& t, int& t2, float& f, float& f2) const {
    const float u = std::max(da, 0.0f) * edgeScale_, u2 = std::max(db, 0.0f) * edgeScale_;
    if (!(u < kEdgeTableSize) || !(u2 < kEdgeTableSize)) return false;
    t = static_cast<int>(u);
    t2 = static_cast<int>(u2);
    f = u - t;
    f2 = u2 - t2;
    return true;
  }

  // The corners' share of add(): the eighth beyond three walls, for every corner whose three walls are all
  // within the support (none, for all but the particles in a corner).
  void addCorners(const VecD& p, float& weight, VecD& gradient) const {
    float d[3][2];
    for (int k = 0; k < 3; ++k) {
      d[k][0] = p[k] - domainMin_[k];
      d[k][1] = domainMax_[k] - p[k];
      const float reach = 1.001f * kEdgeTableSize / edgeScale_;  // a margin over the rounding; cornerTerms decides
      if (!(d[k][0] < reach) && !(d[k][1] < reach)) return;  // no wall of this axis within the support
    }
    for (int corner = 0; corner < 8; ++corner) {
      const int side[3] = {corner >> 2 & 1, corner >> 1 & 1, corner & 1};  // axis 0 slowest, as summed before
      const float at[3] = {d[0][side[0]], d[1][side[1]], d[2][side[2]]};
      float w, g[3];
      if (!cornerTerms(at, w, g)) continue;
      weight += w;
      for (int k = 0; k < 3; ++k) gradient[k] += side[k] ? g[k] : -g[k];
    }
  }

  static constexpr int kTableSize = 64;
  static constexpr int kEdgeTableSize = 32;
  struct EdgeEntry {
    float weight = 0, gradientA = 0, gradientB = 0;  // gradients: magnitudes towards each wall
    // sum r_a grad_a, sum r_b grad_b, sum r_t grad_t (t along the edge, 3D), sum r_a grad_b; the table's r
    // points from the quarter to the particle on both axes (WCSPH's hydrostatic wall pressure at a box's edge)
    float moments[4] = {0, 0, 0, 0};
  };
  VecD domainMin_, domainMax_, clampMin_, clampMax_, interiorMin_, interiorMax_;
  FlatWallTable flat_;
  std::vector<EdgeEntry> edge_;
  float edgeScale_ = 0;
  struct CornerEntry {
    float weight = 0, gradient[3] = {0, 0, 0};  // gradient: magnitudes towards each of the three walls
  };
  std::vector<CornerEntry> corner_;
};

}  // namespace surge
