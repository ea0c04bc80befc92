// The scene's colliders as the solvers see them: each shape (geometry/collider_shape.h) placed at the end of
// the current step, and
//  - its share of a particle's density and density gradient: the tank's flat-wall table (sim/tank.h) read at
//    the particle's signed distance, along the shape's normal there (the rest lattice continued beyond a wall
//    that is taken locally flat; docs/colliders.md measures what that does at curved walls);
//  - the collision response: a particle's move is swept against the shape (sphere tracing the signed distance,
//    never a step longer than a quarter spacing inside the near band), so a wall one spacing thick cannot be
//    crossed, and a particle that would end closer than its radius stops on the surface and keeps the part of
//    its move along it;
//  - friction on the velocity relative to the wall, of the particles touching it: `friction` of it taken away
//    over each 1/30 s of contact (the same at any step), all of it at 1;
//  - the force and torque the fluid exerts on each collider: every impulse a collider gives a particle is
//    summed per collider, per chunk of 1024 particles (so the sums are the same at any thread count), and
//    turned into the frame's mean force and torque for colliders.csv.
// A rigid body (sim/rigid_bodies.h) is a collider whose pose is set each step (setBodyPose) rather than
// scripted; the scene's colliders come first, then its bodies (bodyIndex).
// A scene without colliders or bodies has an empty Colliders: every call returns at once.
//
// The tank is the box container that every scene has; it stays in TankWalls, whose edges and corners are
// tabulated exactly, and Boundary below adds the two for the solvers.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "core/ply.h"
#include "core/scene.h"
#include "geometry/collider_shape.h"
#include "geometry/pose.h"
#include "sim/kernels.h"
#include "sim/tank.h"

namespace surge {

struct Wrench {
  Eigen::Vector3d force = Eigen::Vector3d::Zero(), torque = Eigen::Vector3d::Zero();
  // The work the solid did on the fluid (J): each impulse it gave a particle dotted with its own velocity there
  // (summed as the impulses are; 0 for a solid standing still). The energy ledger's share of a moving solid.
  double work = 0;
};

// The shapes of the scene's colliders, then of its bodies, in the scene's order.
using ColliderShapes = std::vector<ColliderShape>;

// Builds every collider and body shape of the scene (reads files, bakes mesh distances); InputError on bad input.
std::shared_ptr<const ColliderShapes> buildColliderShapes(const Scene& scene);

// True if the scene has colliders or bodies: the fluid meets solids other than the tank.
inline bool hasSolids(const Scene& scene) { return !scene.colliders.empty() || !scene.bodies.empty(); }

template <int Dim>
class Colliders {
 public:
  using VecD = Vec<Dim>;
  static constexpr size_t kChunk = 1024;  // particles per force-sum slot (parallelFor's default grain)
  static constexpr double kFrictionTime = 1.0 / 30;  // friction's fraction is taken away over this long

  Colliders() = default;
  // `tank` must outlive this object (the solver holds both).
  Colliders(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes, const TankWalls<Dim>& tank);

  bool empty() const { return placed_.empty(); }
  size_t size() const { return placed_.size(); }
  bool hasFriction() const { return hasFriction_; }
  // True if some collider or body moves (a distance found at one step then need not hold at the next).
  bool anyMoving() const {
    return std::any_of(placed_.begin(), placed_.end(), [](const Placed& k) { return k.moving; });
  }

  // Places the colliders for a step from `time` to `time + dt`, at its end; each wall's velocity is its motion
  // over the step.
  void beginStep(double time, float dt);
  // Places every solid where it stands at `time`, the start of a step of dt: a keyframed collider moving as over
  // [time - dt, time], a body at its pose before the last setBodyPose, moving as over the coming step. From
  // (time, dt) and the bodies' poses alone: a run resumed from a frame places them as the uninterrupted run.
  void placeAtStepStart(double time, float dt);

  // Bodies: solid firstBody() + b is body b. setBodyPose gives body b's pose at the end of the coming step (its
  // pose at the step's start is the one given before) and its centre of mass there, about which its torque is
  // summed.
  size_t firstBody() const { return firstBody_; }
  void setBodyPose(size_t body, const Pose& pose, const Eigen::Vector3d& centreOfMass);

