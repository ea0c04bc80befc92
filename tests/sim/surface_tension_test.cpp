// Surface tension (sim/surface_tension.h) against the physics: a drop in zero gravity rounds, oscillates at
// Rayleigh's frequency and holds Laplace's pressure, in every method, 2D and 3D, where the model does.
#include "sim/surface_tension.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>

#include "core/errors.h"
#include "core/files.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "sim/dfsph_solver.h"
#include "sim/fluid_solver.h"
#include "sim/simulation.h"
#include "sim/solver_defaults.h"
#include "sim/wcsph_solver.h"
#include "tests/sim/run_scene.h"
#include "tests/sim/stats_columns.h"

namespace surge {
namespace {

constexpr double kSigma = 0.0728, kRho = 1000, kSpacing = 0.001;

// A zero-gravity scene with room for a drop of `radius` about the origin.
Scene dropScene(int dim, const std::string& method, double radius, const std::vector<std::string>& extra = {}) {
  const double half = radius * 2.5 + 0.01;
  const std::string corner = dim == 3 ? "[" + std::to_string(half) + ", " + std::to_string(half) + ", " + std::to_string(half) + "]"
                                      : "[" + std::to_string(half) + ", " + std::to_string(half) + "]";
  const std::string low = dim == 3 ? "[-" + std::to_string(half) + ", -" + std::to_string(half) + ", -" + std::to_string(half) + "]"
                                   : "[-" + std::to_string(half) + ", -" + std::to_string(half) + "]";
  const std::string zero = dim == 3 ? "[0, 0, 0]" : "[0, 0]";
  const std::string json = R"({"name": "drop", "dimensions": )" + std::to_string(dim) + R"(, "domain": {"min": )" + low +
                           R"(, "max": )" + corner + R"(}, "particle_spacing": 0.001, "gravity": )" + zero +
                           R"(, "fluids": [{"box": {"min": )" + low + R"(, "max": )" + corner +
                           R"(}}], "solver": {"method": ")" + method + R"("}, "output": {"fps": 30, "frames": 1}})";
  std::vector<std::string> overrides = {"fluids[0].surface_tension=" + std::to_string(kSigma)};
  overrides.insert(overrides.end(), extra.begin(), extra.end());
  return parseScene(json, "test", overrides);
}

// The lattice sites within `radius` of the origin (cell centres), moving with the l = 2 potential flow
// v = a (x, -y) in 2D and a (2x, -y, -z) in 3D.
ParticleFrame sphereDrop(int dim, double radius, double a) {
  ParticleFrame frame;
  frame.dimensions = dim;
  const int n = static_cast<int>(std::ceil(radius / kSpacing)) + 1;
  uint32_t id = 0;
  for (int i = -n; i < n; ++i)
    for (int j = -n; j < n; ++j)
      for (int k = (dim == 3 ? -n : 0); k < (dim == 3 ? n : 1); ++k) {
        Eigen::Vector3f p((i + 0.5f) * kSpacing, (j + 0.5f) * kSpacing, dim == 3 ? (k + 0.5f) * kSpacing : 0.0f);
        if (p.norm() > radius) continue;
        Eigen::Vector3f v = dim == 3 ? Eigen::Vector3f(2 * p[0], -p[1], -p[2]) : Eigen::Vector3f(p[0], -p[1], 0);
        frame.position.push_back(p);
        frame.velocity.push_back(float(a) * v);
        frame.id.push_back(id++);
      }
  return frame;
}

// Moves each particle of `frame` by up to `amount` along each axis of its plane or space, the same for a seed on
// every machine (std::mt19937's raw draws are the standard's).
void jitter(ParticleFrame& frame, double amount, uint32_t seed) {
  std::mt19937 draw(seed);
  for (auto& p : frame.position)
    for (int axis = 0; axis < frame.dimensions; ++axis)
      p[axis] += float(amount * (2.0 * double(draw()) / 4294967295.0 - 1.0));
}

// (C_xx - the other axes' mean) / trace of the drop's second moment about its centre.
template <int Dim>
double signedAnisotropy(const std::vector<Vec<Dim>>& x) {
  Vec<Dim> c = Vec<Dim>::Zero();
  for (const auto& p : x) c += p;
  c /= float(x.size());
  Eigen::Matrix<double, Dim, 1> m = Eigen::Matrix<double, Dim, 1>::Zero();
  for (const auto& p : x) m += (p - c).template cast<double>().cwiseAbs2();
  return (m[0] - (m.sum() - m[0]) / (Dim - 1)) / m.sum();
}

template <int Dim>
double anisotropy(const std::vector<Vec<Dim>>& x) {
  Vec<Dim> c = Vec<Dim>::Zero();
  for (const auto& p : x) c += p;
  c /= float(x.size());
  Eigen::Matrix<double, Dim, Dim> m = Eigen::Matrix<double, Dim, Dim>::Zero();
  for (const auto& p : x) m += (p - c).template cast<double>() * (p - c).template cast<double>().transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, Dim, Dim>> eig(m);
  const auto e = eig.eigenvalues();
  return (e[Dim - 1] - e[0]) / (e[Dim - 1] + e[0]);
}

// Steps `duration` from `time`, in equal steps no longer than the solver's stable step or `most`.
template <int Dim>
void stepFor(FluidSolver<Dim>& solver, double& time, double duration, double most) {
  const double longest = std::min<double>(solver.stableTimeStep(), most);
  const int count = static_cast<int>(std::max(1.0, std::ceil(duration / longest - 1e-9)));
  const float dt = static_cast<float>(duration / count);
  for (int k = 0; k < count; ++k) {
    const long bad = solver.step(dt, time);
    ASSERT_EQ(bad, -1) << "at " << time << ": " << solver.positions()[bad].transpose();
    time += dt;
  }
}

// A drop of `radius` at rest in equilibrium: the lattice's sphere relaxed for `relax` seconds, its velocities
// zeroed after every step (the staircase of its surface made smooth), in the solver's current order.
template <int Dim>
void relaxDrop(FluidSolver<Dim>& solver, double radius, double relax, const ParticleFrame& start = {}) {
  solver.setParticles(start.size() > 0 ? start : sphereDrop(Dim, radius, 0));
  double time = 0;
  ParticleFrame frame;
  const int steps = 200;
  for (int k = 0; k < steps; ++k) {
    stepFor<Dim>(solver, time, relax / steps, 1.0 / 120);
    if (::testing::Test::HasFatalFailure()) return;
    solver.getParticles(frame);
    for (auto& v : frame.velocity) v.setZero();
    solver.setParticles(frame);
  }
}

// The l = 2 oscillation of a relaxed drop given the potential flow of sphereDrop at amplitude `a` (1/s): the
// times the signed anisotropy crosses zero, sampled every `sample` seconds.
template <int Dim>
std::vector<double> oscillationCrossings(FluidSolver<Dim>& solver, double a, double sample, double until, int most) {
  ParticleFrame frame;
  solver.getParticles(frame);
  Eigen::Vector3f c = Eigen::Vector3f::Zero();
  for (auto& p : frame.position) c += p;
  c /= float(frame.size());
  for (size_t i = 0; i < frame.size(); ++i) {
    const Eigen::Vector3f p = frame.position[i] - c;
    frame.velocity[i] = float(a) * (Dim == 3 ? Eigen::Vector3f(2 * p[0], -p[1], -p[2]) : Eigen::Vector3f(p[0], -p[1], 0));
  }
  solver.setParticles(frame);
  const double rest = signedAnisotropy<Dim>(solver.positions());
  double time = 0, last = 0;
  std::vector<double> crossings;
  while (time < until && int(crossings.size()) < most) {
    solver.beginFrame(time);
    stepFor<Dim>(solver, time, sample, 1.0 / 120);
    if (::testing::Test::HasFatalFailure()) return crossings;
    const double now = signedAnisotropy<Dim>(solver.positions()) - rest;
    if (time > 1.5 * sample && (now > 0) != (last > 0)) crossings.push_back(time - sample * now / (now - last));
    last = now;
  }
  return crossings;
}

// Rayleigh 1879: a drop's l = 2 oscillation has omega^2 = 8 sigma / (rho R^3) in 3D, 6 sigma / (rho R^3) in 2D.
// At 20 particles across (R = 10 mm, unless `radius` says otherwise) a relaxed drop given 10% of the mode's flow
// first comes back through its rest shape after half a period, and its next four half periods average one, each
// within the issue's 10%: sampled 80 times a half period, over 5.5 half periods, where a drop 10% slow crosses the
// fifth time.
template <int Dim>
void expectRayleighsFrequency(const std::string& method, const std::vector<std::string>& extra, double radius = 0.01) {
  const double omega = std::sqrt((Dim == 3 ? 8 : 6) * kSigma / (kRho * std::pow(radius, 3)));
  auto solver = makeFluidSolver<Dim>(dropScene(Dim, method, radius, extra));
  relaxDrop<Dim>(*solver, radius, 0.2);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  const double half = M_PI / omega;
  const std::vector<double> crossings = oscillationCrossings<Dim>(*solver, 0.1 * omega, half / 80, 5.5 * half, 5);
  for (double t : crossings)
    std::printf("%s %dD: back through its rest shape at %.4f half periods\n", method.c_str(), Dim, t / half);
  ASSERT_EQ(crossings.size(), 5u) << "the drop did not oscillate";
  EXPECT_NEAR(crossings[0] / half, 1.0, 0.1);
  EXPECT_NEAR((crossings[4] - crossings[0]) / 4 / half, 1.0, 0.1);
}

// 3D at the default support, which a 3D scene with surface tension gives 2.5 spacings. Measured: DFSPH 0.958 and
// 0.988, PBF 1.019 and 0.970. At 2 spacings the drop keeps a set: DFSPH's never crosses, PBF's crosses at 0.96
// and 1.30 half periods and then no more (the test fails); docs/surface-tension.md has every method's.
TEST(SurfaceTension, AThreeDimensionalDropOscillatesAtRayleighsFrequencyInPbfAtItsDefaults) {
  expectRayleighsFrequency<3>("pbf", {});
}

TEST(SurfaceTension, AThreeDimensionalDropOscillatesAtRayleighsFrequencyInDfsphAtItsDefaults) {
  expectRayleighsFrequency<3>("dfsph", {});
}

// WCSPH 3D takes alpha 0.01 with surface tension (resolveWcsphDefaults): measured 0.951 and 0.959. At alpha 0.05,
// its default elsewhere, the drop rings at 0.856 and 0.860 of Rayleigh's half period and the test fails.
TEST(SurfaceTension, AThreeDimensionalDropOscillatesAtRayleighsFrequencyInWcsphAtItsDefaults) {
  expectRayleighsFrequency<3>("wcsph", {});
}

// WCSPH's artificial viscosity left out is 0.01 in a 3D scene with surface tension and 0.05 in any other (2D with
// surface tension, 3D without), as in every other method's scene.json; a value the file gives is kept.
TEST(SurfaceTension, WcsphsArtificialViscosityIsSmallerIn3DWithSurfaceTension) {
  const auto alpha = [](int dim, const std::string& method, const std::vector<std::string>& extra) {
    return dropScene(dim, method, 0.005, extra).solver.artificial_viscosity;
  };
  EXPECT_EQ(alpha(3, "wcsph", {}), 0.01);
  EXPECT_EQ(alpha(2, "wcsph", {}), 0.05);
  EXPECT_EQ(alpha(3, "wcsph", {"fluids[0].surface_tension=0"}), 0.05);
  EXPECT_EQ(alpha(3, "wcsph", {"solver.artificial_viscosity=0.05"}), 0.05);
  EXPECT_EQ(alpha(3, "wcsph", {"solver.artificial_viscosity=0"}), 0);
  EXPECT_EQ(alpha(3, "dfsph", {}), 0.05);
  EXPECT_EQ(alpha(3, "pbf", {}), 0.05);
}

// 2D at the default support, which a 2D scene with surface tension gives 3.75 spacings in DFSPH and WCSPH
// (FluidMethod::surfaceTensionSupport2d). Measured: DFSPH 0.968 and 0.988; WCSPH 1.003 and 1.019 (at 4 spacings,
// before session 68: 0.968 and 1.000; 1.001 and 0.988; larger WCSPH drops ring 8 to 16% fast there). At 2 spacings the
// lattice holds as a crystal and the drop does not ring (the test fails); docs/surface-tension.md, "The 2D support".
TEST(SurfaceTension, A2DDropOscillatesAtRayleighsFrequencyInDfsphAtItsDefaults) {
  expectRayleighsFrequency<2>("dfsph", {});
}

TEST(SurfaceTension, A2DDropOscillatesAtRayleighsFrequencyInWcsphAtItsDefaults) {
  expectRayleighsFrequency<2>("wcsph", {});
}

// A larger drop, 32 particles across (R = 16 mm), in WCSPH at its 2D default of 3.75 spacings: measured 1.017 and
// 0.986 (DFSPH 0.995, 1.004). At 4 spacings, the 2D default before session 68, it rang fast: 0.929 and 0.874, and
// the test fails (docs/surface-tension.md, "Larger 2D drops at 3.75 spacings").
TEST(SurfaceTension, ALarger2DDropOscillatesAtRayleighsFrequencyInWcsphAtItsDefaults) {
  expectRayleighsFrequency<2>("wcsph", {}, 0.016);
}

// PBF in 2D with surface tension takes Wendland C2 for its density and its constraint's gradient (PbfWendlandC2), at
// its 3.5 spacings, with relaxation 0.8 and no s_corr (resolvePbfDefaults): its drop rings at Rayleigh's frequency
// swing after swing, as the other methods' do. Measured 0.947 and 0.943 (12 runs by step and jittered start: first
// 0.91 to 1.00, next four 0.92 to 1.02). At 2.5 spacings with s_corr, the default before session 71, the first swing
// held (1.004) but the lattice yielded in bursts after it and the later half periods ran 3 to 27% slow (the test
// fails there: docs/surface-tension.md, "PBF 2D at 3.5 spacings"); with the paper's poly6 and spiky it came back at
// 0.76.
TEST(SurfaceTension, A2DDropOscillatesAtRayleighsFrequencyInPbfAtItsDefaults) {
  expectRayleighsFrequency<2>("pbf", {});
}

// Laplace: a drop at rest holds a pressure (d - 1) sigma / R above the air's. The solver's own pressure holds the
// fluid against the cohesion's pull, of order sigma / h, so the pressure Laplace's law speaks of is the mechanical
// one, Irving and Kirkwood's of every pair force (FluidSolver::virialPressureWithin): in a ball about the drop's
// centre, the radial stress on its surface, the same at every radius inside a fluid at rest. `start` relaxed for
// 0.3 s, then `samples` over 0.2 s: the mean over them of the pressure in balls of R/4, R/2 and 3R/4 over
// Laplace's, and of the whole drop's (a ball two supports wider), which at rest sums to zero, the kinetic energy
// counted.
template <int Dim>
std::array<double, 4> laplaceRatios(FluidSolver<Dim>& solver, const ParticleFrame& start, double radius, double support,
                                    int samples = 20) {
  relaxDrop<Dim>(solver, radius, 0.3, start);
  std::array<double, 4> ratio{};
  if (::testing::Test::HasFatalFailure()) return ratio;
  const double laplace = (Dim - 1) * kSigma / radius;
  const std::array<double, 4> ball = {radius / 4, radius / 2, 3 * radius / 4, radius + 2 * support};
  double time = 0;
  for (int sample = 0; sample < samples; ++sample) {
    stepFor<Dim>(solver, time, 0.2 / samples, 1.0 / 120);
    if (::testing::Test::HasFatalFailure()) return ratio;
    Vec<Dim> centre = Vec<Dim>::Zero();
    for (const auto& p : solver.positions()) centre += p;
    centre /= float(solver.size());
    for (size_t k = 0; k < ball.size(); ++k)
      ratio[k] += solver.virialPressureWithin(centre, float(ball[k])) / laplace / samples;
  }
  std::printf("%dD, R = %.0f mm: over (d - 1) sigma / R, within R/4 %.3f, R/2 %.3f, 3R/4 %.3f; the whole drop %.4f\n",
              Dim, radius * 1e3, ratio[0], ratio[1], ratio[2], ratio[3]);
  return ratio;
}

// DFSPH 3D at its default support with surface tension (2.5 spacings), R = 20 mm (40 particles across): each
// ball within the issue's 10% (measured 1.084, 1.074, 1.090: the drop's inside at rest, its stress a pressure;
// the particles' own halves of the virial within R/2, the measure before, read 1.064), and the whole drop to 2% of
// Laplace's (measured 0.01%). Seen failing with the model's pairs counted wholly at the particle inside (the
// measure before): 0.761, 0.993, 1.111. Before, with gamma 20% too large the particles' measure read 1.258, and
// without DFSPH's divergence solve's pressure the whole drop read -3.7%.
TEST(SurfaceTension, ADropsInnerPressureIsLaplacesInDfsph3DAtItsDefaults) {
  const double radius = 0.02;
  auto solver = makeFluidSolver<3>(dropScene(3, "dfsph", radius));
  const std::array<double, 4> ratio = laplaceRatios<3>(*solver, sphereDrop(3, radius, 0), radius, 0.0025);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(ratio[k], 1.0, 0.1) << "ball " << k;
  EXPECT_LT(std::abs(ratio[3]), 0.02);
}

// The 2D measure's completeness: WCSPH at its 2D support, R = 20 mm, a jittered start, sampled every millisecond
// (the compressible drop breathes; 20 samples read the whole drop -3.7 to 0.0% at 40 mm by aliasing). The whole
// drop's virial sums to zero within 1% of sigma / R (measured 0.01%, at most 0.12% in seven runs at 20 to 40 mm,
// at 4 spacings) only with the pair viscosity's force counted, which pushes approaching pairs apart alone
// (without it -2.2% here; -4.9 to -6.8% at 40 mm and 20 samples).
TEST(SurfaceTension, A2DDropsVirialCountsEveryPairForceInWcsph) {
  const double radius = 0.02;
  auto solver = makeFluidSolver<2>(dropScene(2, "wcsph", radius));
  ParticleFrame start = sphereDrop(2, radius, 0);
  jitter(start, 0.25 * kSpacing, 1);
  const std::array<double, 4> ratio = laplaceRatios<2>(*solver, start, radius, 0.00375, 200);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  EXPECT_LT(std::abs(ratio[3]), 0.01);
}

// Laplace in 2D, DFSPH and WCSPH at their 2D support (3.75 spacings, where Kirkwood and Buff's sum that sets gamma
// is the same to 4% on any arrangement of the particles; at 4 the hexagonal one's is 1.16 of the square one's the
// calibration sums, docs/surface-tension.md, "The calibration's lattice"), R = 30 mm (60 particles across), a
// jittered start, 200 samples: the pressure in balls of R/4 and R/2 within the issue's 10% of sigma / R. Measured
// WCSPH 1.062 and 1.062 (another seed 1.015, 1.039), DFSPH 1.083 and 1.076 (1.029, 1.027); 3R/4, whose ball
// reaches the band the surface orders two supports in, read 1.079 and 1.102 and is not held. At 4 spacings WCSPH
// read 1.092 and 1.127 and the test failed (seen; DFSPH 1.029, 1.076); at 40 across, 3.75 spacings, WCSPH reads
// 1.096 and 1.090. The whole drop sums to zero within 1% (WCSPH, as above) and 2% (DFSPH, whose drop is not quite
// at rest: 0.79%).
TEST(SurfaceTension, A2DDropsInnerPressureIsLaplacesAtItsDefaults) {
  const double radius = 0.03;
  for (const std::string method : {"dfsph", "wcsph"}) {
    auto solver = makeFluidSolver<2>(dropScene(2, method, radius));
    ParticleFrame start = sphereDrop(2, radius, 0);
    jitter(start, 0.25 * kSpacing, 1);
    const std::array<double, 4> ratio = laplaceRatios<2>(*solver, start, radius, 0.00375, 200);
    ASSERT_FALSE(::testing::Test::HasFatalFailure());
    for (int k = 0; k < 2; ++k) EXPECT_NEAR(ratio[k], 1.0, 0.1) << method << ", ball " << k;
    EXPECT_LT(std::abs(ratio[3]), method == "wcsph" ? 0.01 : 0.02) << method;
  }
}

// Irving and Kirkwood's momentum flux is the particles' motion relative to the ball's mean, so a drop moving as
// a whole reads the pressure it holds at rest: a 2D drop (R = 10 mm) 0.05 s from the lattice, measured, then
// every velocity shifted by 0.11 m/s in place (the solver's pressures kept) and measured again. The pair forces do
// not change but WCSPH's viscosity, which takes velocity differences, rounded to a float's 1e-7 of the shift; so
// within R/2 and over the whole drop the two agree to 1e-4 of sigma / R. Seen failing with the particles' own
// velocities: the shift's flux rho U^2 / d is 0.86 of Laplace's. (Two runs, one moving from the start, part by
// up to 0.018 of it as the lattice yields, from rounding alone.)
TEST(SurfaceTension, ADropsPressureIsTheSameWhenItMovesAsAWhole) {
  const double radius = 0.01, laplace = kSigma / radius;
  const Vec<2> shift(0.1f, -0.05f);
  for (const std::string method : {"dfsph", "wcsph"}) {
    auto solver = makeFluidSolver<2>(dropScene(2, method, radius));
    solver->setParticles(sphereDrop(2, radius, 0));
    double time = 0;
    stepFor<2>(*solver, time, 0.05, 1.0 / 120);
    ASSERT_FALSE(::testing::Test::HasFatalFailure());
    Vec<2> centre = Vec<2>::Zero();
    for (const auto& p : solver->positions()) centre += p;
    centre /= float(solver->size());
    std::array<double, 2> inner{}, whole{};
    for (int moving = 0; moving < 2; ++moving) {
      // setParticles would start the method's channels afresh; the test shifts the velocities where they are.
      if (moving)
        for (auto& v : const_cast<std::vector<Vec<2>>&>(solver->velocities())) v += shift;
      inner[moving] = solver->virialPressureWithin(centre, float(radius / 2)) / laplace;
      whole[moving] = solver->virialPressureWithin(centre, float(radius + 0.008)) / laplace;
    }
    std::printf("%s: within R/2 %.6f and %.6f of sigma / R at rest and moving; the whole drop %.6f and %.6f\n",
                method.c_str(), inner[0], inner[1], whole[0], whole[1]);
    EXPECT_GT(inner[0], 0.5) << method;  // a pressure held inside, not an empty ball
    EXPECT_NEAR(inner[1], inner[0], 1e-4) << method;
    EXPECT_NEAR(whole[1], whole[0], 1e-4) << method;
  }
}

// The 2:1:1 box of water (24 x 12 x 12 particles at 1 mm) in zero gravity, in `method`.
Scene boxDropScene(const std::string& method, const std::vector<std::string>& extra = {}) {
  Scene scene = dropScene(3, method, 0.012, extra);
  scene.fluids[0].box.min = Eigen::Vector3d(-0.012, -0.006, -0.006);
  scene.fluids[0].box.max = Eigen::Vector3d(0.012, 0.006, 0.006);
  return scene;
}

// Runs `scene` to its last frame and expects the anisotropy under the issue's 2% at each of `frames`; returns the
// run's folder.
fs::path expectRoundWithinTwoPercent(const Scene& scene, const std::string& name, const std::vector<int>& frames) {
  const fs::path dir = runScene(scene, name);
  for (const int frame : frames) {
    const std::vector<Eigen::Vector3f> positions = readParticlePly(framePath(dir, "particles", frame, "ply")).position;
    std::vector<Vec<3>> x;
    std::vector<Vec<2>> flat;
    for (const auto& p : positions) {
      if (scene.dimensions == 3)
        x.push_back(p);
      else
        flat.push_back(p.head<2>());
    }
    const double value = scene.dimensions == 3 ? anisotropy<3>(x) : anisotropy<2>(flat);
    std::printf("%s, frame %d: anisotropy %.4f\n", name.c_str(), frame, value);
    EXPECT_LT(value, 0.02) << "frame " << frame;
  }
  return dir;
}

// The most surface energy the energy account credits is sigma times the lattice's own faces, wherever the block
// sits on the domain's grid: the 30 x 15 rectangle has 90 faces of 1 mm, whether its sites fall on the grid's
// cell centres or, its edges half a spacing off, on their corners (there floor() once split rows between cells
// and counted 330).
TEST(SurfaceTension, TheSurfaceEnergyBoundCountsTheLatticesFaces) {
  for (const double shift : {0.0, 0.0005}) {
    Scene scene = dropScene(2, "dfsph", 0.012);
    scene.fluids[0].box.min = Eigen::Vector3d(-0.015 + shift, -0.0075 + shift, 0);
    scene.fluids[0].box.max = Eigen::Vector3d(0.015 + shift, 0.0075 + shift, 0);
    const ParticleFrame initial = initialParticles(scene);
    ASSERT_EQ(initial.size(), 450u);
    EXPECT_NEAR(surfaceEnergyBound(scene, initial), kSigma * 0.090, 1e-9) << "shift " << shift;
  }
}

// The anisotropy of the second moment of frames first to last of a 3D run, summed: a drop that rings about a
// round shape reads its mean shape, one that keeps a set reads the set.
double meanAnisotropy(const fs::path& dir, int first, int last) {
  std::vector<Vec<3>> x;
  for (int frame = first; frame <= last; ++frame) {
    std::vector<Vec<3>> one;
    for (const auto& p : readParticlePly(framePath(dir, "particles", frame, "ply")).position) one.push_back(p);
    Vec<3> c = Vec<3>::Zero();
    for (const auto& p : one) c += p;
    c /= float(one.size());
    for (const auto& p : one) x.push_back(p - c);
  }
  return anisotropy<3>(x);
}

// A 2:1:1 box of water (24 x 12 x 12 particles) in zero gravity pulls itself round in DFSPH at its defaults (2.5
// spacings of support with surface tension): it rings as a water drop does (its anisotropy swings from 0.60 through
// round, 0.17 at 1 s, 0.03 at 2 s, its l = 2 damping time R^2 / (5 nu) 18 s), about a round mean shape: the second
// moment summed over the frames from 1 to 2 s, four of Rayleigh's periods (0.24 s), is within the issue's 2% of
// round (measured 0.81%; at 2 spacings, where the drop keeps a set, 2.3%). The energy it releases is credited to
// the account up to sigma times its surface, and the run passes the energy stop.
TEST(SurfaceTension, ABoxDropRoundsAndItsEnergyIsAccounted) {
  Scene scene = boxDropScene("dfsph");
  scene.output.frames = 60;
  const fs::path dir = runScene(scene, "box_drop");
  std::vector<Vec<3>> first;
  for (const auto& p : readParticlePly(framePath(dir, "particles", 0, "ply")).position) first.push_back(p);
  EXPECT_NEAR(anisotropy<3>(first), 0.60, 0.01);
  const double mean = meanAnisotropy(dir, 30, 60);
  std::printf("box_drop: the mean shape from 1 to 2 s, anisotropy %.4f\n", mean);
  EXPECT_LT(mean, 0.02);
  // The work credited is the surface energy released: positive, at most sigma A (A: the box's 1,440 mm^2).
  const auto stats = readStats(dir);
  const double work = stats.at("source_work").back();
  EXPECT_GT(work, 0);
  EXPECT_LE(work, kSigma * 1.44e-3 * (1 + 1e-6));
  EXPECT_LE(stats.at("kinetic_energy").back(), work);
}

// A viscous box (nu = 2e-4 m^2/s, so that it comes to rest rather than rings) rounds to within the issue's 2% at
// 1, 1.5 and 2 s in DFSPH 3D at its defaults (measured 0.5, 0.4, 0.5%).
TEST(SurfaceTension, AViscousBoxDropRoundsToWithinTwoPercentInDfsph3DAtItsDefaults) {
  Scene scene = boxDropScene("dfsph", {"fluids[0].viscosity=2e-4"});
  scene.output.frames = 60;
  expectRoundWithinTwoPercent(scene, "viscous_box_drop", {30, 45, 60});
}

// The same box in PBF 3D at its defaults, water: under 2% at 1.5 and 2 s (measured 0.56% and 0.38%; 2.9% at 1 s,
// ringing down), and at no frame more kinetic energy than the surface energy rounding can release, sigma (A_box -
// A_sphere) = 24.4 uJ (measured at most 6.1 uJ). PBF takes the model's forces at its predicted positions, before
// the constraints (PbfSolver::pullBySurfaceTension); taken at the projected ones, as an external force, the
// cohesion fed the drop energy and the energy check stopped the run in frame 23 (the test fails).
TEST(SurfaceTension, ABoxDropRoundsToWithinTwoPercentInPbf3DAtItsDefaults) {
  Scene scene = boxDropScene("pbf");
  scene.output.frames = 60;
  const fs::path dir = expectRoundWithinTwoPercent(scene, "box_drop_pbf", {45, 60});
  const double volume = 24e-3 * 12e-3 * 12e-3, boxArea = 2 * (2 * 24e-3 * 12e-3 + 12e-3 * 12e-3);
  const double sphereArea = std::pow(M_PI, 1.0 / 3) * std::pow(6 * volume, 2.0 / 3);
  const auto kinetic = readStats(dir).at("kinetic_energy");
  ASSERT_EQ(kinetic.size(), 61u);
  const double most = *std::max_element(kinetic.begin(), kinetic.end());
  std::printf("most kinetic energy %.3g J against %.3g J released\n", most, kSigma * (boxArea - sphereArea));
  EXPECT_LE(most, kSigma * (boxArea - sphereArea));
}

// The 2D rectangle of water, 30 x 15 particles (R = 12 mm as a circle), in zero gravity.
Scene rectangleDropScene(const std::string& method, const std::vector<std::string>& extra = {}) {
  Scene scene = dropScene(2, method, 0.012, extra);
  scene.fluids[0].box.min = Eigen::Vector3d(-0.015, -0.0075, 0);
  scene.fluids[0].box.max = Eigen::Vector3d(0.015, 0.0075, 0);
  scene.output.frames = 60;
  return scene;
}

// In 2D the issue's 2% holds at the default support, which a 2D scene with surface tension gives 3.75 spacings in
// DFSPH and WCSPH and 3.5 in PBF (FluidMethod::surfaceTensionSupport2d), in every method for a viscous drop (nu =
// 2e-4 m^2/s) at 1, 1.5 and 2 s. Measured DFSPH 0.58, 0.31, 0.87%; WCSPH 1.01, 0.28, 0.45%; PBF 1.41, 1.69, 1.30% (its
// Wendland C2 kernels at 3.5 spacings; 1.14, 1.31, 1.67% at 2.5; 1.00, 0.54, 0.41% with poly6 and spiky). At 2
// spacings the square lattice re-packs into a hexagonal crystal that holds the rectangle's shape (DFSPH 0.56, WCSPH
// 0.53, PBF 0.27) and the test fails (docs/surface-tension.md, "The 2D support").
TEST(SurfaceTension, AViscousRectangleRoundsToWithinTwoPercentIn2DAtItsDefaults) {
  for (const std::string method : {"dfsph", "wcsph", "pbf"})
    expectRoundWithinTwoPercent(rectangleDropScene(method, {"fluids[0].viscosity=2e-4"}), "viscous_rectangle_" + method,
                                {30, 45, 60});
}

// The same rectangle as water rounds to within 2% by 2 s at the defaults in WCSPH and stays there: measured 0.07,
// 0.41 and 0.07% at 2, 2.5 and 3 s (15.1, 2.2 and 2.6% at 0.5, 1 and 1.5 s: it swings about round; at 4 spacings,
// before session 68, 1.50% and 0.73% at 1.5 and 2 s). DFSPH's water drop rings on (anisotropy 0.26 at 2 s, 0.11 at 4
// s), as a water drop does: its l = 2 mode's viscous damping time is tens of seconds; so does PBF's since its 2D kernel
// is Wendland C2 (5.1% and 1.8%; poly6 and spiky's stiff lattice damped it to 1.31% and 0.55%).
TEST(SurfaceTension, AWaterRectangleRoundsToWithinTwoPercentIn2DAtItsDefaultsInWcsph) {
  Scene scene = rectangleDropScene("wcsph");
  scene.output.frames = 90;
  expectRoundWithinTwoPercent(scene, "water_rectangle_wcsph", {60, 75, 90});
}

// Surface tension keeps a run's bytes the same at any thread count, and a resumed run ends where an uninterrupted
// one does (every method, 2D and 3D).
TEST(SurfaceTension, SameBytesAtAnyThreadCountAndAfterAResume) {
  for (const std::string method : {"dfsph", "pbf", "wcsph"})
    for (int dim : {2, 3}) {
      SCOPED_TRACE(method + " " + std::to_string(dim) + "D");
      Scene scene = dropScene(dim, method, 0.004);
      for (int k = 0; k < dim; ++k) {
        scene.fluids[0].box.min[k] = -0.004;
        scene.fluids[0].box.max[k] = k == 0 ? 0.006 : 0.004;
      }
      scene.output.frames = 6;
      auto run = [&](const std::string& name, int threads, int frames, bool resume) {
        Scene s = scene;
        s.output.frames = frames;
        const fs::path dir = runScene(s, name, threads, resume);
        return frames == 6 ? readTextFile(framePath(dir, "particles", 6, "ply")) : std::string();
      };
      const std::string two = run("st_two", 2, 6, false);
      EXPECT_EQ(run("st_one", 1, 6, false), two);
      run("st_resumed", 2, 3, false);
      EXPECT_EQ(run("st_resumed", 1, 6, true), two);
    }
}

// Several fluids: each pulls together with its own sigma and sees the other as air, so their interface holds
// sigma_1 + sigma_2 (sim/surface_tension.h). A 2:1 rectangle of oil (rho 900, sigma 0.03, 30 x 15 particles)
// inside water (sigma 0.0728) in zero gravity starts at anisotropy 0.60 and rounds in every method to the issue's
// 2% (by 1 s in WCSPH, 2 s in the others), at the default support of a 2D scene with surface tension
// (FluidMethod::surfaceTensionSupport2d). Measured: DFSPH 0.154 at 1 s, 0.014 at 2 s; PBF 0.143 and 0.014 (at its
// defaults where the densities differ, converged, and at its 3.5 spacings without s_corr; at 2.5, before session 71,
// 0.026 and 0.011 with s_corr, 0.024 and 0.031 without);
// WCSPH 0.019 at 1 s (at 4 spacings, before session 68: DFSPH 0.238 and 0.012, WCSPH 0.003). At 2 spacings each kept a
// set (DFSPH 0.47, PBF 0.28, WCSPH 0.53 at 1 s: the crystal, docs/surface-tension.md). Without the sigmas the rectangle
// keeps 0.601 to 1e-3. In DFSPH the run is the same bytes at 1 and 2 threads and after a resume.
Scene oilInWater(const std::string& method, bool tension) {
  const std::string water = tension ? ", \"surface_tension\": 0.0728" : "";
  const std::string oil = tension ? ", \"surface_tension\": 0.03" : "";
  return parseScene(
      R"({"name": "oil_in_water", "dimensions": 2, "domain": {"min": [0, 0], "max": [0.06, 0.06]},
          "particle_spacing": 0.001, "gravity": [0, 0], "solver": {"method": ")" + method + R"("},
          "output": {"fps": 20, "frames": 20}, "fluids": [
            {"name": "water", "box": {"min": [0, 0], "max": [0.06, 0.0225]})" + water + R"(},
            {"name": "water", "box": {"min": [0, 0.0375], "max": [0.06, 0.06]})" + water + R"(},
            {"name": "water", "box": {"min": [0, 0.0225], "max": [0.015, 0.0375]})" + water + R"(},
            {"name": "water", "box": {"min": [0.045, 0.0225], "max": [0.06, 0.0375]})" + water + R"(},
            {"name": "oil", "rest_density": 900, "box": {"min": [0.015, 0.0225], "max": [0.045, 0.0375]})" + oil +
          "}]}",
      "oil_in_water.json");
}

double oilAnisotropy(const fs::path& dir, int frame) {
  const ParticleFrame f = readParticlePly(framePath(dir, "particles", frame, "ply"));
  std::vector<Vec<2>> oil;
  for (size_t i = 0; i < f.size(); ++i)
    if (f.fluid.at(i) == 4) oil.push_back(f.position[i].head<2>());
  EXPECT_EQ(oil.size(), 450u);
  return anisotropy<2>(oil);
}

TEST(SurfaceTension, AnOilRectangleInWaterRoundsInEveryMethod) {
  for (const std::string method : {"dfsph", "pbf", "wcsph"}) {
    Scene scene = oilInWater(method, true);
    scene.output.frames = method == "wcsph" ? 20 : 40;  // WCSPH's steps are short, and its drop is round by 1 s
    const fs::path dir = runScene(scene, "oil_in_water_" + method);
    const double start = oilAnisotropy(dir, 0), end = oilAnisotropy(dir, scene.output.frames);
    std::printf("%s: oil's anisotropy %.3f at 0 s, %.3f at 1 s, %.3f at its end\n", method.c_str(), start,
                oilAnisotropy(dir, 20), end);
    EXPECT_NEAR(start, 0.60, 0.01) << method;
    EXPECT_LT(end, 0.02) << method;
  }
  EXPECT_NEAR(oilAnisotropy(runScene(oilInWater("dfsph", false), "oil_in_water_still"), 20), 0.601, 1e-3);
  Scene scene = oilInWater("dfsph", true);
  scene.output.frames = 6;
  const auto lastFrame = [](const fs::path& dir) { return readTextFile(framePath(dir, "particles", 6, "ply")); };
  const std::string two = lastFrame(runScene(scene, "oil_two", 2));
  EXPECT_EQ(lastFrame(runScene(scene, "oil_one", 1)), two);
  Scene half = scene;
  half.output.frames = 3;
  runScene(half, "oil_resumed", 2);
  EXPECT_EQ(lastFrame(runScene(scene, "oil_resumed", 1, true)), two);
}

// The contact angle of a drop on a plate at y = 0, in degrees, as a spherical (circular in 2D) cap's: 2 atan(h / r)
// from its height h and its first layer's reach r from its centre along the plate, each to half a spacing; NaN
// where no particle touches the plate.
double capAngle(const ParticleFrame& drop) {
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();
  for (const auto& p : drop.position) centre += p;
  centre /= float(drop.size());
  float height = 0, reach = 0;
  for (const auto& p : drop.position) {
    height = std::max(height, p.y() + 0.0005f);
    if (p.y() < 0.001f) reach = std::max(reach, std::hypot(p.x() - centre.x(), p.z() - centre.z()) + 0.0005f);
  }
  return reach > 0 ? 2 * std::atan2(height, reach) * 180 / M_PI : NAN;
}

// The cube's cap angle at 1 s, in `method` at `support` (solver.kernel_radius; "0" the default).
double cubeOnAPlate(const std::string& method, double adhesion, const std::string& support) {
  const Scene scene = parseScene(
      R"({"name": "plate", "dimensions": 3, "domain": {"min": [-0.02, -0.006, -0.02], "max": [0.02, 0.03, 0.02]},
        "particle_spacing": 0.001, "gravity": [0, 0, 0],
        "fluids": [{"box": {"min": [-0.006, 0, -0.006], "max": [0.006, 0.012, 0.006]}}],
        "colliders": [{"shape": "box", "position": [0, -0.003, 0], "size": [0.04, 0.006, 0.04]}],
        "output": {"fps": 30, "frames": 30}})",
      "plate.json",
      {"solver.method=" + method, "fluids[0].surface_tension=" + std::to_string(kSigma),
       "colliders[0].adhesion=" + std::to_string(adhesion), "solver.kernel_radius=" + support});
  return capAngle(readParticlePly(framePath(runScene(scene, "plate"), "particles", 30, "ply")));
}

// Adhesion a = W_adhesion / (2 sigma) (sim/surface_tension.h): a cube of water (12^3 particles) set on a plate in
// zero gravity settles to Young's angle, cos theta = 2a - 1, read from the spherical cap's height h and contact
// radius r as theta = 2 atan(h / r). Half a spacing on each of h and r (about 9 spacings) moves that angle by up
// to 6 degrees; the bound is 10. Measured at 2.5 spacings (the default) 116.7, 92.5, 60.7, at 2 spacings 116.0,
// 87.6, 64.4 and at 3 (0.9 of beta) 120.1, 91.1, 53.0, against 120, 90, 60 (docs/surface-tension.md). At 3 with
// beta whole, before it had its share, 118.4, 87.8 and 5.9 (a film).
TEST(SurfaceTension, ADropOnAPlateSettlesAtYoungsAngle) {
  for (const char* support : {"0", "0.002", "0.003"})
    for (double adhesion : {0.25, 0.5, 0.75}) {
      SCOPED_TRACE(std::string("solver.kernel_radius ") + support + ", adhesion " + std::to_string(adhesion));
      const double angle = cubeOnAPlate("dfsph", adhesion, support);
      std::printf("DFSPH 3D drop on a plate, solver.kernel_radius %s, adhesion %.2f: %.1f degrees\n", support,
                  adhesion, angle);
      ASSERT_FALSE(std::isnan(angle)) << "the drop left the plate";
      EXPECT_NEAR(angle, std::acos(2 * adhesion - 1) * 180 / M_PI, 10);
    }
}

// WCSPH's walls with surface tension (A2DWaterDropOnAPlateSettlesAtYoungsAngleInWcsph) in 3D: the same cube at the
// default support and adhesion 0.5, where the mirrored wall read 110.9 degrees. Measured 92.0 (116.6 and 68.5 at
// 0.25 and 0.75, left out: a minute a run).
TEST(SurfaceTension, ADropOnAPlateMeetsYoungsAngleInWcsph3D) {
  const double angle = cubeOnAPlate("wcsph", 0.5, "0");
  std::printf("WCSPH 3D drop on a plate, adhesion 0.5: %.1f degrees\n", angle);
  EXPECT_NEAR(angle, 90, 10);
}

// A 20 x 20 mm square on a plate in zero gravity, in 2D at the method's default support, run for 3 s.
fs::path squareOnAPlate(const std::string& method, double adhesion, const std::string& viscosity) {
  const Scene scene = parseScene(
      R"({"name": "plate", "dimensions": 2, "domain": {"min": [-0.05, -0.006], "max": [0.05, 0.04]},
        "particle_spacing": 0.001, "gravity": [0, 0],
        "fluids": [{"box": {"min": [-0.01, 0], "max": [0.01, 0.02]}}],
        "colliders": [{"shape": "box", "position": [0, -0.003], "size": [0.1, 0.006]}],
        "output": {"fps": 30, "frames": 90}})",
      "plate2d.json",
      {"solver.method=" + method, "fluids[0].viscosity=" + viscosity,
       "fluids[0].surface_tension=" + std::to_string(kSigma), "colliders[0].adhesion=" + std::to_string(adhesion)});
  return runScene(scene, "plate2d_" + method);
}

