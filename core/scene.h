// A scene: what to simulate, surface and render. Read from JSON into these typed structs; every key is
// declared once, in scene_fields.cpp, with its default, range and description (docs/scene-format.md is
// generated from that declaration by `surge keys`). SI units, y up; in 2D, vectors have two components and z
// is zero here.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <limits>
#include <string>
#include <vector>

#include "core/files.h"

namespace surge {

class SceneVisitor;  // core/scene_fields.h

struct Box {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();
  Eigen::Vector3d max = Eigen::Vector3d::Zero();
};

// The tank's faces by name, in this order (2D: the first four).
inline const std::vector<std::string>& tankFaceNames() {
  static const std::vector<std::string> names = {"-x", "+x", "-y", "+y", "-z", "+z"};
  return names;
}

struct SolverSettings {
  std::string method = "pbf";
  int substeps = 0;  // 0 in the file: max(4, stableSubsteps) (resolved)
  // PBF; 0 in the file: 4, 8 where surface tension holds a fluid under gravity, or 30 where the fluids' densities
  // differ (resolved on load)
  int iterations = 0;
  double kernel_radius = 0;  // 0 in the file: 2 x particle_spacing, wider with surface tension (resolved on load)
  double rest_density = 1000;
  // PBF eq. 11's epsilon. Left out (NaN): 0.01, or 0.8 in 2D with surface tension at a support wider than 3
  // spacings (resolved on load).
  double relaxation_epsilon = std::numeric_limits<double>::quiet_NaN();
  static constexpr double kRelaxationEpsilon = 0.01;
  double warm_start = 0;  // PBF: share of last step's lambda sums applied before the iterations (experimental)
  // PBF to max_density_error: the spectral radius its Chebyshev acceleration assumes. Left out (NaN): 0.85, or 0
  // in 3D at a support wider than 2 spacings (resolved on load).
  double chebyshev_rho = std::numeric_limits<double>::quiet_NaN();
  static constexpr double kChebyshevRho = 0.85;
  // The smallest `iterations` cap the acceleration runs under: cut shorter, it stirs the fluid (sim/pbf_solver.cpp).
  static constexpr int kChebyshevLeastIterations = 8;
  double max_density_error = 0;  // > 0: iterate until the average density error is under it (DFSPH: 0 means 0.0005)
  double max_divergence_error = 0.001;  // DFSPH's divergence solver: average density change a step would cause
  int max_iterations = 100;             // DFSPH: the most iterations of each of its solvers a step
  // PBF eq. 13-14's artificial pressure; 0 turns it off. Left out (NaN): 0.1, or in PBF 0 where the fluids'
  // densities differ without surface tension (resolved on load).
  double scorr_k = std::numeric_limits<double>::quiet_NaN();
  int scorr_n = 4;
  double scorr_delta_q = 0.2;  // as a fraction of the kernel radius
  double vorticity_epsilon = 0;  // vorticity confinement (eq. 15-16); 0 turns it off
  double xsph_c = 0.01;          // XSPH viscosity (eq. 17); 0 turns it off
  // Weakly compressible SPH (solver.method "wcsph", sim/wcsph_solver.h); kernel, cfl and time_step also DFSPH's.
  std::string kernel = "cubic_spline";   // or "wendland_c2"
  std::string equation_of_state = "tait";  // or "linear" (the gas law k (rho - rho_0))
  double speed_of_sound = 0;             // 0 in the file: 10 x the speed of a fall through the tank (resolved)
  double gas_constant = 0;               // linear law's k; 0 in the file: speed_of_sound^2 (resolved)
  std::string integrator = "velocity_verlet";  // or "symplectic_euler"
  double time_step = 0;                  // > 0: a fixed step; 0: from the CFL, viscous and force limits
  double cfl = 0.4;
  // Monaghan's alpha; 0 turns it off. Left out (NaN): 0.05, or 0.01 in WCSPH in a 3D scene with surface tension
  // (resolved on load).
  double artificial_viscosity = std::numeric_limits<double>::quiet_NaN();
  double kinematic_viscosity = 0;        // laminar nu (m^2/s); 0 turns it off
  double near_pressure = 0;              // Clavet et al. 2005 near-pressure stiffness; 0 turns it off
  double background_pressure = 0;        // Adami et al. 2013's transport velocity (Pa); 0 turns it off
  std::string surface_tension_model = "akinci2013";  // how fluids[i].surface_tension acts (sim/surface_tension.h)
  // How fluids[i].viscosity acts (sim/viscosity.h): "implicit", "explicit", or "default": explicit for WCSPH,
  // implicit for the others.
  std::string viscosity_solver = "default";
  // Its pair term (sim/viscosity.h): "laplacian" (each component's) or "strain" (Weiler et al.'s eq. 8).
  std::string viscosity_operator = "laplacian";
  // The implicit solve's residual over the step's viscous change; 0: 0.01, or 0.001 with the strain's operator
  // (resolveSolverDefaults).
  double viscosity_max_error = 0;
  int viscosity_max_iterations = 100;
};

struct AttractorKeyframe {
  double time = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
};

// A point that moves along keyframes and pulls (strength > 0) or pushes particles within its radius, as the
// SPH demo's mouse did. No keyframes: no attractor.
struct AttractorSettings {
  double radius = 0.2;
  double strength = 20;
  std::vector<AttractorKeyframe> keyframes;
};

// A rotation about an axis through the shape's position (in 2D always about z).
struct Rotation {
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  double degrees = 0;
};

struct ColliderKeyframe {
  double time = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Rotation rotation;
};

// An obstacle or a container the fluid meets (geometry/collider_shape.h builds it, sim/colliders.h simulates
// it). Shapes are given in their own frame (centred on `position`, capsule and cylinder along local y) and
// placed by scale, then rotation, then translation.
struct ColliderSettings {
  std::string name;            // empty in the file: "collider<i>" (resolved)
  std::string shape = "box";   // plane, box, sphere, capsule, cylinder, heightfield, mesh
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Rotation rotation;
  double scale = 1;
  int container = 0;           // 1: the fluid stays inside the shape
  std::vector<double> size;    // box: full extents (a vector); heightfield: [x, z] extents
  double radius = 0.1;
  double height = 0.2;         // capsule, cylinder: length along local y; heightfield: height of white
  Eigen::Vector3d normal = Eigen::Vector3d::UnitY();  // plane
  std::string file;            // heightfield PNG or mesh OBJ/PLY, relative to the scene file (resolved absolute)
  double thickness = 0;        // open meshes: shell thickness; 0 means particle_spacing (resolved)
  std::vector<ColliderKeyframe> motion;
  double friction = 0;
  double adhesion = 0;         // W_adhesion / (2 sigma) of the fluid on it (sim/surface_tension.h); 0 none
  double viscous_slip = 0;     // a viscous fluid along it: 0 no slip, 1 free slip (sim/viscosity.h)
  Eigen::Vector3d color = Eigen::Vector3d(0.62, 0.6, 0.56);
  int visible = 1;
};

// A rigid body in the water (sim/rigid_bodies.h): a solid of the colliders' vocabulary (a box, sphere, capsule,
// cylinder or closed mesh, placed as a collider is) whose motion is computed from gravity, the fluid's force and
// torque, and contacts with the other bodies, the colliders and the tank. `solid.friction` is the Coulomb
// coefficient of its contacts (the fluid slides freely along it).
struct BodySettings {
  ColliderSettings solid;
  double density = 0;  // kg/m^3 (kg/m^2 in 2D, as the fluid's); 0: from mass
  double mass = 0;     // kg (kg/m in 2D); 0: from density
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  // rad/s, about the centre of mass (z in 2D)
  double restitution = 0.1;
};

// A block of fluid at t = 0: a box, or a solid of the bodies' shapes placed as a collider is (`solid.shape`
// empty: the box). Every lattice site inside it is filled (sim/simulation.h, initialParticles).
struct FluidBlock {
  Box box;
  ColliderSettings solid = shapeless();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  std::vector<std::string> velocity_field;  // a formula of x, y, z per component, added to velocity; empty none
  double surface_tension = 0;  // sigma, N/m (N in 2D); 0 none
  double viscosity = 0;        // kinematic nu, m^2/s (sim/viscosity.h); 0 none
  // The fluid it is (blocks of one name are one fluid). Empty in the file: "water" (resolved).
  std::string name;
  double rest_density = 0;  // kg/m^3 (kg/m^2 in 2D); 0 in the file: solver.rest_density (resolved)
  // The render's water colour, reached after absorption_distance (m). Not resolved: zero and 0 stand for
  // render.water_color and render.absorption_distance (Scene::fluidColor), so that a run's render follows those.
  Eigen::Vector3d color = Eigen::Vector3d::Zero();
  double absorption_distance = 0;
  double jitter = 0;  // each particle off its lattice site by up to jitter x half the spacing per axis (<= 0.5)