  // Calls visit(c, distance, normal) for every collider whose surface is within the kernel support of p, in
  // the colliders' order.
  template <typename Visit>
  void forEachNear(const VecD& p, Visit&& visit) const {
    forEachCandidate(
        p,
        [&](size_t c, float d, const VecD& n) {
          if (d < support_) visit(c, d, n);
        },
        [] {});
  }

  // True if no collider's near box comes within kFarMargin radii of p's grid cell: forEachNear(p) then finds
  // nothing, and nothing stops a move to p shorter than kFarReach radii (moveFarFrom; the radius between is
  // slack for the tank's clamp and for rounding). Most of a pool is that far from its floating bodies.
  bool farFrom(const VecD& p) const {
    size_t cell;
    return cellOf(p, cell) && !cellReached_[cell];
  }
  bool moveFarFrom(const VecD& from, const VecD& p) const {
    return (p - from).squaredNorm() < kFarReach * kFarReach * radius_ * radius_ && farFrom(p);
  }

  // Collider c's share of sum_b W(p - p_b) (weight) and sum_b grad_p W(p - p_b) (gradient) at p, at distance d
  // along the normal n. A box (boxTerms) counts the lattice beyond its faces, edges and corners exactly, by
  // the tank's tables; every other shape counts the flat wall's, less what it shares with a tank wall it stands
  // square on (`sharesTank`: the tank's walls count the lattice beyond them, TankWalls::add; WCSPH's mirror images
  // of the fluid do not).
  void wallTerms(size_t c, const VecD& p, float d, const VecD& n, float& weight, VecD& gradient,
                 bool sharesTank = true) const {
    if (placed_[c].exactBox && d > 0) {
      boxTerms(placed_[c], p, weight, gradient);
      return;
    }
    float w, g;
    tank_->flatWall().lookup(d, w, g);
    weight = w;
    gradient = -g * n;
    if (sharesTank) tank_->subtractOverlap(p, d, n, weight, gradient);
  }

  // WCSPH's pressure in the wall, continued from the particle's own by the hydrostatic gradient (Adami, Hu and
  // Adams 2012, eq. 27, without the wall's acceleration): p_b = p_i + rho_i g . (x_b - x_i). Returns
  // sum_b (g . (x_b - x_i)) grad W(x_i - x_b) over the flat wall at d along n; the wall's push on the particle
  // gains -m / rho_i times it. Mirroring p_i alone (p_b = p_i) pushes too hard on a particle below a wall and
  // too softly above one: a ball under water read 27% over Archimedes in 3D (docs/colliders.md).
  // A box sums it over its exact lattice (boxTerms; a corner's eighth left out).
  VecD hydrostaticSum(size_t c, const VecD& p, float d, const VecD& n, const VecD& g) const {
    if (placed_[c].exactBox && d > 0) return boxHydrostaticSum(placed_[c], p, g);
    return tank_->flatWall().hydrostaticSum(d, n, g);
  }

  // What add found at p, for a solver that reuses it at the same p (PBF's correction after its lambda pass): a
  // lower bound on p's distance to every collider (-infinity near a shape whose distance is an estimate), how
  // many lie within the support, and for exactly one, which.
  struct Found {
    float clearance = 0;
    uint16_t count = 0, only = 0;
  };

  // Adds every collider's share of the density sums at p (as TankWalls::add does for the tank); `found` and,
  // for a single collider, its gradient `onlyGradient` say what it found.
  // A collider whose near box does not hold p is more than support + radius away, one that is not even a
  // candidate more than the grid's margin further; a particle far from all (farFrom) is given the support alone
  // (it is further), so that add runs for it again at the next pass, where its cell check is all it costs.
  void add(const VecD& p, float& weight, VecD& gradient, Found& found, VecD& onlyGradient,
           bool sharesTank = true) const {
    found = Found{support_ + radius_ + kGridMargin * radius_, 0, 0};
    const bool near = forEachCandidate(
        p,
        [&](size_t c, float d, const VecD& n) {
          found.clearance = std::min(found.clearance, placed_[c].shape->distanceBoundsMoves() ? d : -INFINITY);
          if (d >= support_) return;
          float w;
          VecD g;
          wallTerms(c, p, d, n, w, g, sharesTank);
          weight += w;
          gradient += g;
          if (found.count++ == 0) {
            found.only = static_cast<uint16_t>(c);
            onlyGradient = g;
          }
        },
        [&] { found.clearance = std::min(found.clearance, support_ + radius_); });
    if (!near) found.clearance = support_;
  }
  void add(const VecD& p, float& weight, VecD& gradient, bool sharesTank = true) const {
    Found unused;
    VecD unusedGradient;
    add(p, weight, gradient, unused, unusedGradient, sharesTank);
  }

