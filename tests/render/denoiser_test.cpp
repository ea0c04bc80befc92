// The path tracer's denoiser (render/denoiser.h): it smooths noise where the guides say the surface is one,
// keeps edges the guides see, puts the albedo's texture back, and gives the same bytes at any thread count;
// on a real render it brings a few samples closer to a many-sample reference than the same samples unfiltered.
#include "render/denoiser.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/parallel.h"
#include "render/renderer.h"
#include "render_test_helpers.h"

namespace surge {
namespace {

using Vec3 = Eigen::Vector3f;
constexpr int kSize = 64, kSamples = 4;

// An image whose pixel (x, y) has light light(x, y) on a surface of albedo albedo(x, y) and normal
// normal(x, y), seen through kSamples samples each with uniform noise of +-noise (relative): the colour is the
// samples' mean and luminanceSquare their mean square, as the renderer records them.
template <typename Light, typename Albedo, typename Normal>
std::vector<PixelFeatures> noisyImage(Light light, Albedo albedo, Normal normal, float noise, uint32_t seed = 1) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> uniform(-noise, noise);
  std::vector<PixelFeatures> pixels(kSize * kSize);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      PixelFeatures& p = pixels[y * kSize + x];
      p.albedo = Vec3::Constant(albedo(x, y));
      p.normal = normal(x, y);
      p.depth = 2;
      p.samples = kSamples;
      for (int s = 0; s < kSamples; ++s) {
        const float value = light(x, y) * albedo(x, y) * (1 + uniform(random));
        p.colour += Vec3::Constant(value / kSamples);
        p.luminanceSquare += value * value / kSamples;
      }
    }
  return pixels;
}

const auto up = [](int, int) { return Vec3(0, 1, 0); };

// Mean and standard deviation of the green channel over the pixels with x in [x0, x1) and y in [y0, y1).
void stats(const std::vector<Vec3>& image, int x0, int x1, double& mean, double& deviation, int y0 = 0,
           int y1 = kSize) {
  double sum = 0, squares = 0;
  int n = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      const double v = image[y * kSize + x].y();
      sum += v;
      squares += v * v;
      ++n;
    }
  mean = sum / n;
  deviation = std::sqrt(std::max(0.0, squares / n - mean * mean));
}

// On one flat surface under even light the noise falls. Four samples of +-50% uniform noise leave a pixel's
// mean with a deviation of 0.5 / sqrt(3) / 2 = 14%. Four passes of the 3x3 B-spline kernel at full weight
// divide it by 24 (1 / sum of the squared weights of the combined kernel, 0.0417 a side); the light's
// edge-stopping gives some of that up (a tap whose light differs from the centre's by its noise weighs less):
// asked for half, 12 times, away from the image's border (16 pixels, beyond the kernel's reach of 15), with the
// mean kept within 1% (uniform noise is symmetric, so the edge-stopping biases neither way).
TEST(DenoiserTest, NoiseOnOneSurfaceFallsAndTheMeanStays) {
  const auto pixels = noisyImage([](int, int) { return 1.0f; }, [](int, int) { return 0.5f; }, up, 0.5f);
  std::vector<Vec3> input;
  for (const PixelFeatures& p : pixels) input.push_back(p.colour);
  const std::vector<Vec3> output = Denoiser().filter(pixels, kSize, kSize);
  double meanIn, deviationIn, meanOut, deviationOut;
  stats(input, 16, kSize - 16, meanIn, deviationIn, 16, kSize - 16);
  stats(output, 16, kSize - 16, meanOut, deviationOut, 16, kSize - 16);
  std::printf("flat: mean %.4f -> %.4f, deviation %.4f -> %.4f\n", meanIn, meanOut, deviationIn, deviationOut);
  EXPECT_NEAR(deviationIn / meanIn, 0.5 / std::sqrt(3.0) / 2, 0.1 * deviationIn / meanIn);
  EXPECT_LT(deviationOut, deviationIn / 12);
  EXPECT_NEAR(meanOut, meanIn, 0.01 * meanIn);
}

