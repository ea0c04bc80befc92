// PBF where particles meet solids and each other (sim/pbf_solver.h): the collision response and friction at
// the colliders and the tank, the colliders' share of eq. 12, and the offset that parts coincident particles.
// Kept apart from pbf_solver.cpp, which reads as the paper's Algorithm 1.
#include "sim/pbf_solver.h"

#include "core/parallel.h"

namespace surge {

// The collision response for the move of p*_i from `from`, against the colliders and the tank; each collider's
// push is an impulse m delta / dt given to the particle. Where a collider meets a wall, the wall's clamp can put
// the particle back into the collider: both act again, up to kCornerRounds times, and the clamp acts last. A
// corner round's push records no impulse: it is the tank's push passed on (docs/bodies.md, the rocking box).
template <int Dim>
void PbfSolver<Dim>::collide(size_t i, const VecD& from, bool fromStepStart) {
  constexpr int kCornerRounds = 2;
  const float mass = this->massOf(i);
  auto pushed = [&](size_t c, const VecD& delta) { colliders_.addImpulse(i, c, (mass / stepDt_) * delta, p_[i]); };
  colliders_.project(from, p_[i], fromStepStart, pushed);
  for (int round = 0; round < kCornerRounds; ++round) {
    if (walls_.clamp(p_[i]) == 0) return;
    const VecD clamped = p_[i];
    if (!colliders_.project(clamped, p_[i], false, [](size_t, const VecD&) {})) return;
  }
  walls_.clamp(p_[i]);
}

// Friction at the colliders, on the velocities of line 21.
template <int Dim>
void PbfSolver<Dim>::applyFriction() {
  parallelFor(0, size(), [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) colliders_.applyFriction(i, p_[i], v_[i], this->massOf(i));
  });
}

// The colliders' share of eq. 12 for particle i at p with lambda_i: (m / rho_0) lambda_i sum_c grad W_c, each
// collider's part an impulse it gives the particle. The lambda pass found the colliders at p (found_); the
// gradient of a single one, as most particles near any have, is kept from there. Kept out of the loop above,
// which stays as it was for a scene without colliders (same instructions, same bytes).
template <int Dim>
typename PbfSolver<Dim>::VecD PbfSolver<Dim>::colliderCorrection(size_t i, const VecD& p, float lambda) {
  auto share = [&](size_t c, const VecD& gradient) {
    const VecD move = (massOverRho_ * lambda) * gradient;
    colliders_.addImpulse(i, c, (mass_ / stepDt_) * move, p);
    return move;
  };
  if (found_[i].count == 1) return share(found_[i].only, onlyGradient_[i]);
  VecD delta = VecD::Zero();
  colliders_.forEachNear(p, [&](size_t c, float d, const VecD& n) {
    float unused;
    VecD gradient;
    colliders_.wallTerms(c, p, d, n, unused, gradient);
    delta += share(c, gradient);
  });
  return delta;
}

// p_i - p_j, or coincidentOffset for a pair closer than coincidentLength_.
template <int Dim>
typename PbfSolver<Dim>::VecD PbfSolver<Dim>::pairOffset(size_t i, size_t j, const VecD& pi) const {
  VecD r = pi - p_[j];
  if (this->periodic_.active()) this->periodic_(r);
  if (r.squaredNorm() <= coincidentLength_ * coincidentLength_) [[unlikely]] return coincidentOffset(i, j);
  return r;
}

// Two particles on the same point (the walls project every particle that overshoots a corner onto the same
// corner) have no kernel gradient between them, so no constraint could ever part them, and their summed density
// would push their neighbours ever harder. Such a pair is given a tiny offset along a direction that depends on
// the pair only and flips with its order (so momentum is still conserved).
template <int Dim>
typename PbfSolver<Dim>::VecD PbfSolver<Dim>::coincidentOffset(size_t i, size_t j) const {
  const uint32_t lo = static_cast<uint32_t>(std::min(i, j)), hi = static_cast<uint32_t>(std::max(i, j));
  uint32_t hash = lo * 0x9E3779B1u ^ (hi + 0x7F4A7C15u) * 0x85EBCA77u;
  VecD direction;
  for (int k = 0; k < Dim; ++k) {
    hash ^= hash >> 15;
    hash *= 0x2C1B3C6Du;
    direction[k] = static_cast<float>(hash & 0xFFFF) / 32768.0f - 1.0f;
  }
  direction[0] += 1e-3f;  // never the zero vector
  return (i < j ? coincidentLength_ : -coincidentLength_) * direction.normalized();
}

template void PbfSolver<2>::collide(size_t, const Vec<2>&, bool);
template void PbfSolver<2>::applyFriction();
template Vec<2> PbfSolver<2>::colliderCorrection(size_t, const Vec<2>&, float);
template Vec<2> PbfSolver<2>::pairOffset(size_t, size_t, const Vec<2>&) const;
template Vec<2> PbfSolver<2>::coincidentOffset(size_t, size_t) const;
template void PbfSolver<3>::collide(size_t, const Vec<3>&, bool);
template void PbfSolver<3>::applyFriction();
template Vec<3> PbfSolver<3>::colliderCorrection(size_t, const Vec<3>&, float);
template Vec<3> PbfSolver<3>::pairOffset(size_t, size_t, const Vec<3>&) const;
template Vec<3> PbfSolver<3>::coincidentOffset(size_t, size_t) const;

}  // namespace surge