  bool shaped() const { return !solid.shape.empty(); }
  static ColliderSettings shapeless() {
    ColliderSettings c;
    c.shape.clear();
    return c;
  }
};

struct EmitterKeyframe {
  double time = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  // zero: the emitter's direction
  double speed = -1;                                    // negative: the emitter's speed
};

// Where fluid enters (sim/sources.h): layers of particles leave a disc (a segment in 2D) or a rectangle, along
// `direction` at `speed`, from `start` until `stop`; a keyframe may move it, turn it and change its speed.
struct EmitterSettings {
  std::string name;  // empty in the file: "emitter<i>" (resolved)
  std::string shape = "disc";
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
  double radius = 0.05;
  std::vector<double> size;  // rectangle: [width, height]
  double speed = 1;
  double start = 0;
  double stop = 0;  // 0: never
  std::vector<EmitterKeyframe> motion;
  std::string fluid;  // the name of the fluid it brings (a fluids[i].name); empty: the first block's
};

struct OutputSettings {
  double fps = 30;
  int frames = 90;
};

struct SurfaceSettings {
  double particle_radius = 0;  // 0 in the file: particle_spacing (resolved on load)
  double voxel_size = 0;       // 0 in the file: particle_radius / 2 (resolved on load)
  double adaptivity = 0;
  std::string method = "spheres";      // spheres, smooth_spheres or anisotropic (surface/surfacer.h)
  int smoothing_steps = 2;             // mean-curvature steps of tools::LevelSetFilter
  int write_velocity = 0;              // 1: the VDB also holds a vector grid "v"
  int mesh_velocity = -1;              // 1: mesh vertices carry velocities; -1: on for render.quality final
  int write_points = 0;                // 1: the VDB also holds a PointDataGrid "points" with attribute "v"
  int write_obj = 0;                   // 1: an OBJ mesh beside the PLY
};

// Spray, foam and bubbles made from the saved particle frames (whitewater/, after Ihmsen, Akinci, Akinci and
// Teschner 2012). Thresholds and rates are relative to the scene, so that the same scene at any size makes
// whitewater alike: U is the speed of a fall through the tank's diagonal (or the fluid's fastest start, without
// gravity), T = diagonal / U its time, S the kernel's sum over the rest lattice. 0 in the file: derived (resolved).
struct WhitewaterSettings {
  int enabled = 0;
  double trapped_air_min = 0.02, trapped_air_max = 0.2;  // on v_diff / (U S) (Ihmsen's eq. 2)
  double wave_crest_min = 0.1, wave_crest_max = 0.5;     // on kappa / S (eq. 4-7)
  double kinetic_min = 0.01, kinetic_max = 0.2;          // on (|v| / U)^2 (eq. 8)
  double trapped_air_rate = 8;  // diffuse particles a fluid particle makes per T at full potentials (eq. 9)
  double wave_crest_rate = 8;
  double lifetime_min = 0, lifetime_max = 0;  // s, drawn per particle, spent while foam or a bubble; 0: 1 T and 3 T
  double spray_drag = 0;       // 1/s, air drag on spray; 0: |g| / (2 U), a terminal fall of 2 U
  double bubble_buoyancy = 4;  // times |g|
  double bubble_drag = 0;      // 1/s, toward the fluid's velocity; 0: a terminal rise of U / 10
  int spray_neighbors = 0;     // fewer fluid neighbours: spray; 0: a fifth of the rest lattice's
  int bubble_neighbors = 0;    // more: a bubble; between: foam; 0: three fifths of the rest lattice's
  double particle_size = 0;    // m, the radius drawn; 0: particle_spacing / 4
  int substeps = 0;            // per frame; 0: so that nothing moves more than a kernel radius a substep
  int max_particles = 4000000;
};

// The whitewater's scale: U (m/s) and T (s) of WhitewaterSettings.
struct Scene;
struct WhitewaterScale {
  double speed = 0, time = 0;
};
WhitewaterScale whitewaterScale(const Scene& scene);

struct CameraSettings {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // == look_at: the renderer frames the domain (camera.h)
  Eigen::Vector3d look_at = Eigen::Vector3d::Zero();
  double fov = 40;  // vertical field of view in degrees
};

struct RenderSettings {
  int width = 960;
  int height = 540;
  int samples = 2;  // per pixel (path tracer), at least; see edge_samples and docs/performance.md
  int max_depth = 8;  // path segments before a path stops (Russian roulette may stop it sooner)
  int denoise = 1;       // 1: the path tracer's image goes through the edge-aware filter (render/denoiser.h)
  int edge_samples = 4;  // samples a pixel takes in all when its first ones straddle surfaces (<= samples: none)
  std::string quality = "standard";  // standard: the numbers above; preview and final scale them (renderer.h)
  CameraSettings camera;
  Eigen::Vector3d water_color = Eigen::Vector3d(0.15, 0.45, 0.8);
  double absorption_distance = 0.25;  // white light takes water_color after this far through water (m)
  Eigen::Vector3d sun_direction = Eigen::Vector3d(-0.4, 0.85, -0.25);  // towards the sun
  Eigen::Vector3d sun_color = Eigen::Vector3d(1.0, 0.95, 0.87);
  double sun_radius = 1.2;  // angular radius in degrees (soft shadows)
  Eigen::Vector3d sky_zenith = Eigen::Vector3d(0.32, 0.5, 0.82);
  Eigen::Vector3d sky_horizon = Eigen::Vector3d(0.78, 0.84, 0.9);
  double exposure = 1.0;
  std::string tank = "edges";  // how the tank is drawn: edges, glass or none
  // Whitewater (whitewater.enabled): each kind's linear RGB albedo and its size, times whitewater.particle_size.
  Eigen::Vector3d spray_color = Eigen::Vector3d(0.9, 0.92, 0.95);
  Eigen::Vector3d foam_color = Eigen::Vector3d(0.95, 0.95, 0.95);
  Eigen::Vector3d bubble_color = Eigen::Vector3d(0.8, 0.85, 0.9);
  double spray_size = 1, foam_size = 1.5, bubble_size = 0.8;
};

struct Scene {
  std::string name;
  int dimensions = 3;
  Box domain;
  std::vector<std::string> open;  // domain.open: tank faces that are not walls (tankFaceNames)
  std::vector<std::string> periodic;  // domain.periodic: axes ("x", "y", "z") along which the domain wraps
  double viscous_slip = 0;        // domain.viscous_slip: a viscous fluid along the tank's walls, 0 no slip
  double particle_spacing = 0;
  std::vector<FluidBlock> fluids;
  Eigen::Vector3d gravity = Eigen::Vector3d(0, -9.81, 0);
  AttractorSettings attractor;
  std::vector<ColliderSettings> colliders;
  std::vector<BodySettings> bodies;
  std::vector<EmitterSettings> emitters;
  std::vector<ColliderSettings> sinks;  // shapes that remove the particles entering them
  SolverSettings solver;
  OutputSettings output;
  WhitewaterSettings whitewater;
  SurfaceSettings surface;
  RenderSettings render;