// Where the normal turns, the light on either side is not mixed: a wall lit at 0.2 beside a floor lit at 1.
// The columns next to the edge keep their own side's light within 3% of the brighter side (mixing the two
// evenly would be off by 40%), while they are still smoothed.
TEST(DenoiserTest, AnEdgeInTheNormalsIsKept) {
  const auto light = [](int x, int) { return x < kSize / 2 ? 1.0f : 0.2f; };
  const auto normal = [](int x, int) { return x < kSize / 2 ? Vec3(0, 1, 0) : Vec3(1, 0, 0); };
  const auto pixels = noisyImage(light, [](int, int) { return 1.0f; }, normal, 0.5f);
  const std::vector<Vec3> output = Denoiser().filter(pixels, kSize, kSize);
  double left, right, leftDeviation, rightDeviation;
  stats(output, kSize / 2 - 1, kSize / 2, left, leftDeviation);
  stats(output, kSize / 2, kSize / 2 + 1, right, rightDeviation);
  std::printf("edge: %.4f | %.4f (deviations %.4f, %.4f)\n", left, right, leftDeviation, rightDeviation);
  EXPECT_NEAR(left, 1.0, 0.03);
  EXPECT_NEAR(right, 0.2, 0.03);
  EXPECT_LT(leftDeviation, 0.5 * 0.5 / std::sqrt(3.0) / 2);
}

// The albedo's texture comes back: a checkerboard of albedo 0.3 and 0.9 in 8-pixel squares under even light
// is smoothed as light and multiplied back. The pixels on the squares' edges (a neighbour of the other albedo)
// end, on average, within 2% of their own albedo (light mixed across the edge would put them 30% or more off;
// the noise averages out over their 2,000), and the RMS of every pixel's relative error falls to under a third
// of the input's 14%.
TEST(DenoiserTest, TheAlbedosTextureIsPutBack) {
  const auto albedo = [](int x, int y) { return ((x / 8 + y / 8) & 1) ? 0.9f : 0.3f; };
  const auto pixels = noisyImage([](int, int) { return 1.0f; }, albedo, up, 0.5f);
  const std::vector<Vec3> output = Denoiser().filter(pixels, kSize, kSize);
  double edgeSum = 0, squaresIn = 0, squaresOut = 0;
  int edges = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const double out = output[y * kSize + x].y() / albedo(x, y) - 1.0;
      const double in = pixels[y * kSize + x].colour.y() / albedo(x, y) - 1.0;
      squaresIn += in * in;
      squaresOut += out * out;
      bool edge = false;
      for (int d = -1; d <= 1; d += 2)
        edge = edge || (x + d >= 0 && x + d < kSize && albedo(x + d, y) != albedo(x, y)) ||
               (y + d >= 0 && y + d < kSize && albedo(x, y + d) != albedo(x, y));
      if (edge) edgeSum += out, ++edges;
    }
  const double rmsIn = std::sqrt(squaresIn / (kSize * kSize)), rmsOut = std::sqrt(squaresOut / (kSize * kSize));
  std::printf("checker: edge pixels %+.2f%% off their albedo on average (%d), RMS %.1f%% -> %.1f%%\n",
              100 * edgeSum / edges, edges, 100 * rmsIn, 100 * rmsOut);
  EXPECT_LT(std::abs(edgeSum / edges), 0.02);
  EXPECT_LT(rmsOut, rmsIn / 3);
}

// A texture that changes smoothly (an albedo wave of period 16 pixels, 0.6 +- 0.25) is not blurred: the
// filter smooths the light and multiplies the texture back. Without the albedo divided out, the taps that the
// albedo's edge-stopping lets through would flatten the wave's crests. The mean relative error over the
// crests and troughs (the rows where the wave is within 2% of its extreme) must stay under 1%, where noise
// alone averages out.
TEST(DenoiserTest, ASmoothTextureIsNotBlurred) {
  const auto albedo = [](int x, int) { return 0.6f + 0.25f * std::sin(2 * float(M_PI) * x / 16); };
  const auto pixels = noisyImage([](int, int) { return 1.0f; }, albedo, up, 0.5f);
  const std::vector<Vec3> output = Denoiser().filter(pixels, kSize, kSize);
  double crest = 0;
  int count = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      if (std::abs(std::abs(albedo(x, y) - 0.6f) - 0.25f) > 0.02f * 0.25f) continue;
      crest += std::copysign(1.0, albedo(x, y) - 0.6) * (output[y * kSize + x].y() / albedo(x, y) - 1.0);
      ++count;
    }
  crest /= count;
  std::printf("texture: crests and troughs %+.2f%% (%d pixels; negative: flattened)\n", 100 * crest, count);
  EXPECT_LT(std::abs(crest), 0.01);
}