  // True if nothing stops a move from `from`, where add found `found`, to p: every point of the move stays a
  // radius (and a hundredth, for rounding) from every collider, and so does the tank's clamp of p (which moves
  // it no further from `from`, `from` being inside the clamp): project and its corner rounds would do nothing.
  bool nothingStops(const Found& found, const VecD& from, const VecD& p) const {
    const float room = found.clearance - 1.01f * radius_;
    return room > 0 && (p - from).squaredNorm() < room * room;
  }
  // Carries `found` from `from` to p: a distance less the move is still a bound. While it keeps a particle clear
  // of the support, add would find nothing at p (clearOfSupport) and need not run; while it leaves room, the
  // next move need not be swept (nothingStops). Its count and gradient are those at `from`: a solver reads them
  // only where add has just run.
  void carry(Found& found, const VecD& from, const VecD& p) const { found.clearance -= (p - from).norm(); }
  bool clearOfSupport(const Found& found) const { return found.clearance > support_ + 0.01f * radius_; }

  // Signed distance from p to collider c's solid in the world (negative inside) and the unit normal there.
  float distance(size_t c, const VecD& p, VecD& normal) const;

  // The collision response for a move from `from` to p (see the header comment). The move is swept in each
  // collider's own frame: `from` as it stood at the step's start when fromStepStart (the first move of a step),
  // else at its end, p at the end; so a moving wall meets a particle with the face that moves into it. Calls
  // pushed(c, delta) for each collider that moved p by delta; returns true if any did.
  template <typename Pushed>
  bool project(const VecD& from, VecD& p, bool fromStepStart, Pushed&& pushed) const {
    if (moveFarFrom(from, p)) return false;
    bool moved = false;
    // A move shorter than kShortMove, and the pushes it may take, stay within the grid's margin of p's cell.
    const uint16_t *c = all_.data(), *end = all_.data() + all_.size();
    if ((p - from).squaredNorm() < kShortMove * kShortMove * radius_ * radius_) candidates(p, c, end);
    for (; c != end; ++c) {
      VecD delta;
      if (sweep(*c, from, p, fromStepStart, delta)) {
        p += delta;
        pushed(*c, delta);
        moved = true;
      }
    }
    return moved;
  }

  // The velocity of collider c's surface at p over the current step.
  VecD wallVelocity(size_t c, const VecD& p) const;
  // True if solid c turns over the current step; then spinAcross(c, n) is Omega x n, its rigid velocity's change
  // across the vector n.
  bool turning(size_t c) const {
    return placed_[c].moving && dt_ > 0 && placed_[c].rotation != placed_[c].previousRotation;
  }
  VecD spinAcross(size_t c, const VecD& n) const;
  float friction(size_t c) const { return placed_[c].friction; }
  float particleRadius() const { return radius_; }

  // Particles within this distance of a collider touch it (friction acts on them).
  float contactDistance() const { return 1.5f * radius_; }