// In 2D at DFSPH's default support (3.75 spacings) beta from Young's work of adhesion, 0.9 of it (the 2D share at
// 3.75, adhesionCalibration), gives Young's angle for a drop that settles: a 20 x 20 mm square, viscous (nu = 2e-4
// m^2/s) so that its contact line creeps to its angle rather than overshooting it, read at 3 s from its height and
// the half-width of its first layer, each to half a spacing (a few degrees), within the 3D test's 10 degrees.
// Measured 123.9, 90.5, 62.0; with beta whole 118.7, 84.3, 51.7, with 0.8 of it 129.0, 97.6, 74.5 (at 4 spacings,
// whole, before session 68: 119.7, 89.9, 64.5). A 12 mm water drop's inertia carries its contact line past 60
// degrees at 0.75 and it pins there as a film (18 degrees; surge sim's 2D note); with 3D's share of beta at 2.5
// spacings (0.75) the viscous drop read 133, 108, 84 at 4 spacings and the test failed (docs/surface-tension.md,
// "Adhesion in 2D"). PBF at its 3.5 spacings takes 1.15 of beta (the share at 3.5): measured 119.2, 87.1, 60.7; with
// beta whole 121.7, 95.6, 72.2 (the test fails), with 1.25 of it 115.1, 83.4, 48.9.
TEST(SurfaceTension, A2DDropOnAPlateSettlesAtYoungsAngleInDfsphAndPbf) {
  for (const std::string method : {"dfsph", "pbf"})
    for (double adhesion : {0.25, 0.5, 0.75}) {
      SCOPED_TRACE(method + ", adhesion " + std::to_string(adhesion));
      const double angle =
          capAngle(readParticlePly(framePath(squareOnAPlate(method, adhesion, "2e-4"), "particles", 90, "ply")));
      ASSERT_FALSE(std::isnan(angle)) << "the drop left the plate";
      std::printf("%s 2D drop on a plate, adhesion %.2f: %.1f degrees\n", method.c_str(), adhesion, angle);
      EXPECT_NEAR(angle, std::acos(2 * adhesion - 1) * 180 / M_PI, 10);
    }
}

