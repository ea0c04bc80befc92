// The diffuse particles' motion (whitewater/whitewater.h) against closed forms: a spray particle's projectile with
// linear air drag, a bubble's rise to its terminal velocity in still water, foam on a rigidly turning pool, foam
// carried round a periodic seam, and a sheared stream that makes as much by the seam as in its middle.
#include "whitewater/whitewater.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <string>

namespace surge {
namespace {

Scene whitewaterScene(const std::string& extra = "") {
  return parseScene(R"({"name": "ww", "dimensions": 3, "domain": {"min": [0, 0, 0], "max": [1, 1, 1]},
    "particle_spacing": 0.02, "fluids": [{"box": {"min": [0, 0, 0], "max": [0.2, 0.2, 0.2]}}],
    "output": {"fps": 30, "frames": 10}, "whitewater": {"enabled": 1, "lifetime_min": 100, "lifetime_max": 100)" +
                        extra + "}}",
                    "test");
}

DiffuseFrame oneParticle(const Eigen::Vector3f& x, const Eigen::Vector3f& v, uint8_t type) {
  DiffuseFrame d;
  d.resize(1);
  d.position[0] = x;
  d.velocity[0] = v;
  d.id[0] = 0;
  d.type[0] = type;
  d.lifetime[0] = 100;
  d.nextId = 1;
  return d;
}

// Fluid on the lattice of `spacing` filling [lo, hi), at rest.
ParticleFrame block(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, float spacing) {
  ParticleFrame f;
  uint32_t id = 0;
  for (float z = lo.z() + spacing / 2; z < hi.z(); z += spacing)
    for (float y = lo.y() + spacing / 2; y < hi.y(); y += spacing)
      for (float x = lo.x() + spacing / 2; x < hi.x(); x += spacing) {
        f.position.emplace_back(x, y, z);
        f.velocity.emplace_back(0, 0, 0);
        f.id.push_back(id++);
      }
  return f;
}

// With no fluid about, spray flies as a projectile with drag k: v(t) = v_inf + (v0 - v_inf) e^(-k t), v_inf = g / k.
// The stepper integrates that exactly over each substep in double; what is left is float32 rounding of positions
// near 1 m (ulp 1.2e-7) over a few dozen substeps, so 1e-5 m and 1e-5 m/s.
TEST(Whitewater, SprayFollowsTheProjectileWithItsDrag) {
  const Scene scene = whitewaterScene(R"(, "spray_drag": 0.8)");
  WhitewaterStepper stepper(scene);
  const Eigen::Vector3d x0(0.2, 0.5, 0.3), v0(1.5, 3.0, 0.5), g(0, -9.81, 0);
  DiffuseFrame spray = oneParticle(x0.cast<float>(), v0.cast<float>(), kSpray);
  const ParticleFrame none;
  const double k = 0.8, frameTime = 1.0 / 30;
  int substeps = 0;
  for (int f = 0; f < 12; ++f) {
    stepper.advance(none, none, f, spray);
    substeps += stepper.counts().substeps;
    ASSERT_EQ(spray.size(), 1u);
    EXPECT_EQ(spray.type[0], kSpray);
    const double t = (f + 1) * frameTime;
    const Eigen::Vector3d terminal = g / k;
    const Eigen::Vector3d x = x0 + terminal * t + (v0 - terminal) * (1 - std::exp(-k * t)) / k;
    const Eigen::Vector3d v = terminal + (v0 - terminal) * std::exp(-k * t);
    EXPECT_LT((spray.position[0].cast<double>() - x).norm(), 1e-5) << "frame " << f + 1;
    EXPECT_LT((spray.velocity[0].cast<double>() - v).norm(), 1e-5) << "frame " << f + 1;
  }
  EXPECT_GT(substeps, 12);  // it took substeps within frames
  EXPECT_EQ(stepper.counts().born, 0u);
}

// A bubble deep in still water: dv/dt = -b g + d (0 - v), so it rises at b |g| / d, reached as 1 - e^(-d t).
// The fluid's velocity at it is exactly zero, so the bound is float rounding again.
TEST(Whitewater, ABubbleInStillWaterRisesAtItsTerminalVelocity) {
  const Scene scene = whitewaterScene(R"(, "bubble_buoyancy": 2, "bubble_drag": 20)");
  WhitewaterStepper stepper(scene);
  const ParticleFrame water = block({0, 0, 0}, {0.4f, 0.6f, 0.4f}, 0.02f);
  DiffuseFrame bubble = oneParticle({0.2f, 0.05f, 0.2f}, {0, 0, 0}, kBubble);
  const double terminal = 2 * 9.81 / 20;
  for (int f = 0; f < 9; ++f) {
    stepper.advance(water, water, f, bubble);
    ASSERT_EQ(bubble.size(), 1u) << "still water makes no whitewater";
    EXPECT_EQ(bubble.type[0], kBubble);
  }
  const double t = 9.0 / 30;
  EXPECT_NEAR(bubble.velocity[0].y(), terminal * (1 - std::exp(-20 * t)), 1e-5);
  EXPECT_NEAR(bubble.velocity[0].y(), terminal, 0.01 * terminal);  // e^-6: at its terminal velocity
  EXPECT_NEAR(bubble.position[0].y(), 0.05 + terminal * (t - (1 - std::exp(-20 * t)) / 20), 1e-5);
  EXPECT_LT(std::abs(bubble.velocity[0].x()) + std::abs(bubble.velocity[0].z()), 1e-6);
}

// Foam on the top of a pool turning as a rigid body at 2 rad/s rides the fluid's velocity round its circle.
// Midpoint steps of angle theta = omega dt grow a circle's radius by theta^4 / 8 a step: 2e-4 over the turn's
// 94 steps. The fluid's positions are interpolated linearly between frames (a chord, cos(theta / 2) - 1 = -6e-4
// at most, between frames only), and the fluid's velocity at a point is a linear fit, exact for a rigid motion
// up to its regularisation (1e-3 h^2 against the neighbours' spread of about h^2 / 4: 0.4% of the correction).
// So 0.5% of the radius, a twentieth of a spacing at 0.2 m (measured: 0.02%, 0.11%, 0.14% at 0.1, 0.15, 0.2 m).
// Shepard's average alone drifted 2.4% outward, forward Euler 21%.
TEST(Whitewater, FoamOnARigidlyRotatingPoolStaysOnItsCircle) {
  const Scene scene = whitewaterScene();
  WhitewaterStepper stepper(scene);
  const float omega = 2, fps = 30;
  const Eigen::Vector3f centre(0.5f, 0, 0.5f);
  ParticleFrame pool;
  for (const auto& [x, v, id] : [&] {
         std::vector<std::tuple<Eigen::Vector3f, Eigen::Vector3f, uint32_t>> sites;
         const ParticleFrame box = block({0.18f, 0, 0.18f}, {0.82f, 0.1f, 0.82f}, 0.02f);
         for (size_t i = 0; i < box.size(); ++i)
           if (Eigen::Vector2f(box.position[i].x() - centre.x(), box.position[i].z() - centre.z()).norm() < 0.3f)
             sites.emplace_back(box.position[i], Eigen::Vector3f::Zero(), box.id[i]);
         return sites;
       }()) {
    (void)v;
    pool.position.push_back(x);
    pool.velocity.push_back(Eigen::Vector3f::Zero());
    pool.id.push_back(id);
  }
  auto turned = [&](float t) {
    ParticleFrame f = pool;
    const float c = std::cos(omega * t), s = std::sin(omega * t);
    for (size_t i = 0; i < f.size(); ++i) {
      const Eigen::Vector3f r = pool.position[i] - centre;
      const Eigen::Vector3f q(c * r.x() + s * r.z(), r.y(), -s * r.x() + c * r.z());
      f.position[i] = centre + q;
      f.velocity[i] = Eigen::Vector3f(omega * q.z(), 0, -omega * q.x());  // omega about +y
    }
    return f;
  };
  DiffuseFrame foam;
  const float radii[3] = {0.1f, 0.15f, 0.2f};
  for (int k = 0; k < 3; ++k) {
    const DiffuseFrame one = oneParticle(centre + Eigen::Vector3f(radii[k], 0.1f, 0), {0, 0, 0}, kFoam);
    foam.position.push_back(one.position[0]);
    foam.velocity.push_back(one.velocity[0]);
    foam.id.push_back(uint32_t(k));
    foam.type.push_back(kFoam);
    foam.lifetime.push_back(100);
  }
  foam.nextId = 3;
  const int frames = int(std::ceil(2 * M_PI / omega * fps));
  ParticleFrame a = turned(0);
  std::vector<float> firstHeight;
  for (int f = 0; f < frames; ++f) {
    const ParticleFrame b = turned(float(f + 1) / fps);
    stepper.advance(a, b, f, foam);
    a = b;
    ASSERT_EQ(foam.size(), 3u);
    if (f == 0) firstHeight = {foam.position[0].y(), foam.position[1].y(), foam.position[2].y()};
    EXPECT_EQ(stepper.counts().born, 0u) << "a rigid turn makes no whitewater";
  }
  for (size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(foam.type[k], kFoam);
    const Eigen::Vector3f r = foam.position[k] - centre;
    const float radius = Eigen::Vector2f(r.x(), r.z()).norm();
    EXPECT_NEAR(radius, radii[k], 0.005f * radii[k]) << "foam " << k;
    // On the surface: above the top layer (y = 0.09), below a spacing over it, where the first frame left it
    // (one just under the top may take a bubble's rise to it first).
    EXPECT_GT(r.y(), 0.09f);
    EXPECT_LT(r.y(), 0.12f);
    EXPECT_NEAR(r.y(), firstHeight[k], 1e-4f) << "foam " << k;
    // It went round: back within a tenth of a turn of where it started (the surface turns a little slower
    // than the fluid's rim, the Shepard average reaching inward).
    const float angle = std::atan2(-r.z(), r.x());
    EXPECT_LT(std::abs(std::remainder(angle - omega * float(frames) / fps, float(2 * M_PI))), 0.63f) << "foam " << k;
  }
}

// Spray breaks on a collider (without it the same throw flies on); a bubble that finds itself inside one is moved
// out onto its surface.
TEST(Whitewater, SprayBreaksOnAColliderAndBubblesStayOutOfIt) {
  const std::string box = R"(, "colliders": [{"shape": "box", "position": [0.6, 0.5, 0.5], "size": [0.2, 0.2, 0.2]}])";
  const Scene scene = parseScene(R"({"name": "ww", "dimensions": 3, "domain": {"min": [0, 0, 0], "max": [1, 1, 1]},
    "particle_spacing": 0.02, "fluids": [{"box": {"min": [0, 0, 0], "max": [0.2, 0.2, 0.2]}}],
    "output": {"fps": 30, "frames": 10}, "whitewater": {"enabled": 1, "lifetime_min": 100, "lifetime_max": 100}
    )" + box + "}", "test");
  const Scene open = whitewaterScene();
  const ParticleFrame none;
  for (const Scene* s : {&scene, &open}) {
    WhitewaterStepper stepper(*s);
    DiffuseFrame spray = oneParticle({0.3f, 0.5f, 0.5f}, {3, 0, 0}, kSpray);
    for (int f = 0; f < 4; ++f) stepper.advance(none, none, f, spray);
    EXPECT_EQ(spray.size(), s == &scene ? 0u : 1u) << (s == &scene ? "through the box" : "without the box");
  }
  WhitewaterStepper stepper(scene);
  const ParticleFrame water = block({0, 0, 0}, {1, 0.8f, 1}, 0.02f);
  DiffuseFrame bubble = oneParticle({0.62f, 0.45f, 0.5f}, {0, 0, 0}, kBubble);
  stepper.advance(water, water, 0, bubble);
  ASSERT_EQ(bubble.size(), 1u);
  const Eigen::Vector3f p = bubble.position[0];
  const Eigen::Vector3f inside = (p - Eigen::Vector3f(0.6f, 0.5f, 0.5f)).cwiseAbs();
  EXPECT_GE(inside.maxCoeff(), 0.1f - 1e-5f) << "the bubble is inside the box at " << p.transpose();
}

// A layer 0.1 deep filling a domain periodic along x, flowing along x at U = 2 m/s: frame f is the layer moved
// U f / fps and brought back into the domain. Walled at x = 0 and 1 (periodic = false) it is a slab whose ends
// move.
Scene streamScene(bool periodic) {
  return parseScene(std::string(R"({"name": "stream", "dimensions": 3,
    "domain": {"min": [0, 0, 0], "max": [1, 1, 1])") + (periodic ? R"(, "periodic": ["x"])" : "") + R"(},
    "particle_spacing": 0.02, "fluids": [{"box": {"min": [0, 0, 0.3], "max": [1, 0.1, 0.7]}}],
    "output": {"fps": 30, "frames": 10}, "whitewater": {"enabled": 1, "lifetime_min": 100, "lifetime_max": 100}})",
                    "test");
}