  // Force bookkeeping. resetSlots once the particle count is known; addImpulse(i, c, J, x) records that
  // collider c gave particle i (at x) the impulse J, from inside a parallel loop whose chunks are multiples of
  // kChunk; takeFrameWrenches returns each collider's mean force and torque (about its position) over the
  // frame's `duration`, and the work it did on the fluid in it, and starts the next frame.
  void resetSlots(size_t particles);
  // For a new particle count between steps (emitters, sinks): the impulses recorded so far move to the frame's
  // sums, so the frame's wrench keeps them.
  void resizeSlots(size_t particles) {
    addWrenches(takeSlotSums(), 1.0);
    resetSlots(particles);
  }
  void addImpulse(size_t particle, size_t c, const VecD& impulse, const VecD& at) {
    addImpulseOnSolid(particle, c, impulse, at);  // the fluid pushes the collider back
    if (placed_[c].moving)
      slots_[(particle / kChunk) * placed_.size() + c].work += double(impulse.dot(wallVelocity(c, at)));
  }
  // The same for an impulse the solid takes that the particle does not (the viscous strain's traction, sim/
  // viscosity.h): force and torque, no work on the fluid.
  void addImpulseOnSolid(size_t particle, size_t c, const VecD& impulse, const VecD& at) {
    Wrench& w = slots_[(particle / kChunk) * placed_.size() + c];
    Eigen::Vector3d j = Eigen::Vector3d::Zero(), r = Eigen::Vector3d::Zero();
    j.head<Dim>() = impulse.template cast<double>();
    r.head<Dim>() = (at - placed_[c].centre).template cast<double>();
    w.force -= j;
    w.torque -= r.cross(j);
  }
  std::vector<Wrench> takeFrameWrenches(double duration);
  // Every solid's mean force and torque over the step of length dt just taken (the bodies' coupling); the
  // frame's sums go on.
  std::vector<Wrench> takeStepWrenches(double dt);
  // The slots summed per collider (in slot order) and cleared: for a solver that records forces rather than
  // impulses (WCSPH), which then adds them times their time span with addWrenches.
  std::vector<Wrench> takeSlotSums();
  void addWrenches(const std::vector<Wrench>& wrenches, double scale);

  // Friction: removes the fraction `friction` of the velocity along the wall, relative to the wall, of a
  // particle (index i, mass m) touching a collider, and records the impulse.
  void applyFriction(size_t i, const VecD& x, VecD& v, float mass);

  size_t memoryBytes() const;

 private:
  struct Placed {
    const ColliderShape* shape = nullptr;
    Eigen::Matrix3f rotation = Eigen::Matrix3f::Identity(), previousRotation = Eigen::Matrix3f::Identity();
    Eigen::Vector3f translation = Eigen::Vector3f::Zero(), previousTranslation = Eigen::Vector3f::Zero();
    float scale = 1;
    VecD centre = VecD::Zero();
    Eigen::AlignedBox<float, Dim> near;  // particles outside it are beyond the support
    float friction = 0, frictionThisStep = 0;
    bool moving = false;
    // A box counted exactly (boxTerms): its faces in its frame at boxMin and boxMax (metres), cut back to the
    // tank where it reaches through a wall it is square to.
    bool exactBox = false;
    Eigen::Vector3f boxMin = Eigen::Vector3f::Zero(), boxMax = Eigen::Vector3f::Zero();
  };

  // The lattice beyond a box (Placed::exactBox) from p outside it: along each of its axes the fluid's side of
  // the box is one or two half-spaces beyond its faces (or everything, between them); the solid is their
  // product over the axes, expanded into intersections of half-spaces on distinct axes, each one of the tank's
  // tables (a face, an edge's quarter, a corner's eighth), with signs (inclusion-exclusion).
  void boxTerms(const Placed& k, const VecD& p, float& weight, VecD& gradient) const;
  VecD boxHydrostaticSum(const Placed& k, const VecD& p, const VecD& gravity) const;
  // Decides Placed::exactBox for a box placed by beginStep.
  void placeBox(Placed& k) const;

  bool sweep(size_t c, const VecD& from, const VecD& p, bool fromStepStart, VecD& delta) const;

  // Calls reach(c, distance, normal) for every candidate collider whose near box holds p and missed() for every
  // other candidate, in the colliders' order; returns false, calling nothing, for a p far from all (farFrom).
  template <typename Reach, typename Missed>
  bool forEachCandidate(const VecD& p, Reach&& reach, Missed&& missed) const {
    if (farFrom(p)) return false;
    const uint16_t *c = nullptr, *end = nullptr;
    candidates(p, c, end);
    for (; c != end; ++c) {
      if (!placed_[*c].near.contains(p)) {
        missed();
        continue;
      }
      VecD normal;
      const float d = distance(*c, p, normal);
      reach(*c, d, normal);
    }
    return true;
  }

