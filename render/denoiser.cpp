#include "render/denoiser.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "core/parallel.h"

namespace surge {

namespace {

using Vec3 = Eigen::Vector3f;

// The B-spline kernel's 3 taps (1, 2, 1) / 4 a side.
constexpr float kTaps[3] = {0.25f, 0.5f, 0.25f};
// Below this albedo the light is not divided out (a black surface has no light to recover).
constexpr float kLeastAlbedo = 0.02f;
constexpr size_t kRowsPerTask = 8;

// exp(-x) for x >= 0, to about 0.2% (a tap's weight need not be exact, only the same every run): 0 beyond 16,
// else 2^(-x / ln 2) with the fraction's power from a cubic.
float negativeExp(float x) {
  if (!(x < 16.0f)) return 0.0f;
  const float t = x * 1.44269504f;  // x / ln 2
  const int whole = static_cast<int>(t);
  const float f = t - float(whole);
  const float fraction = 1.0f + f * (-0.69314718f + f * (0.23979f + f * -0.04665f));  // 2^-f
  const uint32_t bits = uint32_t(127 - whole) << 23;  // 2^-whole, whole < 24
  float scale;
  std::memcpy(&scale, &bits, sizeof scale);
  return fraction * scale;
}

// c^(2^k), by squaring.
float powerOfTwoPower(float c, int k) {
  for (int i = 0; i < k; ++i) c *= c;
  return c;
}

// What a tap compares, packed: the guides, and the light with its variance (and its luminance).
struct alignas(32) Guide {
  Vec3 normal;
  float depth;
  Vec3 albedo;
};
struct alignas(32) Light {
  Vec3 rgb;
  float variance;
  float luminance;
};

}  // namespace

struct Denoiser::Buffers {
  std::vector<Guide> guides;
  std::vector<Light> light, next;
  std::vector<float> blurred;
  std::vector<Vec3> result;
};

Denoiser::Denoiser(const DenoiseSettings& settings) : settings_(settings), buffers_(std::make_unique<Buffers>()) {}
Denoiser::~Denoiser() = default;

const std::vector<Vec3>& Denoiser::filter(const std::vector<PixelFeatures>& pixels, int width, int height) {
  const DenoiseSettings& settings = settings_;
  const size_t count = size_t(width) * size_t(height);
  // Every element is written before it is read: resized, not cleared.
  std::vector<Guide>& guides = buffers_->guides;
  std::vector<Light>&light = buffers_->light, &next = buffers_->next;
  std::vector<float>& blurred = buffers_->blurred;
  std::vector<Vec3>& result = buffers_->result;
  guides.resize(count);
  light.resize(count);
  next.resize(count);
  blurred.resize(count);
  result.resize(count);
  const auto rows = [&](const auto& perPixel) {
    parallelFor(
        0, size_t(height),
        [&](size_t y0, size_t y1) {
          for (size_t y = y0; y < y1; ++y)
            for (int x = 0; x < width; ++x) perPixel(x, int(y), y * size_t(width) + size_t(x));
        },
        kRowsPerTask);
  };
  // The variance of each pixel's mean luminance: from its samples, or of one sample from its neighbours'.
  // Then demodulate: the light is the colour over the albedo, its variance scaled likewise.
  rows([&](int x, int y, size_t p) {
    const PixelFeatures& f = pixels[p];
    const float mean = luminance(f.colour);
    float variance = 0;
    if (f.samples > 1) {
      variance = std::max(0.0f, f.luminanceSquare - mean * mean) / float(f.samples - 1);
    } else {
      float sum = 0, squares = 0;
      int n = 0;
      for (int qy = std::max(y - 1, 0); qy <= std::min(y + 1, height - 1); ++qy)
        for (int qx = std::max(x - 1, 0); qx <= std::min(x + 1, width - 1); ++qx) {
          const float l = luminance(pixels[size_t(qy) * width + qx].colour);
          sum += l;
          squares += l * l;
          ++n;
        }
      variance = std::max(0.0f, squares / n - (sum / n) * (sum / n));
    }
    const Vec3 albedo = f.albedo.cwiseMax(kLeastAlbedo);
    const float a = luminance(albedo);
    guides[p] = {f.normal, f.depth, f.albedo};
    const Vec3 rgb = f.colour.cwiseQuotient(albedo);
    light[p] = {rgb, variance / (a * a), luminance(rgb)};
  });
  const float albedoScale = 1.0f / (settings.sigmaAlbedo * settings.sigmaAlbedo);
  for (int pass = 0; pass < settings.passes; ++pass) {
    const int step = 1 << pass;
    // The variance the light is compared against, blurred over 3x3 pixels (a pixel's own estimate from a few
    // samples is itself noisy).
    rows([&](int x, int y, size_t p) {
      float sum = 0, weights = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int qx = x + dx, qy = y + dy;
          if (qx < 0 || qy < 0 || qx >= width || qy >= height) continue;
          const float h = kTaps[dx + 1] * kTaps[dy + 1];
          sum += h * light[size_t(qy) * width + qx].variance;
          weights += h;
        }
      blurred[p] = sum / weights;
    });
    rows([&](int x, int y, size_t p) {
      const Guide& gp = guides[p];
      const bool skyP = gp.depth == 0;
      const float lightP = light[p].luminance;
      const float lightScale = 1.0f / (settings.sigmaLight * std::sqrt(std::max(blurred[p], 0.0f)) + 1e-6f);
      const float depthScale = skyP ? 0.0f : 1.0f / (settings.sigmaDepth * float(step) * gp.depth);
      Vec3 sum = Vec3::Zero();
      float weights = 0, varianceSum = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        const int qy = y + dy * step;
        if (qy < 0 || qy >= height) continue;
        for (int dx = -1; dx <= 1; ++dx) {
          const int qx = x + dx * step;
          if (qx < 0 || qx >= width) continue;
          const size_t q = size_t(qy) * width + qx;
          const Light& lq = light[q];
          float w = kTaps[dx + 1] * kTaps[dy + 1];
          if (q != p) {
            const Guide& gq = guides[q];
            if (skyP != (gq.depth == 0)) continue;  // the sky's edge
            float exponent =
                std::abs(lightP - lq.luminance) * lightScale + (gp.albedo - gq.albedo).squaredNorm() * albedoScale;
            if (!skyP) {
              const float cosine = std::max(0.0f, gp.normal.dot(gq.normal));
              w *= powerOfTwoPower(cosine, settings.normalPower);
              exponent += std::abs(gp.depth - gq.depth) * depthScale;
            }
            w *= negativeExp(exponent);
          }
          sum += w * lq.rgb;
          weights += w;
          varianceSum += w * w * lq.variance;
        }
      }
      const Vec3 filtered = sum / weights;  // the centre's own weight is never 0
      next[p] = {filtered, varianceSum / (weights * weights), luminance(filtered)};
    });
    std::swap(light, next);
  }
  for (size_t p = 0; p < count; ++p)
    result[p] = light[p].rgb.cwiseProduct(pixels[p].albedo.cwiseMax(kLeastAlbedo)) + pixels[p].kept;
  return result;
}

}  // namespace surge