// WCSPH's walls take a particle's pressure once in a scene with surface tension (Akinci 2012), not mirrored: the
// cohesion holds the contact layer at the plate with its own pressure, where the mirrored wall's second share
// stood it off the plate (the adhesion's calibration assumes the rest lattice's stand-off) and fed its motion. The
// water square at 3 s: within the DFSPH test's 10 degrees of Young's (measured 121.0, 90.7, 55.8 at 3.75 spacings
// with the 2D share 0.9; 120.1, 83.9, 37.8 with beta whole, which fails; 124.8, 90.3, 55.5 at 4 spacings before
// session 68), and at rest, its motion under 1% of the surface energy released (measured 2e-4, 2e-5, 7e-6 of it).
// Mirrored, it stirred at 8 to 100% of it, read 111 and 98 degrees at 0.5 and 0.75, and at 0.25 the energy check
// stopped it at frame 82.
TEST(SurfaceTension, A2DWaterDropOnAPlateSettlesAtYoungsAngleInWcsph) {
  for (double adhesion : {0.25, 0.5, 0.75}) {
    SCOPED_TRACE("adhesion " + std::to_string(adhesion));
    const fs::path dir = squareOnAPlate("wcsph", adhesion, "0");
    const double angle = capAngle(readParticlePly(framePath(dir, "particles", 90, "ply")));
    ASSERT_FALSE(std::isnan(angle)) << "the drop left the plate";
    const auto stats = readStats(dir);
    const double motion = stats.at("kinetic_energy").back(), released = stats.at("source_work").back();
    std::printf("WCSPH 2D water drop on a plate, adhesion %.2f: %.1f degrees, motion %.2g of the %.3g J/m released\n",
                adhesion, angle, motion / released, released);
    EXPECT_NEAR(angle, std::acos(2 * adhesion - 1) * 180 / M_PI, 10);
    EXPECT_LT(motion, 0.01 * released);
  }
}

