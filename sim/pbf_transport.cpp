// PBF in a fluid that fills its domain (sim/pbf_solver.h): the density target of a box periodic along every axis
// and Adami, Hu and Adams 2013's transport velocity (solver.background_pressure), as DFSPH has them. Both act
// before the density constraints are solved; a scene with neither runs no pass here.
#include "core/parallel.h"
#include "sim/pbf_solver.h"

namespace surge {

// rho_i / rho_0 at the predicted positions (eq. 2 with the tank's walls), the mean target, and the push: x*_i +=
// dt^2 a_b, stopped at the colliders and the tank, a move the velocity of line 21 does not keep.
template <int Dim>
void PbfSolver<Dim>::prepareFilledDomain(float dt) {
  const PhaseTimer timer(times_.pressure);
  densityRatio_.resize(size());
  const float selfWeight = kernelWeight(0.0f);
  parallelFor(0, size(), [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      const VecD pi = p_[i];
      float weight = selfWeight;
      for (const uint32_t* j = neighbors_.begin(i); j != neighbors_.end(i); ++j)
        weight += kernelWeight(pairOffset(i, *j, pi).squaredNorm());
      VecD unused = VecD::Zero();
      walls_.add(pi, weight, unused);
      densityRatio_[i] = mass_ * weight / restDensity_;
    }
  });
  // Aimed at 1, a Taylor-Green vortex at 2.5 spacings of support and p_b = 4e4 Pa kept 0.49 of its energy to 0.64 s,
  // against 0.955 aimed at the mean.
  if (this->periodic_.everyAxis()) densityTarget_ = this->meanDensityTarget(densityRatio_);
  if (!(backgroundPressure_ > 0)) return;
  // a_b = -(p_b / rho_0) (m / rho_0) (sum_j (1 / r_i^2 + 1 / r_j^2) grad W_ij + 2 / r_i^2 G_i), r = rho / rho_0,
  // G_i the walls' gradient (w_i times it with several fluids, as eq. 12's move). The colliders' share is left out:
  // the push is meant for fluid that fills a periodic box, and a particle it sends into a collider is stopped there
  // as a correction is (moveBy).
  transportPush_.resize(size());
  const float scale = -dt * dt * backgroundPressure_ / restDensity_ * massOverRho_;
  parallelFor(0, size(), [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      const VecD pi = p_[i];
      const float inverseSquareI = 1.0f / (densityRatio_[i] * densityRatio_[i]);
      float unusedWeight = 0;
      VecD wallGradient = VecD::Zero();
      walls_.add(pi, unusedWeight, wallGradient);
      VecD sum = (2.0f * inverseSquareI) * wallGradient;
      for (const uint32_t* j = neighbors_.begin(i); j != neighbors_.end(i); ++j) {
        const VecD r = pairOffset(i, *j, pi);
        const float inverseSquareJ = 1.0f / (densityRatio_[*j] * densityRatio_[*j]);
        sum += ((inverseSquareI + inverseSquareJ) * kernelPair(r.squaredNorm()).gradientFactor) * r;
      }
      transportPush_[i] = (inverseMassRatio_.empty() ? scale : scale * inverseMassRatio_[i]) * sum;
    }
  });
  moveBy(transportPush_);
}

// v_i -= push_i / dt after line 21: the momentum does not feel p_b.
template <int Dim>
void PbfSolver<Dim>::removePushFromVelocities(float dt) {
  const float inverseDt = 1.0f / dt;
  parallelFor(0, size(), [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) v_[i] -= inverseDt * transportPush_[i];
  });
}

template void PbfSolver<2>::prepareFilledDomain(float);
template void PbfSolver<3>::prepareFilledDomain(float);
template void PbfSolver<2>::removePushFromVelocities(float);
template void PbfSolver<3>::removePushFromVelocities(float);

}  // namespace surge
