// How a Surge render looks: the sky, the sun, and the materials of water, ground and tank, and the path
// tracer that carries light between them. traceRadiance() is the one function that answers "what light comes
// back along this camera ray"; the renderer only averages it over samples and tone-maps the result.
//
// The light transport, in short (Pharr, Jakob & Humphreys, "Physically Based Rendering", 3rd ed., ch. 14):
// - water is a smooth dielectric of index 1.333: at each hit the path reflects with the exact Fresnel
//   probability F and refracts otherwise (total internal reflection when Snell has no solution), so the
//   choice itself carries the Fresnel weight and no energy is created or lost at the interface;
// - inside the water the throughput falls as exp(-sigma d) (Beer-Lambert), sigma per colour channel;
// - the ground, the tank's edges and the colliders are Lambertian: the sun is sampled explicitly on its disc
//   (soft shadows) and the path continues in a cosine-distributed direction; the sky is reached by that
//   continuation;
// - a glass tank's walls are slabs of clear glass too thin to shift a ray: the path reflects with the slab's
//   reflectance 2R / (1 + R) (R the single-surface Fresnel reflectance, per polarisation; the light bouncing
//   inside the pane summed incoherently) and goes straight on otherwise;
// - shadow rays pass through water, weighted by its Fresnel transmission and absorption, so the tank floor
//   under water is lit as the average of the caustics it would show (a path tracer cannot find a point sun
//   through a refracting surface); glass walls pass the sun with the slab's transmittance;
// - after three segments Russian roulette stops a path with probability 1 - min(max throughput, 0.95) and
//   reweights the survivors, so the estimate stays unbiased up to max_depth.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "core/scene.h"
#include "render/random.h"
#include "render/tracer.h"

namespace surge {

struct Shading {
  Eigen::Vector3f sunDirection;  // unit, towards the sun
  Eigen::Vector3f sunColor;      // irradiance on a surface facing the sun, over pi (radiance of white paper)
  float sunCosRadius = 0;        // cosine of the sun's angular radius
  Eigen::Vector3f skyZenith, skyHorizon, belowHorizon;
  float sunGlow = 0.25f;  // the sky's brightening around the sun, as a fraction of sunColor
  // Water: index of refraction and Beer-Lambert absorption per metre.
  float ior = 1.333f;
  Eigen::Vector3f waterAbsorption = Eigen::Vector3f::Zero();
  // A scene of several fluids: each fluid's absorption by Hit::fluid (the first is waterAbsorption); empty in a
  // scene of one. Two liquids meet without refraction (one index).
  std::vector<Eigen::Vector3f> fluidAbsorption;
  // Beer-Lambert's coefficients of a liquid that turns white light `color` over `distance` (render.water_color
  // over render.absorption_distance; a fluid's fluids[i].color).
  static Eigen::Vector3f absorptionOf(const Eigen::Vector3d& color, double distance);
  // The ground: a checkerboard of `checkerSize` squares aligned to the tank, of albedo floorAlbedo inside the
  // tank's footprint and groundAlbedo outside, each square +-checkerContrast; distance haze towards the
  // horizon colour.
  float checkerSize = 1;
  float floorAlbedo = 0.62f, groundAlbedo = 0.42f, checkerContrast = 0.12f;
  Eigen::Vector3f tankMin, tankMax;
  float hazeDistance = 100;
  float tankAlbedo = 0.04f;
  float glassIor = 1.5f;  // the tank's walls when render.tank is "glass"
  int maxDepth = 8;
  float exposure = 1;

  // Throws InputError(scene.name, "render.sun_direction", ...) for a zero sun direction.
  static Shading fromScene(const Scene& scene);
};

// The sky seen in a unit direction: a gradient from the horizon to the zenith with a glow around the sun,
// without the sun's disc (which the tracer adds where a specular path sees it).
Eigen::Vector3f skyRadiance(const Shading& shading, const Eigen::Vector3f& direction);

// The albedo of the ground at a point (checkerboard, tank floor), fading the checker with distance.
Eigen::Vector3f groundAlbedoAt(const Shading& shading, const Eigen::Vector3f& point, float distance);

// What a path costs: rays cast (path segments plus shadow rays), for the benchmark's rays per second.
struct PathStats {
  uint64_t rays = 0;
};

// What a camera ray sees besides its light, for the denoiser (render/denoiser.h), along a chain of its own
// that passes glass walls, refracts at water (reflects under total internal reflection) and stops at the first
// diffuse surface: the first surface other than glass (its shading normal, facing the camera, the point and its
// distance along the chain; all zero for the sky) and that diffuse surface's albedo (1 if the chain reaches none). The
// chain draws no random numbers: the light is the same with or without it. Also the part of the light that
// the camera's first water surface reflects (the mirror half of its split, gather in shading.cpp): nearly free
// of noise, full of the surface's detail, and left out of the filter.
struct SampleFeatures {
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();
  Eigen::Vector3f point = Eigen::Vector3f::Zero();  // where the chain met that first surface
  float depth = 0;
  Eigen::Vector3f albedo = Eigen::Vector3f::Ones();
  Eigen::Vector3f reflection = Eigen::Vector3f::Zero();
};

// Linear RGB light arriving along a camera ray: one path-traced sample.
Eigen::Vector3f traceRadiance(const RayScene& world, const Shading& shading, const Ray& ray,
                              SampleRandom& random, PathStats* stats = nullptr,
                              SampleFeatures* features = nullptr);

// Linear light to display: exposure, then the ACES filmic curve fitted by Narkowicz (2015), in [0, 1].
float toneMap(float linear, float exposure);

// The tank's edges to draw, as segments: in 3D its twelve edges less those of an open face (domain.open), in 2D
// its floor and side walls (z = 0) less the open ones.
std::vector<std::array<Eigen::Vector3f, 2>> tankEdges(const Scene& scene);

}  // namespace surge