// solver.kernel_radius 0 gives a scene with surface tension 2.5 spacings in 3D and the method's own support in 2D
// (FluidMethod::surfaceTensionSupport2d: DFSPH and WCSPH 3.75 spacings, PBF 3.5), and any other scene 2 spacings; a
// radius the file gives is kept. PBF in 2D with surface tension at a support wider than 3 spacings takes relaxation
// 0.8 and no s_corr where the file leaves them out (resolvePbfDefaults), 0.01 and 0.1 elsewhere.
TEST(SurfaceTension, TheDefaultSupportWithSurfaceTensionIsTwoAndAHalfIn3DAndTheMethodsIn2D) {
  const auto spacings = [](int dim, const std::string& method, const std::vector<std::string>& extra) {
    return dropScene(dim, method, 0.005, extra).solver.kernel_radius / kSpacing;
  };
  EXPECT_NEAR(spacings(2, "dfsph", {}), 3.75, 1e-9);
  EXPECT_NEAR(spacings(2, "wcsph", {}), 3.75, 1e-9);
  EXPECT_NEAR(spacings(2, "pbf", {}), 3.5, 1e-9);
  const auto pbf = [](int dim, const std::vector<std::string>& extra) {
    const SolverSettings s = dropScene(dim, "pbf", 0.005, extra).solver;
    return std::pair{s.relaxation_epsilon, s.scorr_k};
  };
  EXPECT_EQ(pbf(2, {}), std::pair(0.8, 0.0));
  EXPECT_EQ(pbf(2, {"solver.kernel_radius=0.003"}), std::pair(0.01, 0.1));
  EXPECT_EQ(pbf(2, {"solver.kernel_radius=0.0025"}), std::pair(0.01, 0.1));
  EXPECT_EQ(pbf(2, {"fluids[0].surface_tension=0"}), std::pair(0.01, 0.1));
  EXPECT_EQ(pbf(3, {"solver.kernel_radius=0.0035"}), std::pair(0.01, 0.1));
  EXPECT_EQ(pbf(2, {"solver.relaxation_epsilon=0.1", "solver.scorr_k=0.05"}), std::pair(0.1, 0.05));
  for (const std::string method : {"dfsph", "wcsph", "pbf"}) {
    EXPECT_NEAR(spacings(3, method, {}), 2.5, 1e-9) << method;
    EXPECT_NEAR(spacings(3, method, {"fluids[0].surface_tension=0"}), 2, 1e-9) << method;
    EXPECT_NEAR(spacings(2, method, {"fluids[0].surface_tension=0"}), 2, 1e-9) << method;
    EXPECT_NEAR(spacings(2, method, {"solver.kernel_radius=0.003"}), 3, 1e-9) << method;
    EXPECT_NEAR(spacings(3, method, {"solver.kernel_radius=0.002"}), 2, 1e-9) << method;
  }
}

