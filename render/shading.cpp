#include "render/shading.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace surge {

namespace {

using Vec3 = Eigen::Vector3f;

constexpr float kFar = std::numeric_limits<float>::infinity();

// Water reflects 2 % of light at normal incidence (refractive index 1.33); Schlick's approximation after
// that.
float fresnelWater(float cosine) {
  const float m = 1.0f - std::clamp(cosine, 0.0f, 1.0f);
  return 0.02f + 0.98f * m * m * m * m * m;
}

Vec3 reflect(const Vec3& direction, const Vec3& normal) {
  return direction - 2.0f * direction.dot(normal) * normal;
}

// Two unit vectors orthogonal to n (Duff et al., "Building an orthonormal basis, revisited").
void orthonormalBasis(const Vec3& n, Vec3& a, Vec3& b) {
  const float sign = std::copysign(1.0f, n.z());
  const float p = -1.0f / (sign + n.z());
  const float q = n.x() * n.y() * p;
  a = Vec3(1.0f + sign * n.x() * n.x() * p, sign * q, -sign * n.x());
  b = Vec3(q, sign + n.y() * n.y() * p, -n.y());
}

// A direction towards a random point of the sun's disc, so shadow edges soften by the sun's size.
Vec3 sampleSun(const Shading& shading, SampleRandom& random) {
  Vec3 a, b;
  orthonormalBasis(shading.sunDirection, a, b);
  const float cosTheta = 1.0f - random.next() * (1.0f - shading.sunCosRadius);
  const float sinTheta = std::sqrt(std::max(0.0f, 1.0f - cosTheta * cosTheta));
  const float phi = 6.2831853f * random.next();
  return (cosTheta * shading.sunDirection + sinTheta * (std::cos(phi) * a + std::sin(phi) * b)).normalized();
}

// Direct sun and sky light reaching a point with the given normal (irradiance over pi, times the sun colour).
struct Light {
  Vec3 sunDirection;
  float sunVisible = 0;  // 1 if the sampled sun direction is unblocked
  Vec3 direct = Vec3::Zero();
  Vec3 ambient = Vec3::Zero();
};

Light lightAt(const RayScene& world, const Shading& shading, const Hit& hit, SampleRandom& random) {
  Light light;
  light.sunDirection = sampleSun(shading, random);
  const float cosine = hit.normal.dot(light.sunDirection);
  // No test against the geometric normal: the shadow ray from the lifted leave point decides, which keeps
  // the terminator of smooth-shaded water smooth instead of following the facets.
  if (cosine > 0 && !world.occluded(hit.leavePoint, light.sunDirection, kFar)) light.sunVisible = 1;
  light.direct = light.sunVisible * std::max(cosine, 0.0f) * shading.sunColor;
  // Sky light: full from the zenith on an upward face, about half on a wall, a little on an overhang.
  const Vec3 skyAverage = 0.5f * (shading.skyZenith + shading.skyHorizon);
  light.ambient = shading.skyAmbient * (0.6f + 0.4f * hit.normal.y()) * skyAverage;
  return light;
}

Vec3 groundAlbedo(const Shading& shading, const Hit& hit, float distance) {
  const Vec3& p = hit.point;
  const bool insideTank = p.x() >= shading.tankMin.x() && p.x() <= shading.tankMax.x() &&
                          p.z() >= shading.tankMin.z() && p.z() <= shading.tankMax.z();
  const long cx = std::lround(std::floor((p.x() - shading.tankMin.x()) / shading.checkerSize));
  const long cz = std::lround(std::floor((p.z() - shading.tankMin.z()) / shading.checkerSize));
  // The checker fades out with distance, where its squares would shrink below a pixel and shimmer.
  const float contrast = 0.05f * std::exp(-distance / (0.25f * shading.hazeDistance));
  const float checker = ((cx + cz) & 1) ? contrast : -contrast;
  const float base = insideTank ? 0.72f : 0.5f;
  return Vec3(base + checker, base + checker, base * 0.97f + checker);
}

Vec3 shadeDiffuse(const RayScene& world, const Shading& shading, const Hit& hit, const Vec3& albedo,
                  SampleRandom& random) {
  const Light light = lightAt(world, shading, hit, random);
  return albedo.cwiseProduct(light.direct + light.ambient);
}

Vec3 trace(const RayScene& world, const Shading& shading, const Ray& ray, SampleRandom& random, int depth);

// Water for now: a coloured body lit by sun and sky, a Fresnel-weighted mirror reflection and a sun
// highlight.
Vec3 shadeWater(const RayScene& world, const Shading& shading, const Ray& ray, const Hit& hit,
                SampleRandom& random, int depth) {
  const Vec3& n = hit.normal;
  const Light light = lightAt(world, shading, hit, random);
  const float fresnel = fresnelWater(-ray.direction.dot(n));

  // Smooth normals can send a reflection below the true surface: lift it just above the face instead.
  Vec3 mirror = reflect(ray.direction, n);
  const float below = mirror.dot(hit.geometricNormal);
  if (below < 0.01f) mirror = (mirror + (0.01f - below) * hit.geometricNormal).normalized();
  Vec3 reflected;
  if (depth < 1) {
    Ray bounce;
    bounce.origin = hit.leavePoint;
    bounce.direction = mirror;
    reflected = trace(world, shading, bounce, random, depth + 1);
  } else {
    reflected = skyRadiance(shading, mirror);
  }

  const Vec3 body = shading.waterColor.cwiseProduct(0.6f * light.direct + light.ambient);
  const Vec3 halfway = (light.sunDirection - ray.direction).normalized();
  const float highlight = light.sunVisible * std::pow(std::max(n.dot(halfway), 0.0f), 800.0f);
  return (1.0f - fresnel) * body + fresnel * reflected + 4.0f * highlight * shading.sunColor;
}

Vec3 trace(const RayScene& world, const Shading& shading, const Ray& ray, SampleRandom& random, int depth) {
  Hit hit;
  if (!world.intersect(ray, kFar, hit)) return skyRadiance(shading, ray.direction);
  switch (hit.kind) {
    case SurfaceKind::Water:
      return shadeWater(world, shading, ray, hit, random, depth);
    case SurfaceKind::TankEdge:
      return shadeDiffuse(world, shading, hit, Vec3(0.05f, 0.05f, 0.055f), random);
    case SurfaceKind::Ground:
      break;
  }
  const Vec3 lit = shadeDiffuse(world, shading, hit, groundAlbedo(shading, hit, hit.distance), random);
  const float haze = 1.0f - std::exp(-hit.distance / shading.hazeDistance);
  return (1.0f - haze) * lit + haze * shading.skyHorizon;
}

}  // namespace

