// Every scene key, declared once. Keep docs/scene-format.md in step by running `surge keys`.
#include "core/scene_fields.h"

#include <iomanip>
#include <sstream>

namespace surge {
namespace {

using field::atLeast;
using field::info;
using field::positive;
using field::required;

void visitBox(SceneVisitor& v, const char* key, Box& box, const char* what) {
  v.group(key, info(what), [&] {
    v.vector("min", box.min, required("lower corner", "m"));
    v.vector("max", box.max, required("upper corner", "m"));
  });
}

void visitRotation(SceneVisitor& v, Rotation& r) {
  v.group("rotation", info("rotation about an axis through the position; in 2D always about z"), [&] {
    v.vector("axis", r.axis, info("rotation axis (any length but 0; 3 components also in 2D)"), true);
    v.real("degrees", r.degrees, info("angle, counter-clockwise about the axis", "degrees"));
  });
}

// Keyframes of a collider's or a sink's position and rotation.
void visitMotion(SceneVisitor& v, ColliderSettings& c, const char* description) {
  v.list(
      "motion", info(description), [&] { return c.motion.size(); }, [&](size_t n) { c.motion.resize(n); },
      [&](size_t i) {
        v.real("time", c.motion[i].time, atLeast(0, "time of the keyframe", "s"));
        v.vector("position", c.motion[i].position, required("position at that time", "m"));
        visitRotation(v, c.motion[i].rotation);
      });
}

// The keys colliders and bodies share: a shape, its placement, its look. A body takes no plane or heightfield,
// its friction is its contacts' and its name defaults to body<i>.
void visitSolid(SceneVisitor& v, ColliderSettings& c, bool body) {
  v.text("name", c.name,
         body ? info("a name for bodies.csv and the output meshes (letters, digits, -, _, .); empty: body<i>")
              : info("a name for colliders.csv and the output meshes (letters, digits, -, _, .); empty: "
                     "collider<i>"));
  if (body)
    v.choice("shape", c.shape, {"box", "sphere", "capsule", "cylinder", "mesh"},
             required("box, sphere, capsule and cylinder (along local y), mesh (a closed OBJ or PLY; 3D only)"));
  else
    v.choice("shape", c.shape, {"plane", "box", "sphere", "capsule", "cylinder", "heightfield", "mesh"},
             required("plane (a half-space), box, sphere, capsule and cylinder (along local y), heightfield (a "
                      "greyscale PNG; the fluid stays above), mesh (OBJ or PLY)"));
  v.vector("position", c.position,
           body ? info("where the shape's centre (a mesh's origin) starts", "m")
                : info("the shape's centre; a point on a plane; the centre of a heightfield's base (black)", "m"));
  visitRotation(v, c.rotation);
  v.real("scale", c.scale, positive("uniform scale of the shape about its position"));
  if (!body)
    v.integer("container", c.container,
              atLeast(0, "1: the fluid is held inside the shape (a bowl, a glass) instead of kept out", "", 1));
  v.reals("size", c.size,
          info(body ? "box: full extents (a vector)" : "box: full extents (a vector); heightfield: [x, z] extents",
               "m"));
  v.real("radius", c.radius, positive("sphere, capsule and cylinder radius", "m"));
  v.real("height", c.height,
         positive(body ? "capsule and cylinder: length along local y (a capsule's without its caps)"
                       : "capsule and cylinder: length along local y (a capsule's without its caps); heightfield: "
                         "the height of white",
                  "m"));
  if (!body)
    v.vector("normal", c.normal, info("plane: the normal, pointing into the fluid (any length but 0)"));
  v.text("file", c.file,
         body ? info("mesh: a closed OBJ or PLY, relative to the scene file")
              : info("heightfield: a PNG (8 or 16 bit grey); mesh: an OBJ or PLY; relative to the scene file"));
  if (!body) {
    v.real("thickness", c.thickness,
           atLeast(0, "mesh: the shell thickness given to an open or non-manifold mesh; 0 means particle_spacing",
                   "m"));
    visitMotion(v, c,
                "keyframes of position and rotation, linearly interpolated (held before the first and after the "
                "last); empty: the collider stands still");
  }
  if (body)
    v.real("friction", c.friction,
           atLeast(0, "Coulomb friction coefficient of its contacts with bodies, colliders and the tank"));
  else
    v.real("friction", c.friction,
           atLeast(0, "the fraction of the fluid's sliding velocity along the wall taken away over each 1/30 s of "
                      "contact: 0 free slip, 1 no slip", "", 1));
  v.real("adhesion", c.adhesion,
         atLeast(0, "Akinci 2013's adhesion of the fluid to it, as the work of adhesion over the fluid's work of "
                    "cohesion (Young: cos theta = 2 adhesion - 1; 0.5 wets at 90 degrees, 1 spreads); acts with "
                    "the fluid's surface_tension; 0 turns it off", "", 1));
  v.real("viscous_slip", c.viscous_slip,
         atLeast(0, "a viscous fluid (fluids[i].viscosity) along it: 0 sticks to it (no slip), 1 slides freely",
                 "", 1));
  v.vector("color", c.color, atLeast(0, "linear RGB albedo in the renders", "", 1), true);
  v.integer("visible", c.visible, atLeast(0, "0: simulated but not drawn", "", 1));
}

// The shape keys a fluid block and a sink take: a solid of the collider vocabulary and its placement.
void visitShapeKeys(SceneVisitor& v, ColliderSettings& c, bool sink) {
  if (sink)
    v.text("name", c.name, info("a name for messages (letters, digits, -, _, .); empty: sink<i>"));
  v.text("shape", c.shape,
         sink ? required("plane (a half-space), box, sphere, capsule, cylinder (along local y), heightfield or mesh "
                         "(OBJ or PLY): particles inside it are removed")
              : info("instead of `box`: box, sphere, capsule, cylinder (along local y) or mesh (a closed OBJ or "
                     "PLY, 3D), every lattice site inside it filled"));
  v.vector("position", c.position, info("the shape's centre (a mesh's origin)", "m"));
  visitRotation(v, c.rotation);
  v.real("scale", c.scale, positive("uniform scale of the shape about its position"));
  v.reals("size", c.size, info(sink ? "box: full extents; heightfield: [x, z] extents" : "box: full extents", "m"));
  v.real("radius", c.radius, positive("sphere, capsule and cylinder radius", "m"));
  v.real("height", c.height, positive("capsule and cylinder: length along local y", "m"));
  if (sink) v.vector("normal", c.normal, info("plane: the normal, pointing out of the sink (any length but 0)"));
  v.text("file", c.file, info("mesh: an OBJ or PLY (closed, for a fluid); heightfield: a PNG; relative to the scene "
                              "file"));
  if (sink)
    visitMotion(v, c,
                "keyframes of position and rotation, linearly interpolated (held before the first and after the "
                "last); empty: the sink stands still");
}

void visitEmitter(SceneVisitor& v, EmitterSettings& e) {
  v.text("name", e.name, info("a name for messages (letters, digits, -, _, .); empty: emitter<i>"));
  v.choice("shape", e.shape, {"disc", "rectangle"},
           info("disc: a disc of `radius` across `direction` (in 2D a segment of length 2 radius); rectangle (3D): "
                "`size` [width, height], width along direction x up (x when direction is vertical), height across "
                "both"));
  v.vector("position", e.position, required("the centre of the emitting face", "m"));
  v.vector("direction", e.direction, required("the direction particles leave in (any length but 0)"));
  v.real("radius", e.radius, positive("disc: its radius (2D: half the segment's length)", "m"));
  v.reals("size", e.size, info("rectangle: [width, height]", "m"));
  v.real("speed", e.speed, atLeast(0, "the speed particles leave at; the volume flux is area x speed", "m/s"));
  v.real("start", e.start, atLeast(0, "when it opens", "s"));
  v.real("stop", e.stop, atLeast(0, "when it closes; 0: never", "s"));
  v.list(
      "motion", info("keyframes of position, direction and speed, linearly interpolated (held before the first "
                     "and after the last); empty: it stands still"),
      [&] { return e.motion.size(); }, [&](size_t n) { e.motion.resize(n); },
      [&](size_t i) {
        EmitterKeyframe& k = e.motion[i];
        v.real("time", k.time, atLeast(0, "time of the keyframe", "s"));
        v.vector("position", k.position, required("position at that time", "m"));
        v.vector("direction", k.direction, info("direction at that time; zero (the default): the emitter's"));
        v.real("speed", k.speed, info("speed at that time (0 closes it until a later keyframe opens it); "
                                      "negative (the default): the emitter's", "m/s"));
      });
  v.text("fluid", e.fluid,
         info("the name of the fluid it brings, a fluids[i].name (a block may then have neither box nor shape: it "
              "only says what that fluid is); empty: the first block's fluid"));
}

void visitBody(SceneVisitor& v, BodySettings& b) {
  visitSolid(v, b.solid, true);
  v.real("density", b.density,
         atLeast(0, "mass per volume (per area in 2D, like the fluid's rest_density); give density or mass",
                 "kg/m^3"));
  v.real("mass", b.mass, atLeast(0, "the body's mass (per metre of depth in 2D); give density or mass", "kg"));
  v.vector("velocity", b.velocity, info("initial velocity of the centre of mass", "m/s"));
  v.vector("angular_velocity", b.angular_velocity,
           info("initial angular velocity (3 components also in 2D, where only z counts)", "rad/s"), true);
  v.real("restitution", b.restitution,
         atLeast(0, "bounce of its contacts: 0 none, 1 elastic", "", 1));
}

}  // namespace

void visitScene(Scene& s, SceneVisitor& v) {
  v.text("name", s.name,
         required("the scene's name, a plain file name (letters, digits, -, _, ., not starting with .); the "
                  "default output folder is out/<name>"));
  {
    FieldInfo dims = required("2 or 3; in 2D every vector has two components");
    dims.min = 2;
    dims.max = 3;
    v.integer("dimensions", s.dimensions, dims);
  }
  v.group("domain", required("the tank: an axis-aligned box whose walls are solid"), [&] {
    v.vector("min", s.domain.min, required("lower corner", "m"));
    v.vector("max", s.domain.max, required("upper corner", "m"));
    v.choices("open", s.open, tankFaceNames(),
              info("faces that are not walls (2D: -x, +x, -y, +y): a particle crossing one is removed, and the "
                   "renders leave it out"));
    v.choices("periodic", s.periodic, {"x", "y", "z"},
              info("axes along which the domain wraps (2D: x, y): a particle leaving one side enters the other, "
                   "and neighbours, densities and the surface reach across the seam"));
    v.real("viscous_slip", s.viscous_slip,
           atLeast(0, "a viscous fluid (fluids[i].viscosity) along the walls: 0 sticks to them (no slip), 1 "
                      "slides freely", "", 1));
  });
  v.real("particle_spacing", s.particle_spacing,
         positive("initial lattice spacing; the particle radius is half of it", "m", true));
  v.list(
      "fluids", info("blocks of fluid at the start, each filled with particles on the lattice (none: the "
                     "emitters bring water at solver.rest_density)"),
      [&] { return s.fluids.size(); }, [&](size_t n) { s.fluids.resize(n); },
      [&](size_t i) {
        FluidBlock& f = s.fluids[i];
        visitBox(v, "box", f.box, "the block, filled with particles at cell centres of the lattice; or give a shape");
        visitShapeKeys(v, f.solid, false);
        v.vector("velocity", f.velocity, info("initial velocity", "m/s"));
        v.formulas("velocity_field", f.velocity_field,
                   info("an initial velocity field added to velocity: one formula of the position x, y, z (m) per "
                        "component, such as \"-cos(2*pi*x)*sin(2*pi*y)\" (numbers, pi, + - * / ^, sin, cos, tan, "
                        "exp, log, sqrt, abs, tanh, atan2, min, max, pow, ...)", "m/s"));
        v.real("surface_tension", f.surface_tension,
               atLeast(0, "surface tension sigma against air (water 0.0728; N in 2D), by "
                          "solver.surface_tension_model; 0 turns it off", "N/m"));
        v.text("name", f.name,
               info("the fluid it is: blocks of one name are one fluid, and a scene of several fluids writes "
                    "each particle's in its frames (`fluid`, the index of the fluid's first block) and a surface "
                    "for each (surface_<name> after the first); empty: water"));
        v.real("viscosity", f.viscosity,
               atLeast(0, "that fluid's kinematic viscosity nu (water 1e-6, honey 0.01 to 0.1), by "
                          "solver.viscosity_solver, no-slip at the walls; 0 none (WCSPH: solver.kinematic_viscosity, its own "
                          "pair term, where no fluid gives one)", "m^2/s"));
        v.real("rest_density", f.rest_density,
               positive("that fluid's rest density (oil about 900, water 1000); not given: solver.rest_density",
                        "kg/m^3"));
        v.vector("color", f.color,
                 atLeast(0.001, "that fluid's colour in the render, as render.water_color (not given: that)", "", 1),
                 true);
        v.real("absorption_distance", f.absorption_distance,
               positive("the distance over which that fluid absorbs white light to its colour, as "
                        "render.absorption_distance (not given: that); a strongly coloured liquid such as oil takes "
                        "its colour in centimetres where clear water takes metres",
                        "m"));
        v.real("jitter", f.jitter,
               atLeast(0, "each particle starts off its lattice site by up to this fraction of half the spacing "
                          "along each axis (a fixed pattern, by particle): a square lattice's rows can then not "
                          "snap all at once; at most 0.5, so that no pair starts closer than 0.5 spacing (WCSPH "
                          "gives the compression back as motion); 0: on the lattice", "", 0.5));
      });
  v.vector("gravity", s.gravity, info("gravitational acceleration", "m/s^2"));
  v.group("attractor", info("a point moving along keyframes that pulls (or pushes) particles near it"), [&] {
    v.real("radius", s.attractor.radius, positive("particles closer than this feel it", "m"));
    v.real("strength", s.attractor.strength,
           info("acceleration at its centre, falling linearly to 0 at the radius; negative pushes", "m/s^2"));
    v.list(
        "keyframes", info("times and positions, linearly interpolated (held before the first and after the last)"),
        [&] { return s.attractor.keyframes.size(); }, [&](size_t n) { s.attractor.keyframes.resize(n); },
        [&](size_t i) {
          v.real("time", s.attractor.keyframes[i].time, atLeast(0, "time of the keyframe", "s"));
          v.vector("position", s.attractor.keyframes[i].position, required("position at that time", "m"));
        });
  });

  v.list(
      "colliders", info("obstacles and containers the fluid meets (the tank's walls are always there)"),
      [&] { return s.colliders.size(); }, [&](size_t n) { s.colliders.resize(n); },
      [&](size_t i) { visitSolid(v, s.colliders[i], false); });
  v.list(
      "bodies", info("rigid bodies the fluid carries and pushes, and that collide with each other, the colliders "
                     "and the tank (Bullet)"),
      [&] { return s.bodies.size(); }, [&](size_t n) { s.bodies.resize(n); },
      [&](size_t i) { visitBody(v, s.bodies[i]); });
  v.list(
      "emitters", info("where fluid flows in: layers of particles leaving a disc or a rectangle (sim/sources.h)"),
      [&] { return s.emitters.size(); }, [&](size_t n) { s.emitters.resize(n); },
      [&](size_t i) { visitEmitter(v, s.emitters[i]); });
  v.list(
      "sinks", info("shapes that remove every particle entering them"), [&] { return s.sinks.size(); },
      [&](size_t n) { s.sinks.resize(n); }, [&](size_t i) { visitShapeKeys(v, s.sinks[i], true); });

  v.group("solver", info("the simulator"), [&] {
    std::vector<std::string> methods;
    std::string methodLines;
    for (const SolverMethodEntry& method : solverMethodCatalog()) {
      methods.push_back(method.name);
      methodLines += (methodLines.empty() ? "" : "; ") + method.name + ": " + method.description;
    }
    // A program without the simulator (no registry) takes any name, as it takes the simulator's defaults.
    if (methods.empty()) v.text("method", s.solver.method, info("the fluid method"));
    else v.choice("method", s.solver.method, methods, info(methodLines.c_str()));
    v.integer("substeps", s.solver.substeps,
              atLeast(0, "PBF: the fewest time steps per output frame, each shortened when the fluid needs it (the "
                         "CFL step, and dt <= 0.9 particle_spacing / sqrt(g depth) on its deepest column); WCSPH "
                         "chooses its own, see time_step; DFSPH takes at least this many, from its CFL step and the same depth "
                         "limit; 0: 4, or more if the pool the fluid settles into is "
                         "deep enough to need them (dt <= 0.9 particle_spacing / sqrt(g depth)) or an emitter fast "
                         "enough to (its jet moves at most half a spacing a step)", "", 100000));
    v.real("kernel_radius", s.solver.kernel_radius,
           atLeast(0,
                   "SPH kernel radius h; 0 means 2 x particle_spacing, and with surface tension 2.5 spacings "
                   "in 3D and in 2D the method's own support, 3.75 spacings in DFSPH and WCSPH, 3.5 in PBF "
                   "(docs/surface-tension.md)",
                   "m"));
    v.real("rest_density", s.solver.rest_density, positive("rest density rho_0", "kg/m^3"));
    v.real("max_density_error", s.solver.max_density_error,
           atLeast(0,
                   "PBF: when > 0, iterate until the average density error (a fraction) is under it, at most "
                   "`iterations` times; 0 runs exactly `iterations` (where the fluids' densities differ and "
                   "`iterations` is left out: 0.001). DFSPH: its density solver's limit on the average predicted "
                   "compression; 0 means 0.0005"));
    v.real("xsph_c", s.solver.xsph_c,
           atLeast(0, "PBF eq. 17 XSPH viscosity c (weights scaled by the particle volume), also DFSPH's; 0 turns "
                      "it off", "", 1));
    v.choice("kernel", s.solver.kernel, {"cubic_spline", "wendland_c2"},
             info("WCSPH and DFSPH smoothing kernel, support kernel_radius: cubic spline (Monaghan 1992) or "
                  "Wendland C2"));
    v.real("background_pressure", s.solver.background_pressure,
           atLeast(0, "Adami, Hu and Adams 2013's transport velocity: particles move as if under this extra "
                      "pressure, which keeps them evenly spaced, while their momentum does not feel it; for fluid "
                      "that fills its domain (it pulls a free surface apart). WCSPH: about 2 rho_0 c^2. DFSPH and "
                      "PBF: a push of dt^2 p_b / rho_0 a step, which bounds the step at 0.45 (kernel_radius / 2) / "
                      "sqrt(p_b / rho_0) (a vortex at spacing 0.02: 1e4 in DFSPH, 4e4 in PBF); 0 turns it off "
                      "(docs/viscosity.md)",
                      "Pa"));
    v.real("time_step", s.solver.time_step,
           atLeast(0, "WCSPH: a fixed step; 0 chooses each step from the CFL condition and the viscous and "
                      "force limits. DFSPH: the largest step (its CFL step may be shorter); 0 means one frame / "
                      "substeps", "s"));
    v.choice("surface_tension_model", s.solver.surface_tension_model, {"akinci2013"},
             info("how fluids[i].surface_tension acts: akinci2013, cohesion and curvature forces (Akinci, Akinci "
                  "and Teschner 2013) calibrated so that sigma is N/m (docs/surface-tension.md)"));
    v.choice("viscosity_solver", s.solver.viscosity_solver, {"default", "implicit", "explicit"},
             info("how fluids[i].viscosity acts: implicit, Weiler et al. 2018's backward Euler solved by "
                  "conjugate gradients (no step limit); explicit, Morris et al. 1997 (dt <= 0.125 (h/2)^2 / nu); "
                  "default: explicit for WCSPH, implicit for the others (docs/viscosity.md)"));
    v.choice("viscosity_operator", s.solver.viscosity_operator, {"laplacian", "strain"},
             info("the viscosity's pair term: laplacian, the Laplacian of each component (exact on the rest "
                  "lattice in every direction: for flows between walls); strain, Weiler et al. 2018's eq. 8, on "
                  "each pair's stretching (a free surface then carries no traction: a column of honey creeps at "
                  "Trouton's rate, a rope buckles and coils; a shear along a lattice axis reads 0.66 of nu). Free "
                  "surfaces that stretch, drip or coil want strain (docs/viscosity.md)"));
    v.real("viscosity_max_error", s.solver.viscosity_max_error,
           atLeast(0,
                   "the implicit viscosity solve stops when its residual is under this share of the step's "
                   "viscous change, |r| <= e |b - A v*|; 0: 0.01, or 0.001 with viscosity_operator strain, whose "
                   "stiff ropes creep in jerks at 0.01 (docs/viscosity.md)"));
    v.integer("viscosity_max_iterations", s.solver.viscosity_max_iterations,
              atLeast(1, "the most conjugate-gradient iterations of the implicit viscosity solve a step", "", 10000));
    FieldInfo cfl = positive("Courant number. WCSPH: dt <= cfl h / (c + |v|max), h = kernel_radius / 2; DFSPH: "
                             "dt <= cfl particle_spacing / |v|max; PBF: dt <= cfl kernel_radius / |v|max");
    cfl.max = 1;
    v.real("cfl", s.solver.cfl, cfl);
    for (const SolverMethodEntry& method : solverMethodCatalog())
      if (method.declareKeys) method.declareKeys(v, s.solver);
  });
  v.group("output", info("what the simulator writes"), [&] {
    v.real("fps", s.output.fps, positive("output frames per simulated second (and the video's frame rate)"));
    v.integer("frames", s.output.frames, atLeast(1, "frames to simulate after frame 0", "", 1e7));
  });
  v.group("whitewater", info("spray, foam and bubbles from the saved frames (docs/whitewater.md); U is the speed "
                              "of a fall through the tank, T the tank's diagonal over U, S the rest kernel sum"),
          [&] {
    WhitewaterSettings& w = s.whitewater;
    v.integer("enabled", w.enabled, atLeast(0, "1: surge run makes whitewater between sim and surface", "", 1));
    v.real("trapped_air_min", w.trapped_air_min, atLeast(0, "trapped air: potential 0 below this v_diff / (U S)"));
    v.real("trapped_air_max", w.trapped_air_max, positive("trapped air: potential 1 above this v_diff / (U S)"));
    v.real("wave_crest_min", w.wave_crest_min, atLeast(0, "wave crest: potential 0 below this curvature / S"));
    v.real("wave_crest_max", w.wave_crest_max, positive("wave crest: potential 1 above this curvature / S"));
    v.real("kinetic_min", w.kinetic_min, atLeast(0, "kinetic energy: potential 0 below this (|v| / U)^2"));
    v.real("kinetic_max", w.kinetic_max, positive("kinetic energy: potential 1 above this (|v| / U)^2"));
    v.real("trapped_air_rate", w.trapped_air_rate,
           atLeast(0, "diffuse particles a fluid particle makes per T at full trapped-air and kinetic potentials"));
    v.real("wave_crest_rate", w.wave_crest_rate,
           atLeast(0, "diffuse particles a fluid particle makes per T at full wave-crest and kinetic potentials"));
    v.real("lifetime_min", w.lifetime_min,
           atLeast(0, "shortest lifetime drawn, spent while the particle is foam or a bubble (not in the air); 0 means T", "s"));
    v.real("lifetime_max", w.lifetime_max, atLeast(0, "longest lifetime drawn; 0 means 3 T", "s"));
    v.real("spray_drag", w.spray_drag,
           atLeast(0, "air drag rate on spray (terminal fall |g| / drag); 0 means |g| / (2 U)", "1/s"));
    v.real("bubble_buoyancy", w.bubble_buoyancy, atLeast(0, "a bubble's upward acceleration, in |g|", "", 1000));
    v.real("bubble_drag", w.bubble_drag,
           atLeast(0, "rate a bubble's velocity relaxes to the fluid's (terminal rise buoyancy |g| / drag); 0 means "
                      "a rise of U / 10", "1/s"));
    v.integer("spray_neighbors", w.spray_neighbors,
              atLeast(0, "fewer fluid neighbours than this: spray; 0 means a fifth of the rest lattice's", "", 10000));
    v.integer("bubble_neighbors", w.bubble_neighbors,
              atLeast(0, "more fluid neighbours than this: a bubble (between: foam); 0 means three fifths of the "
                         "rest lattice's", "", 10000));
    v.real("particle_size", w.particle_size, atLeast(0, "radius a diffuse particle is drawn at; 0 means "
                                                        "particle_spacing / 4", "m"));
    v.integer("substeps", w.substeps,
              atLeast(0, "diffuse steps a frame; 0: enough that nothing moves more than a kernel radius in one",
                      "", 10000));
    v.integer("max_particles", w.max_particles,
              atLeast(0, "most diffuse particles at once; generation stops at it", "", 2e9));
  });
  v.group("surface", info("the surfacer"), [&] {
    v.real("particle_radius", s.surface.particle_radius,
           atLeast(0, "radius of each particle's sphere in the level set; 0 means particle_spacing", "m"));
    v.real("voxel_size", s.surface.voxel_size,
           atLeast(0, "level-set voxel size; 0 means particle_radius / 2 (never above particle_radius / 1.5, "
                      "below which OpenVDB would drop particles)",
                   "m"));
    v.real("adaptivity", s.surface.adaptivity, atLeast(0, "volumeToMesh adaptivity, 0 (uniform) to 1", "", 1));
    v.choice("method", s.surface.method, {"spheres", "smooth_spheres", "anisotropic"},
             info("level set: spheres (union of particle spheres), smooth_spheres (Zhu & Bridson 2005 blend), "
                  "anisotropic (Yu & Turk 2013 ellipsoids from neighbour PCA); see docs/performance.md"));
    v.integer("smoothing_steps", s.surface.smoothing_steps,
              atLeast(0,
                      "mean-curvature smoothing steps of the level set, each moving the surface by at most a "
                      "third of a voxel times its curvature in voxels; 0 turns smoothing off",
                      "", 100));
    v.integer("write_velocity", s.surface.write_velocity,
              atLeast(0, "1: the VDB also holds a velocity grid `v` (particle velocities, kernel-averaged)", "", 1));
    v.integer("write_points", s.surface.write_points,
              atLeast(0, "1: the VDB also holds the particles as a PointDataGrid `points` with a `v` attribute", "", 1));
    v.integer("write_obj", s.surface.write_obj, atLeast(0, "1: write an OBJ mesh beside each PLY mesh", "", 1));
    v.integer("mesh_velocity", s.surface.mesh_velocity,
              atLeast(-1,
                      "1: each mesh vertex carries the particles' velocity there (PLY vx vy vz, kernel-averaged), "
                      "for motion blur; 0: none; -1: as render.quality, on for final",
                      "", 1));
  });
  v.group("render", info("the renderer"), [&] {
    v.integer("width", s.render.width, atLeast(16, "image width", "pixels", 16384));
    v.integer("height", s.render.height, atLeast(16, "image height", "pixels", 16384));
    v.integer("samples", s.render.samples, atLeast(1, "samples per pixel", "", 65536));
    v.integer("max_depth", s.render.max_depth,
              atLeast(1, "path tracer: most surfaces a path meets (Russian roulette may stop it sooner)", "", 1000));
    v.integer("denoise", s.render.denoise,
              atLeast(0, "1: filter the path tracer's noise, guided by its normals, depths and albedos", "", 1));
    v.integer("edge_samples", s.render.edge_samples,
              atLeast(0, "samples a pixel takes in all where its first samples straddle surfaces (an edge, a "
                         "splash); not above `samples`: every pixel takes `samples`", "", 65536));
    v.choice("quality", s.render.quality, {"standard", "preview", "final"},
             info("standard: width, height, samples and max_depth as given; preview: half the resolution, 4 "
                  "samples, depth 4; final: at least 720 pixels high, 64 samples, depth 12"));
    v.group("camera", info("the camera; leave position equal to look_at to frame the domain"), [&] {
      v.vector("position", s.render.camera.position, info("eye position", "m"), true);
      v.vector("look_at", s.render.camera.look_at, info("point at the image centre", "m"), true);
      FieldInfo fov = positive("vertical field of view", "degrees");
      fov.max = 170;
      v.real("fov", s.render.camera.fov, fov);
    });
    v.vector("water_color", s.render.water_color,
             atLeast(0.001, "linear RGB colour white light takes through absorption_distance of water", "", 1), true);
    v.real("absorption_distance", s.render.absorption_distance,
           positive("distance over which water absorbs white light to water_color (Beer-Lambert)", "m"));
    v.vector("sun_direction", s.render.sun_direction, info("direction towards the sun (any length but 0)"), true);
    v.vector("sun_color", s.render.sun_color, atLeast(0, "linear RGB irradiance of the sun", "", 1000), true);
    FieldInfo sunRadius = positive("angular radius of the sun; larger gives softer shadows", "degrees");
    sunRadius.max = 30;
    v.real("sun_radius", s.render.sun_radius, sunRadius);
    v.vector("sky_zenith", s.render.sky_zenith, atLeast(0, "linear RGB radiance of the sky overhead", "", 1000), true);
    v.vector("sky_horizon", s.render.sky_horizon,
             atLeast(0, "linear RGB radiance of the sky at the horizon", "", 1000), true);
    v.real("exposure", s.render.exposure, positive("scale on linear light before the tone map"));
    v.choice("tank", s.render.tank, {"edges", "glass", "none"},
             info("how the tank is drawn: its edges as thin dark bars, its walls as clear glass (path tracer; the "
                  "preview draws edges), or not at all"));
    v.vector("spray_color", s.render.spray_color, atLeast(0, "linear RGB albedo of spray", "", 1), true);
    v.vector("foam_color", s.render.foam_color, atLeast(0, "linear RGB albedo of foam", "", 1), true);
    v.vector("bubble_color", s.render.bubble_color, atLeast(0, "linear RGB albedo of bubbles", "", 1), true);
    v.real("spray_size", s.render.spray_size, positive("spray's radius, times whitewater.particle_size"));
    v.real("foam_size", s.render.foam_size, positive("foam's radius, times whitewater.particle_size"));
    v.real("bubble_size", s.render.bubble_size, positive("bubbles' radius, times whitewater.particle_size"));
  });
}

namespace field {

FieldInfo info(const char* description, const char* units) {
  FieldInfo f;
  f.description = description;
  f.units = units;
  return f;
}
FieldInfo required(const char* description, const char* units) {
  FieldInfo f = info(description, units);
  f.required = true;
  return f;
}
FieldInfo positive(const char* description, const char* units, bool isRequired) {
  FieldInfo f = info(description, units);
  f.min = 0;
  f.minExclusive = true;
  f.required = isRequired;
  return f;
}
FieldInfo atLeast(double min, const char* description, const char* units, double max) {
  FieldInfo f = info(description, units);
  f.min = min;
  f.max = max;
  return f;
}

}  // namespace field

std::string formatNumber(double value) {
  std::ostringstream out;
  out << std::setprecision(10) << value;
  return out.str();
}

}  // namespace surge