// Cohesion over 2 spacings holds a 2D drop as a crystal: surge sim says so where the scene sets a support under
// the one that rounds it (2.75 spacings; 2.5 in PBF, FluidMethod::roundingSupport2d) and under the method's own,
// and names the radius the default gives.
TEST(SurfaceTension, SurgeSimSaysA2DDropAtTwoSpacingsKeepsItsShape) {
  auto crystalNotes = [](int dim, const std::string& method, const std::vector<std::string>& extra) {
    int count = 0;
    for (const std::string& note : solverNotes(dropScene(dim, method, 0.005, extra)))
      if (note.find("crystal") != std::string::npos) {
        EXPECT_NE(note.find(method == "pbf" ? "3.5 spacings (0.0035 here)" : "3.75 spacings (0.00375 here)"),
                  std::string::npos)
            << note;
        ++count;
      }
    return count;
  };
  for (const std::string method : {"dfsph", "wcsph", "pbf"}) {
    EXPECT_EQ(crystalNotes(2, method, {"solver.kernel_radius=0.002"}), 1) << method;
    EXPECT_EQ(crystalNotes(2, method, {}), 0) << method;
    EXPECT_EQ(crystalNotes(2, method, {"solver.kernel_radius=0.003"}), 0) << method;
    EXPECT_EQ(crystalNotes(3, method, {}), 0) << method;
    EXPECT_EQ(crystalNotes(2, method, {"solver.kernel_radius=0.002", "fluids[0].surface_tension=0"}), 0) << method;
  }
  EXPECT_EQ(crystalNotes(2, "dfsph", {"solver.kernel_radius=0.0025"}), 1);
  EXPECT_EQ(crystalNotes(2, "pbf", {"solver.kernel_radius=0.0025"}), 0);
}

