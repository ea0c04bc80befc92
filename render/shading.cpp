#include "render/shading.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/errors.h"

namespace surge {

namespace {

using Vec3 = Eigen::Vector3f;

constexpr float kFar = std::numeric_limits<float>::infinity();
constexpr float kPi = 3.14159265f;
// Russian roulette starts after this many segments: the first bounces carry most of the image and are never
// cut.
constexpr int kRouletteAfter = 3;
// The first passes of a path through or off a glass wall do not count as segments (for max_depth and the
// roulette): a view through the tank crosses two walls, which would otherwise start the roulette at the first
// diffuse bounce behind them and scatter its noise over the whole tank. Beyond these, a pass counts, so paths
// caught between the walls still end.
constexpr int kFreeGlassPasses = 8;
// Shadow rays cross at most this many water surfaces (a splash seen edge-on); beyond, the sun counts as
// blocked.
constexpr int kMaxShadowCrossings = 16;
// A single sample is clamped to this radiance (about 30 times white paper). Only specular chains that find
// the sun's disc (radiance ~2000) after a refraction or two reach it; unclamped, one such sample among 16
// paints an isolated white pixel ("firefly"). The clamp biases those glints a little dark and leaves
// everything else, including the white furnace (radiance 1), untouched.
constexpr float kSampleClamp = 32.0f;
// The denoiser's guide chain meets at most this many surfaces (glass walls, water) before it gives up on
// finding a diffuse one.
constexpr int kFeatureChain = 8;

Vec3 reflect(const Vec3& direction, const Vec3& normal) {
  return direction - 2.0f * direction.dot(normal) * normal;
}

// Unpolarised Fresnel reflectance of a smooth dielectric for light arriving at cosine cosI (> 0) with
// eta = n_incident / n_transmitted; cosT receives the cosine of the refracted ray. Returns 1 for total
// internal reflection (PBRT 3rd ed., eq. 8.4-8.5).
float fresnelDielectric(float cosI, float eta, float& cosT) {
  const float sin2T = eta * eta * std::max(0.0f, 1.0f - cosI * cosI);
  if (sin2T >= 1.0f) {
    cosT = 0;
    return 1.0f;
  }
  cosT = std::sqrt(1.0f - sin2T);
  const float rs = (eta * cosI - cosT) / (eta * cosI + cosT);
  const float rp = (eta * cosT - cosI) / (eta * cosT + cosI);
  return 0.5f * (rs * rs + rp * rp);
}

// The reflectance of a thin slab of index `ior` in air for light at cosine cosI (> 0): each polarisation's
// single-surface reflectance R becomes R + (1 - R)^2 R (1 + R^2 + R^4 + ...) = 2R / (1 + R) once the light
// bouncing inside the slab is summed (incoherently, the pane being far thicker than a wavelength), and the
// slab is symmetric: the same from either side. PBRT 3rd ed. eq. 8.4-8.5 for R.
float slabReflectance(float cosI, float ior) {
  const float eta = 1.0f / ior;
  const float sin2T = eta * eta * std::max(0.0f, 1.0f - cosI * cosI);
  const float cosT = std::sqrt(std::max(0.0f, 1.0f - sin2T));  // never total reflection entering glass
  const float rs = (eta * cosI - cosT) / (eta * cosI + cosT);
  const float rp = (eta * cosT - cosI) / (eta * cosT + cosI);
  const float reflectS = rs * rs, reflectP = rp * rp;
  return 0.5f * (2.0f * reflectS / (1.0f + reflectS) + 2.0f * reflectP / (1.0f + reflectP));
}

// Two unit vectors orthogonal to n (Duff et al., "Building an orthonormal basis, revisited", 2017).
void orthonormalBasis(const Vec3& n, Vec3& a, Vec3& b) {
  const float sign = std::copysign(1.0f, n.z());
  const float p = -1.0f / (sign + n.z());
  const float q = n.x() * n.y() * p;
  a = Vec3(1.0f + sign * n.x() * n.x() * p, sign * q, -sign * n.x());
  b = Vec3(q, sign + n.y() * n.y() * p, -n.y());
}

// A cosine-distributed direction around n (Malley's method): pdf cos / pi, so a Lambertian bounce weighs
// exactly its albedo.
Vec3 sampleCosine(const Vec3& n, SampleRandom& random) {
  float u = 0, v = 0;
  random.next2(u, v);
  const float r = std::sqrt(u), phi = 2.0f * kPi * v;
  Vec3 a, b;
  orthonormalBasis(n, a, b);
  const float x = r * std::cos(phi), y = r * std::sin(phi);
  return (x * a + y * b + std::sqrt(std::max(0.0f, 1.0f - x * x - y * y)) * n).normalized();
}

// A direction uniformly distributed over the sun's disc (a cone of the sun's angular radius).
Vec3 sampleSun(const Shading& shading, SampleRandom& random) {
  Vec3 a, b;
  orthonormalBasis(shading.sunDirection, a, b);
  float u = 0, v = 0;
  random.next2(u, v);
  const float cosTheta = 1.0f - u * (1.0f - shading.sunCosRadius);
  const float sinTheta = std::sqrt(std::max(0.0f, 1.0f - cosTheta * cosTheta));
  const float phi = 2.0f * kPi * v;
  return (cosTheta * shading.sunDirection + sinTheta * (std::cos(phi) * a + std::sin(phi) * b)).normalized();
}

// Which liquids a path is in: bit f set inside fluid f's surface (Hit::fluid). A scene of one fluid has 0 (air)
// and 1 (water); where two liquids' surfaces overlap at their interface, two bits.
using Media = uint32_t;
Media mediaBit(const Hit& hit) { return 1u << std::min<unsigned>(hit.fluid, 31u); }

Vec3 absorb(const Shading& shading, Media media, float distance) {
  if (media == 1) return (-distance * shading.waterAbsorption).array().exp().matrix();
  Vec3 sigma = Vec3::Zero();
  for (size_t f = 0; f < shading.fluidAbsorption.size() && f < 32; ++f)
    if (media & (1u << f)) sigma += shading.fluidAbsorption[f];
  return (-distance * sigma).array().exp().matrix();
}

// How much sunlight arrives along a straight shadow ray: 0 if the ground or a collider blocks it, else the
// product of the Fresnel transmissions and the absorption of the water and the glass walls it crosses.
Vec3 sunTransmittance(const RayScene& world, const Shading& shading, const Vec3& origin,
                      const Vec3& direction, Media media, PathStats& stats) {
  Vec3 transmittance = Vec3::Ones();
  Ray ray;
  ray.origin = origin;
  ray.direction = direction;
  for (int crossing = 0; crossing < kMaxShadowCrossings; ++crossing) {
    Hit hit;
    ++stats.rays;
    if (!world.intersect(ray, kFar, hit, true)) return transmittance;
    if (media) transmittance = transmittance.cwiseProduct(absorb(shading, media, hit.distance));
    if (hit.kind == SurfaceKind::TankGlass) {
      transmittance *= 1.0f - slabReflectance(std::abs(direction.dot(hit.geometricNormal)), shading.glassIor);
      ray.origin = hit.passPoint;
      continue;
    }
    if (hit.kind != SurfaceKind::Water) return Vec3::Zero();
    const Media after = media ^ mediaBit(hit);
    if (!media || !after) {  // liquid and air meet; between two liquids (of one index) the light passes
      float cosT = 0;
      const float cosI = std::abs(direction.dot(hit.geometricNormal));
      transmittance *= 1.0f - fresnelDielectric(cosI, media ? shading.ior : 1.0f / shading.ior, cosT);
    }
    media = after;
    ray.origin = hit.passPoint;
  }
  return Vec3::Zero();
}

// The specular event at a water surface: the Fresnel reflectance and both directions (refracted is unset
// under total internal reflection, fresnel = 1). False if, with a smooth shading normal, either direction
// lies on the wrong side of the true face; the caller then uses the geometric normal.
bool waterEvent(const Shading& shading, const Vec3& normal, const Hit& hit, bool inside, const Vec3& d,
                float& fresnel, Vec3& reflected, Vec3& refracted) {
  const float cosI = -d.dot(normal);
  if (cosI <= 0) return false;
  const float eta = inside ? shading.ior : 1.0f / shading.ior;
  float cosT = 0;
  fresnel = fresnelDielectric(cosI, eta, cosT);
  reflected = reflect(d, normal);
  if (reflected.dot(hit.geometricNormal) <= 0) return false;
  if (fresnel < 1.0f) {
    refracted = (eta * d + (eta * cosI - cosT) * normal).normalized();  // Snell's law, PBRT eq. 8.8
    if (refracted.dot(hit.geometricNormal) >= 0) return false;
  }
  return true;
}

// waterEvent at a hit with its smooth normal, or with the face's where the smooth normal disagrees with the
// face (a ray grazing a coarse mesh); false if neither gives a consistent event.
bool waterEventAt(const Shading& shading, const Hit& hit, bool inside, const Vec3& d, float& fresnel,
                  Vec3& reflected, Vec3& refracted) {
  if (waterEvent(shading, hit.normal, hit, inside, d, fresnel, reflected, refracted)) return true;
  return waterEvent(shading, hit.geometricNormal, hit, inside, d, fresnel, reflected, refracted);
}

Vec3 sunDisc(const Shading& shading, const Vec3& direction) {
  if (direction.dot(shading.sunDirection) < shading.sunCosRadius) return Vec3::Zero();
  // Radiance that gives irradiance pi * sunColor over the disc's solid angle 2 pi (1 - cos r).
  return shading.sunColor / (2.0f * (1.0f - shading.sunCosRadius));
}

}  // namespace

// Beer-Lambert: exp(-sigma d) = colour at d = absorption_distance, so sigma = -ln(colour) / d.
Eigen::Vector3f Shading::absorptionOf(const Eigen::Vector3d& color, double distance) {
  Eigen::Vector3f sigma;
  for (int k = 0; k < 3; ++k) sigma[k] = float(-std::log(std::clamp(color[k], 1e-3, 1.0)) / std::max(distance, 1e-6));
  return sigma;
}

Shading Shading::fromScene(const Scene& scene) {
  const RenderSettings& r = scene.render;
  Shading s;
  if (r.sun_direction.norm() < 1e-9) throw InputError(scene.name, "render.sun_direction", "must not be zero");
  s.sunDirection = r.sun_direction.cast<float>().normalized();
  s.sunColor = r.sun_color.cast<float>();
  s.sunCosRadius = float(std::cos(r.sun_radius * M_PI / 180.0));
  s.skyZenith = r.sky_zenith.cast<float>();
  s.skyHorizon = r.sky_horizon.cast<float>();
  s.belowHorizon = 0.5f * s.skyHorizon;
  // The first fluid's colour (render.water_color unless it gives its own), or water's in a scene fed only by
  // emitters.
  s.waterAbsorption = scene.fluids.empty() ? absorptionOf(r.water_color, r.absorption_distance)
                                           : absorptionOf(scene.fluidColor(0), scene.fluidAbsorptionDistance(0));
  if (scene.severalFluids()) {  // in the order of the meshes: the first fluid's, then Scene::laterFluids
    s.fluidAbsorption.push_back(s.waterAbsorption);
    for (size_t b : scene.laterFluids())
      s.fluidAbsorption.push_back(absorptionOf(scene.fluidColor(b), scene.fluidAbsorptionDistance(b)));
  }
  s.tankMin = scene.domain.min.cast<float>();
  s.tankMax = scene.domain.max.cast<float>();
  const float size = std::max((s.tankMax - s.tankMin).maxCoeff(), 1e-3f);
  s.checkerSize = size / 8.0f;
  s.hazeDistance = 12.0f * size;
  s.maxDepth = r.max_depth;
  s.exposure = float(r.exposure);
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
  return gradient + shading.sunGlow * glow * shading.sunColor;
}

Vec3 groundAlbedoAt(const Shading& shading, const Vec3& p, float distance) {
  const bool insideTank = p.x() >= shading.tankMin.x() && p.x() <= shading.tankMax.x() &&
                          p.z() >= shading.tankMin.z() && p.z() <= shading.tankMax.z();
  const long cx = std::lround(std::floor((p.x() - shading.tankMin.x()) / shading.checkerSize));
  const long cz = std::lround(std::floor((p.z() - shading.tankMin.z()) / shading.checkerSize));
  // The checker fades out with distance, where its squares would shrink below a pixel and shimmer.
  const float contrast = shading.checkerContrast * std::exp(-distance / (0.25f * shading.hazeDistance));
  const float checker = ((cx + cz) & 1) ? contrast : -contrast;
  const float base = insideTank ? shading.floorAlbedo : shading.groundAlbedo;
  return Vec3(base + checker, base + checker, 0.97f * base + checker);
}

namespace {

// The albedo of a diffuse hit (the ground's checkerboard at the distance travelled to it, a collider's or a
// whitewater particle's colour, the tank's edges).
Vec3 diffuseAlbedo(const Shading& shading, const Hit& hit, float travelled) {
  return hit.kind == SurfaceKind::Ground     ? groundAlbedoAt(shading, hit.point, travelled)
         : hit.kind == SurfaceKind::Collider || hit.kind == SurfaceKind::Whitewater ? hit.albedo
                                             : Vec3::Constant(shading.tankAlbedo);
}

// Where a path is: its next ray, whether it is in water, whether it has been specular so far (then the sun's
// disc is seen, not sampled), how far the camera ray and its specular continuations went (checker fade), its
// segment count, its throughput, and whether it may still split at water or at how many glass walls (see
// gather).
struct PathState {
  Ray ray;
  Media media = 0;  // the camera is assumed to be in air
  bool specular = true;
  float travelled = 0;
  int depth = 0;
  Vec3 throughput = Vec3::Ones();
  bool splitWater = true;
  int glassSplits = 2;
  int glassPasses = 0;
  bool onChain = false;  // the denoiser's guide chain goes the same way (GuideChain)
};

// The denoiser's guides (SampleFeatures) come from a chain of rays that passes glass walls straight, refracts at
// water (reflects under total internal reflection) and stops at the first diffuse surface. The chain rides
// along the path while the path goes its way (it does through the camera's first splits, which follow both
// ways), using the path's own hits, and is traced on its own (continueChain) only from where they part.
struct GuideChain {
  SampleFeatures* features = nullptr;
  bool firstSeen = false, done = false;
  int events = 0;  // surfaces met

