// Spray, foam and bubbles from the saved particle frames, after Ihmsen, Akinci, Akinci and Teschner 2012,
// "Unified spray, foam and bubbles for particle-based fluids" (the paper's section numbers beside the code).
// Between two fluid frames the fluid is interpolated in time, particle by particle (matched by id), and the
// diffuse particles advance through it in substeps; new ones are made from the first frame's potentials.
// Every random number is a hash of (frame, parent id, draw), and every loop writes only its own particle, so
// the result does not depend on the thread count; a frame holds all the state, so a resumed run is exact.
#pragma once

#include <cstdint>
#include <vector>

#include "core/ply.h"
#include "core/scene.h"
#include "geometry/collider_shape.h"
#include "geometry/pose.h"
#include "sim/neighbor_grid.h"

namespace surge {

// What the last advance did.
struct WhitewaterCounts {
  size_t spray = 0, foam = 0, bubbles = 0;  // at the frame's end
  size_t born = 0, died = 0;
  int substeps = 0;
};

class WhitewaterStepper {
 public:
  explicit WhitewaterStepper(const Scene& scene);  // a resolved scene with whitewater keys

  // Advances `diffuse` from frame `frame` to frame + 1, through the fluid frames `a` (frame) and `b` (frame + 1).
  void advance(const ParticleFrame& a, const ParticleFrame& b, int frame, DiffuseFrame& diffuse);
  const WhitewaterCounts& counts() const { return counts_; }

  // Ihmsen's three potentials of each particle of `a` (section 4), each clamped to [0, 1] by its thresholds
  // (eq. 1), and the diffuse particles each would make over one frame (eq. 9, per T).
  struct Potentials {
    std::vector<float> trappedAir, waveCrest, kinetic, generated;
  };
  Potentials potentials(const ParticleFrame& a);

  // The rest lattice's sum of Ihmsen's weight 1 - r / h over a particle's neighbours (S of WhitewaterSettings).
  double restSum() const { return restSum_; }

 private:
  struct FluidSample {
    int neighbors = 0;
    Eigen::Vector3f velocity = Eigen::Vector3f::Zero();  // Shepard average (eq. 13), zero without neighbours
  };
  // The fluid at a point, from the grid of the substep's interpolated fluid.
  FluidSample sampleFluid(const Eigen::Vector3f& p) const;
  void sortFluid(const std::vector<Eigen::Vector3f>& x, const std::vector<Eigen::Vector3f>& v);
  // Sorts `fluid` into the grid; on a periodic domain with its images within two kernel radii of each periodic
  // face after it (withPeriodicImages), so that the grid (the domain and two radii about it) finds neighbours
  // across the seam. Two radii: an image's own surface normal (eq. 4's n_j) is whole where it is a neighbour.
  void sortFluidAndImages(const ParticleFrame& fluid);

  // visit(slot, r2) for each fluid particle of the sorted grid within h of p.
  template <typename Visit>
  void forEachFluidNear(const Eigen::Vector3f& p, Visit&& visit) const;

  // Moves p out of the colliders as they stand at `time` (their poses), taking the velocity's part into them
  // away; false if p is spray that met one (it breaks there).
  bool meetColliders(Eigen::Vector3f& p, Eigen::Vector3f& v, bool spray, const std::vector<Pose>& poses) const;

  const Scene& scene_;
  std::vector<ColliderShape> colliders_;  // the scene's colliders (not its bodies), in their own frames
  const WhitewaterSettings& settings_;
  float h_, restSum_, speed_, timeScale_, frameTime_;
  Eigen::Vector3f gravity_, tankMin_, tankMax_;
  PeriodicDomain<3> periodic_;
  NeighborGrid<3> grid_;
  std::vector<Eigen::Vector3f> sortedX_, sortedV_;  // the fluid in the grid's order
  std::vector<float> coordinates_;                   // sortedX_ as x, y and z arrays, for keepInRange
  NeighborLists lists_;                              // the fluid's own neighbours, for the potentials
  WhitewaterCounts counts_;
};

}  // namespace surge