// In 3D the cohesion over 2 spacings holds a set (ABoxDropRoundsAndItsEnergyIsAccounted reads 2.3% there): surge
// sim says so where a 3D scene with surface tension sets a support under the default's 2.5 spacings, and names it.
TEST(SurfaceTension, SurgeSimSaysA3DDropAtTwoSpacingsKeepsASet) {
  auto setNotes = [](const std::string& method, const std::vector<std::string>& extra) {
    int count = 0;
    for (const std::string& note : solverNotes(dropScene(3, method, 0.005, extra)))
      if (note.find("holds the particles in a set") != std::string::npos) {
        EXPECT_NE(note.find("2.5 spacings (0.0025 here)"), std::string::npos) << note;
        ++count;
      }
    return count;
  };
  for (const std::string method : {"dfsph", "wcsph", "pbf"}) {
    EXPECT_EQ(setNotes(method, {"solver.kernel_radius=0.002"}), 1) << method;
    EXPECT_EQ(setNotes(method, {}), 0) << method;
    EXPECT_EQ(setNotes(method, {"solver.kernel_radius=0.003"}), 0) << method;
    EXPECT_EQ(setNotes(method, {"solver.kernel_radius=0.002", "fluids[0].surface_tension=0"}), 0) << method;
  }
}

// The adhesion's calibration is measured at 2, 2.5 and 3 spacings of support (the test above; adhesionCalibration),
// not at 2.25 or 3.5: surge sim says so where a scene with adhesion and surface tension has another support.
TEST(SurfaceTension, SurgeSimSaysTheAdhesionIsCalibratedAtTwoTwoAndAHalfAndThreeSpacings) {
  auto adhesionNotes = [](const std::vector<std::string>& extra) {
    std::string json = R"({"name": "plate", "dimensions": 3, "domain": {"min": [-0.02, -0.006, -0.02],
        "max": [0.02, 0.03, 0.02]}, "particle_spacing": 0.001, "gravity": [0, 0, 0], "solver": {"method": "dfsph"},
        "fluids": [{"box": {"min": [-0.006, 0, -0.006], "max": [0.006, 0.012, 0.006]}, "surface_tension": 0.0728}],
        "colliders": [{"shape": "box", "position": [0, -0.003, 0], "size": [0.04, 0.006, 0.04]}]})";
    int count = 0;
    for (const std::string& note : solverNotes(parseScene(json, "plate.json", extra)))
      count += note.find("adhesion is calibrated at 2, 2.5 and 3 spacings") != std::string::npos;
    return count;
  };
  EXPECT_EQ(adhesionNotes({"colliders[0].adhesion=0.5"}), 0);
  EXPECT_EQ(adhesionNotes({"colliders[0].adhesion=0.5", "solver.kernel_radius=0.002"}), 0);
  EXPECT_EQ(adhesionNotes({"colliders[0].adhesion=0.5", "solver.kernel_radius=0.00225"}), 1);
  EXPECT_EQ(adhesionNotes({"colliders[0].adhesion=0.5", "solver.kernel_radius=0.003"}), 0);
  EXPECT_EQ(adhesionNotes({"colliders[0].adhesion=0.5", "solver.kernel_radius=0.0035"}), 1);
  EXPECT_EQ(adhesionNotes({"solver.kernel_radius=0.0025"}), 0);
}