// The light kept out of the filter (the water's reflection) comes back as it was, pixel for pixel: stripes of
// it over smoothly lit noise keep their full contrast.
TEST(DenoiserTest, KeptLightIsAddedBackUnfiltered) {
  auto pixels = noisyImage([](int, int) { return 1.0f; }, [](int, int) { return 0.5f; }, up, 0.5f);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) pixels[y * kSize + x].kept = Vec3::Constant(x % 2 ? 2.0f : 0.0f);
  const std::vector<Vec3> output = Denoiser().filter(pixels, kSize, kSize);
  double stripes = 0;
  for (int y = 16; y < kSize - 16; ++y)
    for (int x = 16; x < kSize - 16; ++x) stripes += (x % 2 ? 1 : -1) * output[y * kSize + x].y();
  stripes /= (kSize - 32) * (kSize - 32) / 2;
  std::printf("kept: stripe contrast %.4f of 2\n", stripes);
  EXPECT_NEAR(stripes, 2.0, 0.02);
}

TEST(DenoiserTest, SameResultWithOneAndTwoThreads) {
  const auto light = [](int x, int y) { return 0.5f + 0.5f * std::sin(0.2f * x) * std::cos(0.3f * y); };
  const auto normal = [](int x, int y) { return Vec3(std::sin(0.1f * x), 1, std::cos(0.07f * y)).normalized(); };
  const auto pixels = noisyImage(light, [](int x, int) { return x % 7 ? 0.6f : 0.2f; }, normal, 0.8f);
  std::vector<Vec3> one, two;
  {
    const ThreadLimit limit(1);
    one = Denoiser().filter(pixels, kSize, kSize);
  }
  {
    const ThreadLimit limit(2);
    two = Denoiser().filter(pixels, kSize, kSize);
  }
  ASSERT_EQ(one.size(), two.size());
  EXPECT_EQ(0, std::memcmp(one.data(), two.data(), one.size() * sizeof(Vec3)));
}

// RMSE of the 8-bit values.
double rmse(const Image& a, const Image& b) { return std::sqrt(meanSquaredDifference(a, b)); }

// On a real render (a block of water in the tank, its shadow on the checkered floor; 160x120 pixels), against
// a 256-sample reference: 2 samples filtered are closer to it than 2 unfiltered by at least a fifth (measured:
// 12.4 against 16.4). Filtering cannot anti-alias: the tank's edges, thinner than a pixel here, stay dashed
// where 2 samples hit them or missed. Edge samples (8 in all where a pixel straddles surfaces: here the tank's
// edges, the box's and the checker's lines, under half the pixels) do that: 2 filtered samples with them must
// beat 8 unfiltered ones (the demo's setting before the denoiser) by a tenth (measured: 4.25 against 5.15),
// at fewer samples on average.
TEST(DenoiserTest, FilteredAndEdgeSampledRendersAreCloserToTheReference) {
  Scene scene = testing::unitTankScene(R"("width": 160, "height": 120)");
  const TriangleMesh water = testing::boxMesh({0.2f, 0.0f, 0.25f}, {0.7f, 0.45f, 0.75f});
  RenderStats stats;
  const auto render = [&](int samples, int filter, int edgeSamples = 0) {
    scene.render.samples = samples;
    scene.render.denoise = filter;
    scene.render.edge_samples = edgeSamples;
    stats = RenderStats{};
    return renderMesh(water, scene, 3, &stats);
  };
  const Image reference = render(256, 0);
  const double raw2 = rmse(render(2, 0), reference), raw8 = rmse(render(8, 0), reference),
               filtered2 = rmse(render(2, 1), reference);
  EXPECT_EQ(stats.edgePixels, 0u);
  const double edged = rmse(render(2, 1, 8), reference);
  const double edgeShare = double(stats.edgePixels) / (160.0 * 120.0);
  std::printf("RMSE against 256 samples: 2 raw %.2f, 8 raw %.2f, 2 filtered %.2f, 2 filtered with 8 at edges %.2f "
              "(%.1f%% of the pixels)\n", raw2, raw8, filtered2, edged, 100 * edgeShare);
  EXPECT_LT(filtered2, 0.8 * raw2);
  EXPECT_LT(edged, 0.9 * raw8);
  EXPECT_GT(edgeShare, 0.0);
  EXPECT_LT(2 + 6 * edgeShare, 8 * 0.75) << "the edge samples cost as much as sampling everything";
}

// Edge samples no more than `samples` change nothing: the same bytes as without.
TEST(DenoiserTest, EdgeSamplesNotAboveSamplesChangeNothing) {
  Scene scene = testing::unitTankScene(R"("samples": 4, "edge_samples": 0)");
  const TriangleMesh water = testing::boxMesh({0.2f, 0.0f, 0.25f}, {0.7f, 0.45f, 0.75f});
  const Image plain = renderMesh(water, scene, 1);
  scene.render.edge_samples = 4;
  EXPECT_TRUE(renderMesh(water, scene, 1).rgb == plain.rgb);
}

}  // namespace
}  // namespace surge