Shading Shading::fromScene(const Scene& scene) {
  Shading s;
  s.sunDirection = Vec3(-0.4f, 0.85f, -0.25f).normalized();  // high, from the back left: highlights on waves
  s.sunColor = Vec3(1.0f, 0.95f, 0.87f);
  s.sunCosRadius = std::cos(0.02f);  // about twice the real sun, for visibly soft shadow edges
  s.skyZenith = Vec3(0.32f, 0.5f, 0.82f);
  s.skyHorizon = Vec3(0.78f, 0.84f, 0.9f);
  s.belowHorizon = Vec3(0.42f, 0.42f, 0.44f);
  s.skyAmbient = 0.5f;
  s.waterColor = scene.render.water_color.cast<float>();
  s.tankMin = scene.domain.min.cast<float>();
  s.tankMax = scene.domain.max.cast<float>();
  const float size = std::max((s.tankMax - s.tankMin).maxCoeff(), 1e-3f);
  s.checkerSize = size / 8.0f;
  s.hazeDistance = 12.0f * size;
  return s;
}

Vec3 skyRadiance(const Shading& shading, const Vec3& direction) {
  const float up = direction.y();
  if (up < 0) {
    const float t = std::min(-up * 4.0f, 1.0f);
    return (1.0f - t) * shading.skyHorizon + t * shading.belowHorizon;
  }
  const float t = std::pow(up, 0.6f);
  const Vec3 gradient = (1.0f - t) * shading.skyHorizon + t * shading.skyZenith;
  const float glow = std::pow(std::max(direction.dot(shading.sunDirection), 0.0f), 64.0f);
  return gradient + 0.25f * glow * shading.sunColor;
}

Vec3 traceRadiance(const RayScene& world, const Shading& shading, const Ray& ray, SampleRandom& random) {
  return trace(world, shading, ray, random, 0);
}

}  // namespace surge
