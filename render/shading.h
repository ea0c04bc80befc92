// How a Surge render looks: the sky, the sun, and the materials of water, ground and tank. traceRadiance() is
// the one function that answers "what light comes back along this camera ray"; the renderer only averages it
// over samples, so a path tracer can replace it without touching cameras, tiles or files.
#pragma once

#include <Eigen/Core>

#include "core/scene.h"
#include "render/random.h"
#include "render/tracer.h"

namespace surge {

struct Shading {
  Eigen::Vector3f sunDirection;  // unit, towards the sun
  Eigen::Vector3f sunColor;      // radiance scale of direct sun light on a surface facing it
  float sunCosRadius = 0;        // cosine of the sun's angular radius (soft shadows)
  Eigen::Vector3f skyZenith, skyHorizon, belowHorizon;
  float skyAmbient = 0;  // sky light on an upward-facing surface, as a fraction of the sky's colour
  Eigen::Vector3f waterColor;
  // The ground: a subtle checkerboard of `checkerSize` squares aligned to the tank, a lighter tank floor
  // inside the tank's footprint, and distance haze towards the horizon colour.
  float checkerSize = 1;
  Eigen::Vector3f tankMin, tankMax;
  float hazeDistance = 100;

  static Shading fromScene(const Scene& scene);
};

// The sky seen in a unit direction: a gradient from the horizon to the zenith with a glow around the sun.
Eigen::Vector3f skyRadiance(const Shading& shading, const Eigen::Vector3f& direction);

// Linear RGB light arriving along `ray` (camera rays and the reflections they spawn).
Eigen::Vector3f traceRadiance(const RayScene& world, const Shading& shading, const Ray& ray,
                              SampleRandom& random);

}  // namespace surge