// The adhesion's calibration meets Young's angle in DFSPH (ADropOnAPlateSettlesAtYoungsAngle) and in WCSPH (117, 92,
// 69 degrees at 0.25, 0.5, 0.75 since its walls take the particle's pressure once with surface tension; before,
// 126, 111, 94); PBF reads 116, 96, 76 at the 3D default support: surge sim says so for a scene with adhesion in
// PBF, with its figures.
TEST(SurfaceTension, SurgeSimSaysTheAdhesionIsCalibratedInDfsph) {
  auto methodNotes = [](const std::string& method, const std::vector<std::string>& extra) {
    std::string json = R"({"name": "plate", "dimensions": 3, "domain": {"min": [-0.02, -0.006, -0.02],
        "max": [0.02, 0.03, 0.02]}, "particle_spacing": 0.001, "gravity": [0, 0, 0], "solver": {"method": ")" +
                       method + R"("}, "fluids": [{"box": {"min": [-0.006, 0, -0.006], "max": [0.006, 0.012, 0.006]},
        "surface_tension": 0.0728}], "colliders": [{"shape": "box", "position": [0, -0.003, 0], "size": [0.04, 0.006,
        0.04]}]})";
    std::vector<std::string> found;
    for (const std::string& note : solverNotes(parseScene(json, "plate.json", extra)))
      if (note.find("adhesion is calibrated in DFSPH") != std::string::npos) found.push_back(note);
    return found;
  };
  const auto pbf = methodNotes("pbf", {"colliders[0].adhesion=0.5"});
  ASSERT_EQ(pbf.size(), 1u);
  EXPECT_NE(pbf[0].find("in PBF the same drop reads 116, 96, 76 degrees"), std::string::npos) << pbf[0];
  EXPECT_TRUE(methodNotes("wcsph", {"colliders[0].adhesion=0.5"}).empty());
  EXPECT_TRUE(methodNotes("dfsph", {"colliders[0].adhesion=0.5"}).empty());
  EXPECT_TRUE(methodNotes("pbf", {}).empty());
  EXPECT_TRUE(methodNotes("pbf", {"colliders[0].adhesion=0.5", "fluids[0].surface_tension=0"}).empty());
}