  // The colliders whose near boxes, grown by the grid's margin, reach the grid cell of p (every collider for a
  // p off the grid), ascending: a particle tests those only, not all of them (ten floating bodies cost 17% of a
  // step when every particle tested every one). Built by beginStep over the tank, cells at least the kernel
  // support and at most 64 a side.
  void candidates(const VecD& p, const uint16_t*& begin, const uint16_t*& end) const {
    size_t index;
    if (!cellOf(p, index)) {
      begin = all_.data();
      end = all_.data() + all_.size();
      return;
    }
    begin = cellSolids_.data() + cellStart_[index];
    end = cellSolids_.data() + cellStart_[index + 1];
  }
  // The index of p's grid cell; false for a p off the grid (or NaN).
  bool cellOf(const VecD& p, size_t& index) const {
    Eigen::Array<int, Dim, 1> cell;
    for (int k = 0; k < Dim; ++k) {
      const float u = (p[k] - gridMin_[k]) * cellInverse_[k];
      if (!(u >= 0 && u < gridCounts_[k])) return false;
      cell[k] = static_cast<int>(u);
    }
    index = cell[Dim - 1];
    for (int k = Dim - 2; k >= 0; --k) index = index * gridCounts_[k] + cell[k];
    return true;
  }
  void buildGrid();
  static constexpr float kShortMove = 4;  // in particle radii
  static constexpr float kGridMargin = kShortMove + 2 * kShortMove + 2;  // see buildGrid
  static constexpr float kFarMargin = 4, kFarReach = 2;  // in particle radii; see farFrom

  std::shared_ptr<const ColliderShapes> shapes_;
  std::vector<ColliderSettings> settings_;
  std::vector<Placed> placed_;
  const TankWalls<Dim>* tank_ = nullptr;
  float support_ = 0, radius_ = 0, dt_ = 1;
  bool hasFriction_ = false;
  std::vector<Wrench> slots_, extra_, stepMark_;
  std::vector<uint8_t> cellReached_;  // 1 for a cell that some near box, grown by kFarMargin radii, reaches
  std::vector<uint16_t> all_, cellSolids_;
  std::vector<uint32_t> cellStart_;
  VecD gridMin_ = VecD::Zero(), cellInverse_ = VecD::Zero();
  Eigen::Array<int, Dim, 1> gridCounts_ = Eigen::Array<int, Dim, 1>::Zero();
  size_t firstBody_ = 0;
  std::vector<Pose> bodyStart_, bodyEnd_;
  std::vector<Eigen::Vector3d> bodyCentre_;
};

// Removes from `frame` the particles closer to a collider than 0.99 of their radius, with the colliders as
// they are placed (at time 0 before the first step), renumbering the ids; returns how many were removed. A
// fluid box drawn against a wall keeps its layer a radius from it.
template <int Dim>
size_t removeParticlesInside(const Colliders<Dim>& colliders, ParticleFrame& frame);

// Moves every particle by dt v (x += dt v), stopped at the colliders and the tank: the collision
// response. A particle stopped at a collider loses its velocity into it, relative to the wall's own, and that
// change is the collider's impulse; friction acts on the particles touching one; at a tank wall the particle is
// clamped a radius inside and loses its velocity into that wall. A particle's mass is referenceMass times its
// massRatio (ParticleSolver::massRatios; empty: all referenceMass). With `push` (the transport velocity's
// accelerations, Adami et al. 2013) the particle moves with v + pushScale push, and the stops act on v alone.
template <int Dim>
void driftAgainstSolids(std::vector<Vec<Dim>>& x, std::vector<Vec<Dim>>& v, float dt, float referenceMass,
                        const std::vector<float>& massRatio, Colliders<Dim>& colliders, const TankWalls<Dim>& walls,
                        const std::vector<Vec<Dim>>* push = nullptr, float pushScale = 0);

// The tank and the colliders together, as the measures see them.
template <int Dim>
struct Boundary {
  const TankWalls<Dim>& tank;
  const Colliders<Dim>& colliders;

  void add(const Vec<Dim>& p, float& weight, Vec<Dim>& gradient) const {
    tank.add(p, weight, gradient);
    if (!colliders.empty()) colliders.add(p, weight, gradient);
  }
  bool contains(const Vec<Dim>& p) const { return tank.contains(p); }
};

extern template class Colliders<2>;
extern template class Colliders<3>;

}  // namespace surge