  // Records a surface the chain met after `travelled` along it; returns false when the chain ends here.
  bool meet(const Shading& shading, const Hit& hit, float travelled) {
    if (++events > kFeatureChain) return finish();
    if (hit.kind == SurfaceKind::TankGlass) return true;
    if (!firstSeen) {
      features->normal = hit.normal;
      features->point = hit.point;
      features->depth = travelled;
      firstSeen = true;
    }
    if (hit.kind == SurfaceKind::Water) return true;
    features->albedo = diffuseAlbedo(shading, hit, travelled);
    return finish();
  }
  bool finish() {
    done = true;
    return false;
  }
};

// The chain on its own from `ray` on (in the liquids `media`, `travelled` so far).
void continueChain(const RayScene& world, const Shading& shading, Ray ray, Media media, float travelled,
                   GuideChain& chain, PathStats& stats) {
  while (!chain.done) {
    Hit hit;
    ++stats.rays;
    if (!world.intersect(ray, kFar, hit)) {
      chain.finish();
      return;
    }
    travelled += hit.distance;
    if (!chain.meet(shading, hit, travelled)) return;
    if (hit.kind == SurfaceKind::TankGlass) {
      ray.origin = hit.passPoint;
      continue;
    }
    const Media after = media ^ mediaBit(hit);
    if (media && after) {  // from one liquid into another: straight on
      ray.origin = hit.passPoint;
      media = after;
      continue;
    }
    float fresnel = 1;
    Vec3 reflected, refracted;
    if (!waterEventAt(shading, hit, media != 0, ray.direction, fresnel, reflected, refracted)) {
      chain.finish();
      return;
    }
    if (fresnel < 1.0f) {
      ray.origin = hit.passPoint;
      ray.direction = refracted;
      media = after;
    } else {
      ray.origin = hit.leavePoint;
      ray.direction = reflected;
    }
  }
}

// The light a path gathers from its state on. On the camera's direct view, the first water surface met sends
// both a reflected and a refracted path, weighted F and 1 - F, instead of choosing one: the water then shows
// its reflection without the speckle of a random choice at 2-10 % odds. The first two glass walls along the
// view split the same way (most of the image is seen through the front and the back pane), and the water
// behind them still splits once. Later surfaces choose at random (with the Fresnel probability, which keeps
// the estimate unbiased).
Vec3 gather(const RayScene& world, const Shading& shading, PathState path, SampleRandom& random,
            PathStats& stats, Vec3* reflection = nullptr, GuideChain* chain = nullptr) {
  Vec3 radiance = Vec3::Zero();
  Vec3& throughput = path.throughput;
  Ray& ray = path.ray;
  // Where the path leaves the chain's way, the chain goes on alone along `next`.
  const auto partFromChain = [&](const Ray& next, Media media) {
    if (!path.onChain) return;
    path.onChain = false;
    continueChain(world, shading, next, media, path.travelled, *chain, stats);
  };
  for (; path.depth < shading.maxDepth; ++path.depth) {
    Hit hit;
    ++stats.rays;
    if (!world.intersect(ray, kFar, hit)) {
      radiance += throughput.cwiseProduct(skyRadiance(shading, ray.direction) +
                                          (path.specular ? sunDisc(shading, ray.direction) : Vec3::Zero()));
      if (path.onChain) chain->finish();
      return radiance;
    }
    if (path.media) throughput = throughput.cwiseProduct(absorb(shading, path.media, hit.distance));
    if (path.specular) path.travelled += hit.distance;
    if (path.onChain && !chain->meet(shading, hit, path.travelled)) path.onChain = false;
    if (path.specular && hit.kind == SurfaceKind::Ground) {
      // Haze over the ground seen from the camera, growing with the square of the distance: nothing on the
      // tank, the horizon colour far away, so the ground plane's edge melts into the sky.
      const float r = path.travelled / shading.hazeDistance, haze = 1.0f - std::exp(-r * r);
      radiance += haze * throughput.cwiseProduct(shading.skyHorizon);
      throughput *= 1.0f - haze;
    }

    if (hit.kind == SurfaceKind::Water) {
      const Media after = path.media ^ mediaBit(hit);
      if (path.media && after) {  // from one liquid into another (of one index): straight on, not a segment
        ray.origin = hit.passPoint;
        path.media = after;
        --path.depth;
        continue;
      }
      float fresnel = 1;
      Vec3 reflected, refracted;
      if (!waterEventAt(shading, hit, path.media != 0, ray.direction, fresnel, reflected, refracted)) {
        if (path.onChain) chain->finish();
        return radiance;
      }
      if (path.splitWater && fresnel < 1.0f) {
        PathState mirror = path, through = path;
        mirror.splitWater = through.splitWater = false;
        mirror.glassSplits = through.glassSplits = 0;
        ++mirror.depth;
        ++through.depth;
        mirror.ray.origin = hit.leavePoint;
        mirror.ray.direction = reflected;
        mirror.throughput *= fresnel;
        through.ray.origin = hit.passPoint;
        through.ray.direction = refracted;
        through.media = after;
        through.throughput *= 1.0f - fresnel;
        mirror.onChain = false;  // the chain refracts
        const Vec3 mirrored = gather(world, shading, mirror, random, stats);
        if (reflection) *reflection += mirrored;
        return radiance + mirrored + gather(world, shading, through, random, stats, nullptr, chain);
      }
      if (fresnel >= 1.0f || random.next() < fresnel) {
        if (fresnel < 1.0f) partFromChain(Ray{hit.passPoint, refracted}, after);
        ray.origin = hit.leavePoint;
        ray.direction = reflected;
      } else {
        ray.origin = hit.passPoint;
        ray.direction = refracted;
        path.media = after;
      }
    } else if (hit.kind == SurfaceKind::TankGlass) {
      const float reflectance = slabReflectance(-ray.direction.dot(hit.geometricNormal), shading.glassIor);
      const Vec3 reflected = reflect(ray.direction, hit.geometricNormal);
      const bool freePass = path.glassPasses++ < kFreeGlassPasses;
      if (path.glassSplits > 0) {
        PathState mirror = path, through = path;
        mirror.glassSplits = 0;  // the reflection mostly goes to the sky
        through.glassSplits = path.glassSplits - 1;
        if (!freePass) {
          ++mirror.depth;
          ++through.depth;
        }
        mirror.ray.origin = hit.leavePoint;
        mirror.ray.direction = reflected;
        mirror.throughput *= reflectance;
        through.ray.origin = hit.passPoint;  // straight on: the pane is too thin to shift the ray
        through.throughput *= 1.0f - reflectance;
        mirror.onChain = false;  // the chain passes
        return radiance + gather(world, shading, mirror, random, stats, reflection) +
               gather(world, shading, through, random, stats, reflection, chain);
      }
      if (random.next() < reflectance) {
        partFromChain(Ray{hit.passPoint, ray.direction}, path.media);
        ray.origin = hit.leavePoint;
        ray.direction = reflected;
      } else {
        ray.origin = hit.passPoint;
      }
      if (freePass) {
        --path.depth;  // undone by the loop's increment: the pass is not a segment
        continue;
      }
    } else {
      const Vec3 albedo = diffuseAlbedo(shading, hit, path.travelled);
      // Next-event estimation of the sun: (albedo / pi) L_sun cos / pdf, with pdf = 1 / solid angle of the
      // disc, which is albedo * sunColor * cos.
      const Vec3 toSun = sampleSun(shading, random);
      const float cosine = hit.normal.dot(toSun);
      if (cosine > 0) {
        const Vec3 sun = sunTransmittance(world, shading, hit.leavePoint, toSun, path.media, stats);
        radiance += cosine * throughput.cwiseProduct(albedo).cwiseProduct(sun).cwiseProduct(shading.sunColor);
      }
      if (hit.kind == SurfaceKind::Whitewater && !path.media) {
        // One bounce for spray and foam in air: the sky along the normal stands for the rest of the path (paths
        // followed on among the white spheres cost the demo 28% more render time). Bubbles, under water, go on
        // as any diffuse surface does, lit through the water around them.
        radiance += throughput.cwiseProduct(albedo).cwiseProduct(skyRadiance(shading, hit.normal));
        ray.origin = hit.leavePoint;
        ray.direction = hit.normal;
        break;
      }
      throughput = throughput.cwiseProduct(albedo);
      ray.origin = hit.leavePoint;
      ray.direction = sampleCosine(hit.normal, random);
      path.specular = false;
      path.splitWater = false;  // only the camera's direct view splits
      path.glassSplits = 0;
    }

    if (path.depth + 1 >= kRouletteAfter) {
      const float survive = std::min(throughput.maxCoeff(), 0.95f);
      if (survive <= 0 || random.next() >= survive) break;
      throughput /= survive;
    }
  }
  partFromChain(ray, path.media);  // the path stopped (roulette, depth) where the chain had not
  return radiance;
}

}  // namespace

Vec3 traceRadiance(const RayScene& world, const Shading& shading, const Ray& cameraRay, SampleRandom& random,
                   PathStats* stats, SampleFeatures* features) {
  PathStats local;
  PathState path;
  path.ray = cameraRay;
  Vec3 reflection = Vec3::Zero();
  GuideChain chain;
  if (features) {
    *features = SampleFeatures{};
    chain.features = features;
    path.onChain = true;
  }
  const Vec3 radiance = gather(world, shading, path, random, local, features ? &reflection : nullptr,
                               features ? &chain : nullptr);
  if (features) features->reflection = reflection;
  if (stats) stats->rays += local.rays;
  const float peak = radiance.maxCoeff();
  if (!(peak > kSampleClamp)) return radiance;
  if (features) features->reflection *= kSampleClamp / peak;
  return radiance * (kSampleClamp / peak);
}

float toneMap(float linear, float exposure) {
  const float x = std::max(0.0f, linear * exposure);
  return std::clamp((x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f), 0.0f, 1.0f);
}

std::vector<std::array<Eigen::Vector3f, 2>> tankEdges(const Scene& scene) {
  const Eigen::Vector3f lo = scene.domain.min.cast<float>(), hi = scene.domain.max.cast<float>();
  std::vector<std::array<Eigen::Vector3f, 2>> edges;
  if (scene.dimensions == 2) {
    const Eigen::Vector3f a(lo.x(), hi.y(), 0), b(lo.x(), lo.y(), 0), c(hi.x(), lo.y(), 0), d(hi.x(), hi.y(), 0);
    if (scene.hasWall(0, false)) edges.push_back({a, b});
    if (scene.hasWall(1, false)) edges.push_back({b, c});
    if (scene.hasWall(0, true)) edges.push_back({c, d});
    return edges;
  }
  for (int axis = 0; axis < 3; ++axis) {
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    for (int corner = 0; corner < 4; ++corner) {
      // The edge along `axis` lies on face a (upper when corner & 1) and face b (upper when corner & 2).
      if (!scene.hasWall(a, corner & 1) || !scene.hasWall(b, corner & 2)) continue;
      Eigen::Vector3f p0 = lo, p1 = hi;
      p0[a] = p1[a] = (corner & 1) ? hi[a] : lo[a];
      p0[b] = p1[b] = (corner & 2) ? hi[b] : lo[b];
      edges.push_back({p0, p1});
    }
  }
  return edges;
}

}  // namespace surge