  // The scene file it was read from (not a key): collider files are found beside it, errors name it.
  std::string source;

  // Particles the fluid boxes hold on the lattice of particle_spacing (shaped fluids not counted: the simulator
  // fills them, initialParticles in sim/simulation.h).
  size_t particleCount() const;
  // The fluid of block i: the index of the first block of its name (a particle frame's `fluid` property).
  size_t fluidOf(size_t block) const;
  // The fluid emitter e brings, as fluidOf: its `fluid`'s first block, or 0.
  size_t emittedFluid(size_t emitter) const;
  // True when the blocks name more than one fluid: the particles then carry their fluid.
  bool severalFluids() const;
  // True when some fluid's rest density is not the first's (a density contrast: docs/several-fluids.md).
  bool densitiesDiffer() const;
  // The first block of every fluid after the first, in order (none in a scene of one fluid).
  std::vector<size_t> laterFluids() const;
  // Block i's colour in the render and the distance over which white light takes it: its own, or the render's
  // water_color and absorption_distance where it gives none.
  Eigen::Vector3d fluidColor(size_t block) const;
  double fluidAbsorptionDistance(size_t block) const;
  // The rest density of the particles that are not told apart: the first block's, or solver.rest_density
  // without blocks.
  double referenceDensity() const { return fluids.empty() ? solver.rest_density : fluids.front().rest_density; }
  // True when fluid can enter or leave: emitters, sinks or open faces.
  bool hasSources() const { return !emitters.empty() || !sinks.empty() || !open.empty(); }
  // True when domain.periodic names `axis` (0 x, 1 y, 2 z).
  bool isPeriodic(int axis) const {
    return std::find(periodic.begin(), periodic.end(), std::string(1, char('x' + axis))) != periodic.end();
  }
  // The periodic axes as bits (1 << axis).
  int periodicAxes() const {
    int axes = 0;
    for (int k = 0; k < 3; ++k) axes |= isPeriodic(k) << k;
    return axes;
  }
  // True when domain.open names the tank's face on `axis` (0 x, 1 y, 2 z), its upper side or its lower.
  bool isOpen(int axis, bool upper) const {
    const std::string face = std::string(upper ? "+" : "-") + char('x' + axis);
    for (const std::string& name : open)
      if (name == face) return true;
    return false;
  }
  // True when the tank has a wall on that face: it is neither open nor on a periodic axis.
  bool hasWall(int axis, bool upper) const { return !isOpen(axis, upper) && !isPeriodic(axis); }
};

// A collider or a body as the simulation left it for the later stages: its mesh in the world at time 0 in
// <folder>/<name>.ply and, when it moves (keyframes, or a body), at each frame in <folder>/<name>/frame_NNNNN.ply.
struct SolidFiles {
  ColliderSettings settings;  // a body's solid settings
  std::string folder;         // "colliders" or "bodies", under the output folder
  bool moving = false;
};
// The scene's colliders, then its bodies.
std::vector<SolidFiles> solidFiles(const Scene& scene);

// The simulator's defaults for what the file left 0 (solver.substeps, speed_of_sound, ...): they come from the
// methods' physics, so sim/ installs the function that resolves them (sim/solver_defaults.h) and the scene
// reader calls it last; a program without the simulator reads those keys as the file gives them.
using SolverDefaults = void (*)(Scene&);
SolverDefaults& solverDefaults();
// The methods `solver.method` may name, with the line each adds to the key's description, in the order of sim/'s
// registry, which fills this list wherever the simulator is linked (sim/fluid_solver.cpp); empty, any name is read.
struct SolverMethodEntry {
  std::string name, description;
  void (*declareKeys)(SceneVisitor&, SolverSettings&) = nullptr;  // its own keys under `solver`
  double surfaceTensionSupport2d = 2;  // solver.kernel_radius 0's spacings in 2D with surface tension
};
std::vector<SolverMethodEntry>& solverMethodCatalog();
// solver.kernel_radius 0's support in spacings: 2, or with surface tension wider, where its cohesion lets a drop
// flow and ring rather than hold a set: 2.5 in 3D, the method's own in 2D (docs/surface-tension.md).
double defaultKernelSupport(const Scene& scene);

// Lattice points of one fluid box: counts per axis (1 on unused axes in 2D).
Eigen::Array3i latticeCounts(const Scene& scene, const Box& box);
// The distances (m) from a site of the rest lattice (particle_spacing, in the scene's dimensions) to its
// neighbours closer than solver.kernel_radius, itself left out.
std::vector<double> restNeighborDistances(const Scene& scene);

// Loads a scene file, applies `overrides` ("key.path=value", from --set) and checks it; derived defaults are
// resolved. Throws InputError naming the file (or --set) and the key.
Scene loadScene(const fs::path& path, const std::vector<std::string>& overrides = {});
// The same from JSON text; `where` names the source in messages.
Scene parseScene(const std::string& text, const std::string& where,
                 const std::vector<std::string>& overrides = {});

// The scene as JSON text with every key (the resolved scene saved as scene.json in the output folder).
std::string sceneToJson(const Scene& scene);

// The settings a later stage reads, as dir/<stage>_settings.json ("surface", "render" or "whitewater"), with `extra` (the
// stage's own options, a JSON object) added; the file is rewritten only when they change, so that its time says
// when they last did. Each frame a stage makes is up to date when it is newer than its inputs and this file, so
// a changed render setting leaves the surfaces up to date, and a changed surface setting the physics.
//   surface: dimensions, domain, particle_spacing, surface, colliders, bodies (and whitewater where enabled)
//   render:  dimensions, domain, particle_spacing, render, colliders, bodies (and whitewater where enabled)
//   whitewater: dimensions, domain, particle_spacing, gravity, solver, whitewater
fs::path writeStageSettings(const fs::path& dir, const std::string& stage, const Scene& scene,
                            const std::string& extra = "{}");

// A markdown table of every key: path, type, default, allowed values, meaning.
std::string sceneKeysMarkdown();

}  // namespace surge
