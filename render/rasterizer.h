// The quick-look renderer: OSMesa (Mesa's off-screen GL, no display needed) rasterises the water mesh, or the
// particles as shaded spheres, with the same camera, sky, sun and ground colours as the path tracer but no
// refraction or shadows: each water vertex is a Fresnel blend (Schlick) of the sky it reflects and the
// water's body colour, plus a sun highlight. Two-dimensional scenes are drawn face-on with an orthographic
// camera as a clean picture of the fluid in the tank. Colliders are drawn in their colour: lit by sky and sun
// (Lambert and ambient) in 3D, as flat cross-sections with the plane z = 0 in 2D. Images are drawn at twice
// the resolution and averaged down 2x2, for anti-aliased edges.
#pragma once

#include <memory>

#include "core/ply.h"
#include "core/scene.h"
#include "render/colliders.h"
#include "render/image.h"
#include "render/whitewater_spheres.h"

namespace surge {

// Another fluid's surface mesh in a scene of several, and its liquid's absorption (Shading::absorptionOf).
struct FluidMesh {
  TriangleMesh mesh;
  Eigen::Vector3f absorption = Eigen::Vector3f::Zero();
};

class Rasterizer {
 public:
  // One GL context for the scene's resolved resolution (render.quality applies). Throws RunError if OSMesa
  // cannot create it.
  explicit Rasterizer(const Scene& scene);
  ~Rasterizer();
  Rasterizer(const Rasterizer&) = delete;
  Rasterizer& operator=(const Rasterizer&) = delete;

  // Throws InputError if a triangle names a vertex the mesh does not have.
  // With the frame's whitewater as spheres (discs in 2D, at least a spacing across) in their colours, lit as
  // the colliders are.
  // `others`: the other fluids' meshes of a scene of several, each in its fluid's colour (fluids[i].color).
  Image drawMesh(const TriangleMesh& water, const std::vector<ColliderMesh>& colliders = {},
                 const WhitewaterSpheres& whitewater = {}, const std::vector<FluidMesh>& others = {});
  // Spheres of radius particle_spacing / 2 (in 2D flat discs of 0.8 particle_spacing, overlapping).
  Image drawParticles(const ParticleFrame& particles, const std::vector<ColliderMesh>& colliders = {});

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace surge