// In 2D surge sim gives each method's own angles (FluidMethod::adhesionAngles2d, the 3D test's drop in 2D at the
// method's 2D support: DFSPH 128, 93, 18; PBF 116, 81, 20; WCSPH 126, 94, 47 degrees) in place of the 3D notes,
// and says where the scene's support is not the one they were measured at.
TEST(SurfaceTension, SurgeSimGivesEachMethodsAdhesionAnglesIn2D) {
  auto adhesionNotes = [](const std::string& method, const std::vector<std::string>& extra) {
    std::string json = R"({"name": "plate", "dimensions": 2, "domain": {"min": [-0.03, -0.006], "max": [0.03, 0.03]},
        "particle_spacing": 0.001, "gravity": [0, 0], "solver": {"method": ")" + method + R"("},
        "fluids": [{"box": {"min": [-0.006, 0], "max": [0.006, 0.012]}, "surface_tension": 0.0728}],
        "colliders": [{"shape": "box", "position": [0, -0.003], "size": [0.06, 0.006]}]})";
    std::vector<std::string> found;
    for (const std::string& note : solverNotes(parseScene(json, "plate.json", extra)))
      if (note.find("adhesion") != std::string::npos) found.push_back(note);
    return found;
  };
  const std::vector<std::pair<std::string, std::string>> angles = {
      {"dfsph", "DFSPH at its own 3.75 spacings of kernel support reads 128, 93, 18 degrees"},
      {"pbf", "PBF at its own 3.5 spacings of kernel support reads 116, 81, 20 degrees"},
      {"wcsph", "WCSPH at its own 3.75 spacings of kernel support reads 126, 94, 47 degrees"}};
  for (const auto& [method, text] : angles) {
    const auto own = adhesionNotes(method, {"colliders[0].adhesion=0.5"});
    ASSERT_EQ(own.size(), 1u) << method;
    EXPECT_NE(own[0].find(text), std::string::npos) << own[0];
    EXPECT_EQ(own[0].find("not measured"), std::string::npos) << own[0];
    const auto narrow = adhesionNotes(method, {"colliders[0].adhesion=0.5", "solver.kernel_radius=0.002"});
    ASSERT_EQ(narrow.size(), 1u) << method;
    EXPECT_NE(narrow[0].find("at this scene's 2 it is not measured"), std::string::npos) << narrow[0];
    EXPECT_TRUE(adhesionNotes(method, {}).empty()) << method;
  }
}

// Bad input: one line naming the key.
TEST(SurfaceTension, BadInputIsRefusedNamingTheKey) {
  auto message = [](const std::vector<std::string>& overrides) {
    try {
      dropScene(2, "pbf", 0.004, overrides);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message({"fluids[0].surface_tension=-1"}).find("fluids[0].surface_tension"), std::string::npos);
  EXPECT_NE(message({"solver.surface_tension_model=young"}).find("solver.surface_tension_model"), std::string::npos);
  std::string two;
  try {
    parseScene(R"({"name": "two", "dimensions": 2, "domain": {"min": [0, 0], "max": [1, 1]}, "particle_spacing": 0.01,
                   "fluids": [{"box": {"min": [0, 0], "max": [0.2, 0.2]}, "surface_tension": 0.07},
                              {"box": {"min": [0.5, 0], "max": [0.7, 0.2]}, "surface_tension": 0.03}]})",
               "two.json");
  } catch (const InputError& e) {
    two = e.what();
  }
  EXPECT_NE(two.find("two.json"), std::string::npos) << two;
  EXPECT_NE(two.find("fluids[1].surface_tension"), std::string::npos) << two;
  // Adhesion without surface tension does nothing: surge sim says so before it starts.
  const Scene dry = parseScene(
      R"({"name": "dry", "dimensions": 2, "domain": {"min": [0, 0], "max": [1, 1]}, "particle_spacing": 0.01,
          "fluids": [{"box": {"min": [0, 0], "max": [0.2, 0.2]}}],
          "colliders": [{"shape": "box", "position": [0.5, 0.1], "size": [0.1, 0.1], "adhesion": 0.5}]})",
      "dry.json");
  const std::vector<std::string> notes = solverNotes(dry);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("adhesion"), std::string::npos);
}

}  // namespace
}  // namespace surge