ParticleFrame stream(int frame) {
  const float speed = 2, moved = speed * float(frame) / 30;
  ParticleFrame f = block({0, 0, 0.3f}, {1, 0.1f, 0.7f}, 0.02f);
  for (size_t i = 0; i < f.size(); ++i) {
    f.position[i].x() = std::fmod(f.position[i].x() + moved, 1.0f);
    f.velocity[i] = {speed, 0, 0};
  }
  return f;
}

// Foam on the stream rides it round the seam: one starting 5 cm before the seam and one 20 spacings behind it
// keep the stream's speed (the fitted velocity is exact for a uniform flow), the same kind (they see the same
// lattice about them) and their distance along x, every frame while each crosses the seam once. Unwrapped, the first would meet the wall at
// x = 1; without the images across the seam it would see half its neighbours there.
TEST(Whitewater, FoamRidesAStreamRoundAPeriodicSeam) {
  const Scene scene = streamScene(true);  // the stepper keeps a reference
  WhitewaterStepper stepper(scene);
  DiffuseFrame foam = oneParticle({0.95f, 0.095f, 0.5f}, {2, 0, 0}, kFoam);
  foam.position.push_back({0.55f, 0.095f, 0.5f});
  foam.velocity.push_back({2, 0, 0});
  foam.id.push_back(1);
  foam.type.push_back(kFoam);
  foam.lifetime.push_back(100);
  foam.nextId = 2;
  for (int f = 0; f < 10; ++f) {
    stepper.advance(stream(f), stream(f + 1), f, foam);
    ASSERT_EQ(foam.size(), 2u) << "frame " << f + 1;
    EXPECT_EQ(stepper.counts().born, 0u) << "a uniform stream makes no whitewater";
    const float travelled = 2.0f * float(f + 1) / 30;
    for (size_t k = 0; k < 2; ++k) {
      EXPECT_EQ(foam.type[k], foam.type[1]) << "frame " << f + 1;
      EXPECT_NEAR(foam.velocity[k].x(), 2.0f, 1e-4f) << "foam " << k << ", frame " << f + 1;
      const float start = k == 0 ? 0.95f : 0.55f;
      EXPECT_NEAR(foam.position[k].x(), std::fmod(start + travelled, 1.0f), 1e-4f) << "foam " << k;
      EXPECT_GE(foam.position[k].x(), 0.0f);
      EXPECT_LT(foam.position[k].x(), 1.0f);
    }
  }
  EXPECT_NE(foam.type[1], kSpray);
}

