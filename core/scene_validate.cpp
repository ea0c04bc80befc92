// Checking a scene once its keys are read (core/scene.h): what the keys' declared ranges cannot say (a box's min
// below its max, names unique and plain, keyframes in time order, fluid inside the tank), the derived defaults
// (kernel radius, surface radius and voxel), and the simulator's, through solverDefaults(). The camera that frames
// the domain is the renderer's (render/camera.h, framedCamera).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>

#include "core/errors.h"
#include "core/scene.h"
#include "core/scene_fields.h"

namespace surge {
namespace {

bool isPlainName(const std::string& name) {
  if (name.empty() || name.front() == '.') return false;
  for (char c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_' && c != '.') return false;
  return true;
}

void validateRotation(const Rotation& r, int dimensions, const std::string& where, const std::string& key) {
  if (!(r.axis.norm() > 0)) throw InputError(where, key + ".axis", "must not be the zero vector");
  if (dimensions == 2 && r.degrees != 0 && (std::abs(r.axis.x()) > 0 || std::abs(r.axis.y()) > 0))
    throw InputError(where, key + ".axis", "in 2D a rotation is about z: leave the axis out or make it [0, 0, 1]");
}

// What can be checked of the colliders without reading their files (geometry/collider_shape.cpp checks those).
// What colliders and bodies share: a unique plain name, a shape with the parameters it needs.
void validateSolid(ColliderSettings& c, const std::string& key, const std::string& defaultName, int dimensions,
                   std::set<std::string>& names, const std::string& where) {
  if (c.name.empty()) c.name = defaultName;
  if (!isPlainName(c.name))
    throw InputError(where, key + ".name", "must be letters, digits, '-', '_' or '.', not starting with '.'");
  if (!names.insert(c.name).second)
    throw InputError(where, key + ".name", "'" + c.name + "' is used twice");
  validateRotation(c.rotation, dimensions, where, key + ".rotation");
  if (c.shape == "box") {
    if (c.size.size() != size_t(dimensions))
      throw InputError(where, key + ".size",
                       "a box needs its full extents, " + std::to_string(dimensions) + " numbers");
  } else if (c.shape == "heightfield") {
    if (c.size.size() != 2) throw InputError(where, key + ".size", "a heightfield needs its [x, z] extents");
  } else if (!c.size.empty()) {
    throw InputError(where, key + ".size", "only a box or a heightfield has a size");
  }
  for (double extent : c.size)
    if (!(extent > 0)) throw InputError(where, key + ".size", "extents must be > 0");
  if ((c.shape == "heightfield" || c.shape == "mesh") && c.file.empty())
    throw InputError(where, key + ".file", "a " + c.shape + " needs a file");
  if (c.shape != "heightfield" && c.shape != "mesh" && !c.file.empty())
    throw InputError(where, key + ".file", "only a heightfield or a mesh reads a file");
}

// What can be checked of the colliders and bodies without reading their files (geometry/collider_shape.cpp
// checks those; sim/rigid_bodies.cpp checks that bodies do not overlap at the start).
void validateSolids(Scene& s, const std::string& where) {
  std::set<std::string> names;
  for (size_t i = 0; i < s.colliders.size(); ++i) {
    ColliderSettings& c = s.colliders[i];
    const std::string key = "colliders[" + std::to_string(i) + "]";
    validateSolid(c, key, "collider" + std::to_string(i), s.dimensions, names, where);
    if (c.shape == "plane") {
      if (!(c.normal.norm() > 0)) throw InputError(where, key + ".normal", "must not be the zero vector");
      if (c.container) throw InputError(where, key + ".container", "a plane cannot hold fluid; turn its normal");
    }
    if (c.thickness == 0) c.thickness = s.particle_spacing;
    for (size_t k = 0; k < c.motion.size(); ++k) {
      const std::string frameKey = key + ".motion[" + std::to_string(k) + "]";
      validateRotation(c.motion[k].rotation, s.dimensions, where, frameKey + ".rotation");
      if (k > 0 && c.motion[k].time < c.motion[k - 1].time)
        throw InputError(where, frameKey + ".time", "keyframes must be in time order");
    }
  }
  for (size_t i = 0; i < s.bodies.size(); ++i) {
    BodySettings& b = s.bodies[i];
    const std::string key = "bodies[" + std::to_string(i) + "]";
    validateSolid(b.solid, key, "body" + std::to_string(i), s.dimensions, names, where);
    if (b.solid.shape == "mesh" && s.dimensions == 2)
      throw InputError(where, key + ".shape", "a mesh body needs 3 dimensions");
    if ((b.density > 0) == (b.mass > 0))
      throw InputError(where, key + (b.density > 0 ? ".mass" : ".density"),
                       "give a body its density or its mass (> 0), not both");
    b.solid.thickness = s.particle_spacing;
    if (s.dimensions == 2) {
      // Motion in the plane: no z velocity, no spin but about z.
      b.velocity.z() = 0;
      b.angular_velocity.x() = b.angular_velocity.y() = 0;
    }
  }
}

// Fluid blocks: a box inside the tank, or a shape of the bodies' vocabulary (geometry/ checks its file and that
// it lies in the tank).
void validateFluids(Scene& s, const std::string& where) {
  constexpr size_t kMostFluids = 255;  // a particle frame's `fluid` is a byte
  // The fluid each emitter brings names one of the blocks' (emitters[i].fluid).
  for (FluidBlock& fluid : s.fluids)
    if (fluid.name.empty()) fluid.name = "water";
  for (size_t i = 0; i < s.emitters.size(); ++i) {
    const std::string& name = s.emitters[i].fluid;
    auto named = [&](const FluidBlock& f) { return f.name == name; };
    if (name.empty() || std::any_of(s.fluids.begin(), s.fluids.end(), named)) continue;
    std::string known;
    for (size_t b = 0; b < s.fluids.size(); ++b)
      if (s.fluidOf(b) == b) known += (known.empty() ? "" : ", ") + s.fluids[b].name;
    throw InputError(where, "emitters[" + std::to_string(i) + "].fluid",
                     "'" + name + "' is not the name of a fluid: " +
                         (known.empty() ? std::string("the scene has no fluids blocks") : "the scene has " + known));
  }
  for (size_t i = 0; i < s.fluids.size(); ++i) {
    FluidBlock& fluid = s.fluids[i];
    const std::string key = "fluids[" + std::to_string(i) + "]";
    // Which fluid: a name that can end a grid's name (surface_<name>), and one density and colour a name.
    if (!std::all_of(fluid.name.begin(), fluid.name.end(), [](char c) { return std::isalnum(uint8_t(c)) || c == '_' || c == '-'; }))
      throw InputError(where, key + ".name", "'" + fluid.name + "' may hold only letters, digits, _ and -");
    if (fluid.rest_density == 0) fluid.rest_density = s.solver.rest_density;
    if (i >= kMostFluids) throw InputError(where, key, "a scene holds at most 255 fluid blocks");
    const FluidBlock& first = s.fluids[s.fluidOf(i)];
    if (fluid.rest_density != first.rest_density)
      throw InputError(where, key + ".rest_density",
                       formatNumber(fluid.rest_density) + " differs from fluids[" + std::to_string(s.fluidOf(i)) +
                           "]'s " + formatNumber(first.rest_density) + ", a block of the same fluid '" + fluid.name +
                           "': give it another name");
    if (s.fluidColor(i) != s.fluidColor(s.fluidOf(i)))
      throw InputError(where, key + ".color",
                       "differs from fluids[" + std::to_string(s.fluidOf(i)) + "]'s, a block of the same fluid '" +
                           fluid.name + "': give it another name");
    if (s.fluidAbsorptionDistance(i) != s.fluidAbsorptionDistance(s.fluidOf(i)))
      throw InputError(where, key + ".absorption_distance",
                       formatNumber(s.fluidAbsorptionDistance(i)) + " differs from fluids[" +
                           std::to_string(s.fluidOf(i)) + "]'s " +
                           formatNumber(s.fluidAbsorptionDistance(s.fluidOf(i))) + ", a block of the same fluid '" +
                           fluid.name + "': give it another name");
    if (fluid.viscosity != first.viscosity)
      throw InputError(where, key + ".viscosity",
                       formatNumber(fluid.viscosity) + " differs from fluids[" + std::to_string(s.fluidOf(i)) +
                           "]'s " + formatNumber(first.viscosity) + ", a block of the same fluid '" + fluid.name +
                           "': give it another name");
    if (fluid.surface_tension != first.surface_tension)
      throw InputError(where, key + ".surface_tension",
                       formatNumber(fluid.surface_tension) + " differs from fluids[" + std::to_string(s.fluidOf(i)) +
                           "]'s " + formatNumber(first.surface_tension) + ", a block of the same fluid '" +
                           fluid.name + "': give it another name");
    const Box& b = fluid.box;
    if (fluid.shaped()) {
      const std::string& shape = fluid.solid.shape;
      if (shape != "box" && shape != "sphere" && shape != "capsule" && shape != "cylinder" && shape != "mesh")
        throw InputError(where, key + ".shape", "'" + shape + "' is not one of: box, sphere, capsule, cylinder, mesh");
      if (shape == "mesh" && s.dimensions == 2) throw InputError(where, key + ".shape", "a mesh fluid needs 3 dimensions");
      if (b.min != b.max) throw InputError(where, key + ".box", "give the fluid a box or a shape, not both");
      std::set<std::string> names;
      validateSolid(fluid.solid, key, "fluid" + std::to_string(i), s.dimensions, names, where);
      continue;
    }
    // A block of neither box nor shape holds no particles: it says what the fluid an emitter brings is.
    const bool emitted = std::any_of(s.emitters.begin(), s.emitters.end(), [&](const EmitterSettings& e) {
      return e.fluid.empty() ? i == 0 : e.fluid == fluid.name;
    });
    if (emitted && b.min == Eigen::Vector3d::Zero() && b.max == Eigen::Vector3d::Zero()) continue;
    for (int k = 0; k < s.dimensions; ++k) {
      if (!(b.min[k] < b.max[k]))
        throw InputError(where, key + ".box", "min must be below max on every axis (or give a shape)");
      if (b.min[k] < s.domain.min[k] || b.max[k] > s.domain.max[k])
        throw InputError(where, key + ".box", "lies outside the domain");
    }
  }
}

// Emitters, sinks and open faces: what can be checked without the geometry (sim/sources.cpp checks that an
// emitter is clear of the colliders and that the sinks leave some of the fluid).
void validateSources(Scene& s, const std::string& where) {
  const int d = s.dimensions;
  for (const std::string& face : s.open)
    if (d == 2 && face.back() == 'z')
      throw InputError(where, "domain.open", "'" + face + "' does not exist in 2D (faces -x, +x, -y, +y)");
  std::set<std::string> names;
  for (size_t i = 0; i < s.emitters.size(); ++i) {
    EmitterSettings& e = s.emitters[i];
    const std::string key = "emitters[" + std::to_string(i) + "]";
    if (e.name.empty()) e.name = "emitter" + std::to_string(i);
    if (!isPlainName(e.name))
      throw InputError(where, key + ".name", "must be letters, digits, '-', '_' or '.', not starting with '.'");
    if (!names.insert(e.name).second) throw InputError(where, key + ".name", "'" + e.name + "' is used twice");
    if (!(e.direction.head(d).norm() > 0)) throw InputError(where, key + ".direction", "must not be the zero vector");
    if (e.shape == "rectangle") {
      if (d == 2) throw InputError(where, key + ".shape", "a rectangle needs 3 dimensions; in 2D a disc is a segment");
      if (e.size.size() != 2 || !(e.size[0] > 0) || !(e.size[1] > 0))
        throw InputError(where, key + ".size", "a rectangle needs its [width, height], both > 0");
    } else if (!e.size.empty()) {
      throw InputError(where, key + ".size", "only a rectangle has a size; a disc has a radius");
    }
    if (e.stop != 0 && !(e.stop > e.start)) throw InputError(where, key + ".stop", "must be after start (or 0: never)");
    for (int k = 0; k < d; ++k)
      if (e.position[k] < s.domain.min[k] || e.position[k] > s.domain.max[k])
        throw InputError(where, key + ".position", "lies outside the tank");
    for (size_t k = 0; k < e.motion.size(); ++k) {
      const std::string frameKey = key + ".motion[" + std::to_string(k) + "]";
      if (k > 0 && e.motion[k].time < e.motion[k - 1].time)
        throw InputError(where, frameKey + ".time", "keyframes must be in time order");
      for (int a = 0; a < d; ++a)
        if (e.motion[k].position[a] < s.domain.min[a] || e.motion[k].position[a] > s.domain.max[a])
          throw InputError(where, frameKey + ".position", "lies outside the tank");
    }
  }
  names.clear();
  for (size_t i = 0; i < s.sinks.size(); ++i) {
    ColliderSettings& c = s.sinks[i];
    const std::string key = "sinks[" + std::to_string(i) + "]";
    validateSolid(c, key, "sink" + std::to_string(i), d, names, where);
    if (c.shape == "plane" && !(c.normal.norm() > 0))
      throw InputError(where, key + ".normal", "must not be the zero vector");
    if (c.thickness == 0) c.thickness = s.particle_spacing;
  }
}

void validateWhitewater(Scene& s, const std::string& where) {
  WhitewaterSettings& w = s.whitewater;
  if (w.particle_size == 0) w.particle_size = s.particle_spacing / 4;  // the later stages draw any whitewater/
  if (!w.enabled) return;
  auto ordered = [&](double lo, double hi, const char* key) {
    if (!(lo < hi)) throw InputError(where, std::string("whitewater.") + key, "must exceed its _min");
  };
  ordered(w.trapped_air_min, w.trapped_air_max, "trapped_air_max");
  ordered(w.wave_crest_min, w.wave_crest_max, "wave_crest_max");
  ordered(w.kinetic_min, w.kinetic_max, "kinetic_max");
  const WhitewaterScale scale = whitewaterScale(s);
  if (!(scale.speed > 0))
    throw InputError(where, "whitewater.enabled",
                     "the scene has neither gravity nor a moving fluid to set the whitewater's scale");
  const double g = s.gravity.norm();
  if (w.lifetime_min == 0) w.lifetime_min = scale.time;
  if (w.lifetime_max == 0) w.lifetime_max = std::max(3 * scale.time, w.lifetime_min);
  if (w.lifetime_max < w.lifetime_min)
    throw InputError(where, "whitewater.lifetime_max", "must not be below lifetime_min");
  if (w.spray_drag == 0) w.spray_drag = g / (2 * scale.speed);
  if (w.bubble_drag == 0) w.bubble_drag = w.bubble_buoyancy * g / (0.1 * scale.speed);
  const int rest = int(restNeighborDistances(s).size());
  if (w.spray_neighbors == 0) w.spray_neighbors = std::max(1, int(std::lround(rest / 5.0)));
  if (w.bubble_neighbors == 0) w.bubble_neighbors = std::max(w.spray_neighbors, int(std::lround(rest * 0.6)));
  if (w.bubble_neighbors < w.spray_neighbors)
    throw InputError(where, "whitewater.bubble_neighbors", "must not be below spray_neighbors");
}

}  // namespace

double defaultKernelSupport(const Scene& s) {
  const bool tension =
      std::any_of(s.fluids.begin(), s.fluids.end(), [](const FluidBlock& f) { return f.surface_tension > 0; });
  if (!tension) return 2;
  if (s.dimensions == 3) return 2.5;
  for (const SolverMethodEntry& method : solverMethodCatalog())
    if (method.name == s.solver.method) return method.surfaceTensionSupport2d;
  return 2;
}

std::vector<double> restNeighborDistances(const Scene& s) {
  const double spacing = s.particle_spacing, h = s.solver.kernel_radius;
  const int reach = int(std::floor(h / spacing)), zReach = s.dimensions == 3 ? reach : 0;
  std::vector<double> distances;
  for (int z = -zReach; z <= zReach; ++z)
    for (int y = -reach; y <= reach; ++y)
      for (int x = -reach; x <= reach; ++x) {
        const double r = spacing * std::sqrt(double(x * x + y * y + z * z));
        if (r > 0 && r < h) distances.push_back(r);
      }
  return distances;
}

WhitewaterScale whitewaterScale(const Scene& s) {
  // In 2D the z components are zero.
  const double diagonal = (s.domain.max - s.domain.min).norm();
  double speed = std::sqrt(2 * s.gravity.norm() * diagonal);
  if (speed == 0) {
    for (const FluidBlock& block : s.fluids) speed = std::max(speed, block.velocity.norm());
    for (const EmitterSettings& emitter : s.emitters) speed = std::max(speed, std::abs(emitter.speed));
  }
  return WhitewaterScale{speed, speed > 0 ? diagonal / speed : 0.0};
}

// domain.periodic: axes the scene has, not open, and at least three kernel radii long (the neighbour grid's
// stencil of three cells must not meet itself across the seam, and a pair's nearest image must be unique).
static void validatePeriodic(const Scene& s, const std::string& where) {
  for (const std::string& axis : s.periodic) {
    const int k = axis[0] - 'x';
    if (k >= s.dimensions)
      throw InputError(where, "domain.periodic", "'" + axis + "' does not exist in 2D (axes x, y)");
    if (s.isOpen(k, false) || s.isOpen(k, true))
      throw InputError(where, "domain.periodic", "'" + axis + "' has an open face (domain.open): a periodic axis has no faces");
    if (s.domain.max[k] - s.domain.min[k] < 3 * s.solver.kernel_radius)
      throw InputError(where, "domain.periodic",
                       "the domain along " + axis + " must be at least 3 kernel radii (" +
                           formatNumber(3 * s.solver.kernel_radius) + " m) to wrap");
  }
}

void validateScene(Scene& s, const std::string& where) {
  // The default output folder is out/<name>: a scene file must not choose where Surge writes.
  if (!isPlainName(s.name))
    throw InputError(where, "name", "must be a plain file name: letters, digits, '-', '_' or '.', not starting with '.'");
  const int d = s.dimensions;
  for (int k = 0; k < d; ++k)
    if (!(s.domain.min[k] < s.domain.max[k]))
      throw InputError(where, "domain", "min must be below max on every axis");
  validateFluids(s, where);
  const double spacing = s.particle_spacing;
  const bool shaped = std::any_of(s.fluids.begin(), s.fluids.end(), [](const FluidBlock& f) { return f.shaped(); });
  if (s.fluids.empty() && s.emitters.empty())
    throw InputError(where, "fluids", "the scene has no fluid: give a fluid block or an emitter");
  const bool boxed =
      std::any_of(s.fluids.begin(), s.fluids.end(), [](const FluidBlock& f) { return f.box.min != f.box.max; });
  if (boxed && !shaped && s.particleCount() == 0)
    throw InputError(where, "fluids",
                     "the fluid boxes hold no particles at particle_spacing " + formatNumber(spacing));
  validateSources(s, where);

  SolverSettings& solver = s.solver;
  if (solver.kernel_radius == 0) solver.kernel_radius = defaultKernelSupport(s) * spacing;
  if (solver.kernel_radius <= spacing)
    throw InputError(where, "solver.kernel_radius", "must exceed particle_spacing, or particles have no neighbours");
  // The neighbour grid covers the particles' box only (sparsely if need be); cell coordinates must fit.
  for (int k = 0; k < d; ++k)
    if ((s.domain.max[k] - s.domain.min[k]) / solver.kernel_radius > double(1 << 20))
      throw InputError(where, "domain", "spans more than 2^20 kernel radii along an axis");
  validatePeriodic(s, where);

  for (size_t i = 1; i < s.attractor.keyframes.size(); ++i)
    if (s.attractor.keyframes[i].time < s.attractor.keyframes[i - 1].time)
      throw InputError(where, "attractor.keyframes[" + std::to_string(i) + "].time", "keyframes must be in time order");

  validateSolids(s, where);

  SurfaceSettings& surface = s.surface;
  if (surface.particle_radius == 0) surface.particle_radius = spacing;
  if (surface.voxel_size == 0) surface.voxel_size = surface.particle_radius / 2;
  if (surface.voxel_size > surface.particle_radius / 1.5)
    throw InputError(where, "surface.voxel_size",
                     "above particle_radius / 1.5: OpenVDB would drop every particle sphere");
  // The surfacer keys its blocks of 8^3 voxels by 21-bit coordinates about the origin (2^23 voxels each way);
  // half that leaves room for the band around the domain.
  for (int k = 0; k < d; ++k)
    if (std::max(std::abs(s.domain.min[k]), std::abs(s.domain.max[k])) / surface.voxel_size > double(1 << 22))
      throw InputError(where, "surface.voxel_size", "the domain reaches more than 2^22 voxels from the origin");

  validateWhitewater(s, where);

  // The simulator's defaults (sim/solver_defaults.cpp), where the program has the simulator.
  if (solverDefaults()) solverDefaults()(s);
  // The methods' keys where their own defaults (PBF where the fluids' densities differ, WCSPH with surface tension
  // in 3D) left them unset, and in every other scene, whose scene.json writes them too: 4 iterations, s_corr 0.1,
  // Chebyshev 0.85, relaxation 0.01, alpha 0.05.
  if (s.solver.iterations == 0) s.solver.iterations = 4;
  if (std::isnan(s.solver.relaxation_epsilon)) s.solver.relaxation_epsilon = SolverSettings::kRelaxationEpsilon;
  if (std::isnan(s.solver.scorr_k)) s.solver.scorr_k = 0.1;
  if (std::isnan(s.solver.chebyshev_rho)) s.solver.chebyshev_rho = SolverSettings::kChebyshevRho;
  if (std::isnan(s.solver.artificial_viscosity)) s.solver.artificial_viscosity = 0.05;
}

Eigen::Array3i latticeCounts(const Scene& scene, const Box& box) {
  Eigen::Array3i counts(1, 1, 1);
  for (int k = 0; k < scene.dimensions; ++k) {
    const double n = std::floor((box.max[k] - box.min[k]) / scene.particle_spacing + 1e-6);
    counts[k] = static_cast<int>(std::min(std::max(n, 0.0), 2e9));
  }
  return counts;
}

size_t Scene::fluidOf(size_t block) const {
  for (size_t i = 0; i < block; ++i)
    if (fluids[i].name == fluids[block].name) return i;
  return block;
}

size_t Scene::emittedFluid(size_t emitter) const {
  for (size_t i = 0; i < fluids.size(); ++i)
    if (fluids[i].name == emitters[emitter].fluid) return i;
  return 0;
}

bool Scene::severalFluids() const {
  for (size_t i = 1; i < fluids.size(); ++i)
    if (fluids[i].name != fluids[0].name) return true;
  return false;
}

bool Scene::densitiesDiffer() const {
  return std::any_of(fluids.begin(), fluids.end(),
                     [&](const FluidBlock& f) { return f.rest_density != referenceDensity(); });
}

Eigen::Vector3d Scene::fluidColor(size_t block) const {
  const Eigen::Vector3d& own = fluids[block].color;
  return own == Eigen::Vector3d::Zero() ? render.water_color : own;
}

double Scene::fluidAbsorptionDistance(size_t block) const {
  const double own = fluids[block].absorption_distance;
  return own == 0 ? render.absorption_distance : own;
}

std::vector<size_t> Scene::laterFluids() const {
  std::vector<size_t> later;
  for (size_t i = 1; i < fluids.size(); ++i)
    if (fluidOf(i) == i) later.push_back(i);
  return later;
}

size_t Scene::particleCount() const {
  size_t total = 0;
  for (const FluidBlock& fluid : fluids) {
    if (fluid.shaped()) continue;
    const Eigen::Array3i n = latticeCounts(*this, fluid.box);
    total += size_t(n[0]) * size_t(n[1]) * size_t(n[2]);
  }
  return total;
}

SolverDefaults& solverDefaults() {
  static SolverDefaults resolve = nullptr;
  return resolve;
}

std::vector<SolverMethodEntry>& solverMethodCatalog() {
  static std::vector<SolverMethodEntry> methods;
  return methods;
}

std::vector<SolidFiles> solidFiles(const Scene& scene) {
  std::vector<SolidFiles> solids;
  for (const ColliderSettings& c : scene.colliders) solids.push_back({c, "colliders", c.motion.size() > 1});
  for (const BodySettings& b : scene.bodies) solids.push_back({b.solid, "bodies", true});
  return solids;
}

}  // namespace surge