// A sheared stream, u = 2 + 20 (y - 0.05) m/s, makes whitewater by the seam as it does in its middle: Ihmsen's
// potentials (trapped air from the rows' relative motion, the surface's crests, the kinetic energy) of each
// particle equal those of the particle half the period along x, to float rounding (its neighbours summed in
// another order). Without the images across the seam, the particles there would see half their neighbours and
// a surface facing along x.
TEST(Whitewater, AShearedStreamMakesWhitewaterByAPeriodicSeamAsInItsMiddle) {
  const Scene scene = streamScene(true);
  WhitewaterStepper stepper(scene);
  ParticleFrame sheared = stream(0);
  for (size_t i = 0; i < sheared.size(); ++i) sheared.velocity[i].x() = 2 + 20 * (sheared.position[i].y() - 0.05f);
  const WhitewaterStepper::Potentials p = stepper.potentials(sheared);
  // The lattice's sites, (x, y, z) in spacings; x runs over 50.
  std::map<std::array<int, 3>, size_t> site;
  auto at = [&](const Eigen::Vector3f& x) {
    return std::array<int, 3>{int(std::lround((x.x() - 0.01f) / 0.02f)), int(std::lround((x.y() - 0.01f) / 0.02f)),
                              int(std::lround((x.z() - 0.31f) / 0.02f))};
  };
  for (size_t i = 0; i < sheared.size(); ++i) site[at(sheared.position[i])] = i;
  ASSERT_EQ(site.size(), sheared.size());
  double trapped = 0;
  for (size_t i = 0; i < sheared.size(); ++i) {
    std::array<int, 3> half = at(sheared.position[i]);
    half[0] = (half[0] + 25) % 50;
    const size_t j = site.at(half);
    EXPECT_NEAR(p.trappedAir[i], p.trappedAir[j], 1e-5f) << "particle at " << sheared.position[i].transpose();
    EXPECT_NEAR(p.waveCrest[i], p.waveCrest[j], 1e-5f) << "particle at " << sheared.position[i].transpose();
    EXPECT_NEAR(p.generated[i], p.generated[j], 1e-5f * std::max(1.0f, p.generated[j]));
    trapped += p.trappedAir[i];
  }
  EXPECT_GT(trapped, 1.0) << "the shear traps air (the comparison is not of zeros)";
}

}  // namespace
}  // namespace surge
