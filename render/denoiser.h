// An edge-aware filter for the path tracer's noisy images, driven by what the tracer knows besides colour:
// the first surface each camera ray meets (its normal and distance) and the albedo of the first diffuse
// surface along the view (through water and glass), averaged over a pixel's samples. These are nearly free of
// noise, so they say where the image has real edges, and dividing the colour by the albedo leaves the light
// alone to be smoothed: the floor's checkerboard, seen directly or through water, is put back afterwards.
//
// The filter is the edge-avoiding a-trous wavelet transform (Dammertz, Sewtz, Hanika and Lensch, "Edge-Avoiding
// A-Trous Wavelet Transform for fast Global Illumination Filtering", HPG 2010): passes of a 3x3 B-spline
// kernel whose taps lie 1, 2, 4, ... pixels apart, each tap weighted by how alike its pixel is to the centre:
//   w = h(dx) h(dy) w_normal w_depth w_albedo w_light,
//   w_normal = max(0, n_p . n_q)^(2^normal_power),
//   w_depth  = exp(-|z_p - z_q| / (sigma_depth step z_p)),
//   w_albedo = exp(-|a_p - a_q|^2 / sigma_albedo^2),
//   w_light  = exp(-|l_p - l_q| / (sigma_light sqrt(var_p))),
// where l is the luminance of the demodulated light and var its variance, estimated from the pixel's own
// samples and filtered along with it (after Schied et al., "Spatiotemporal Variance-Guided Filtering", HPG
// 2017, eq. 3-5, without its temporal part). Where a pixel's samples agree (var small) nothing is blurred
// across a change of light; where they disagree the filter smooths.
//
// Every output pixel is gathered from the input in a fixed order, so the result is the same bytes whatever
// the thread count.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

namespace surge {

// The luminance of linear sRGB (Rec. 709 weights): what the filter compares and estimates the variance of.
inline float luminance(const Eigen::Vector3f& c) { return 0.2126f * c.x() + 0.7152f * c.y() + 0.0722f * c.z(); }

// A pixel's mean over its samples of what the tracer saw.
struct PixelFeatures {
  Eigen::Vector3f colour = Eigen::Vector3f::Zero();  // linear radiance to filter
  Eigen::Vector3f kept = Eigen::Vector3f::Zero();    // linear radiance added back unfiltered (reflections)
  Eigen::Vector3f albedo = Eigen::Vector3f::Ones();  // 1 where the view reaches no diffuse surface
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();  // zero where the camera ray meets nothing (the sky)
  float depth = 0;                                   // 0 for the sky
  float luminanceSquare = 0;  // the mean of the samples' squared luminance of `colour`, for their variance
  int samples = 1;
};

struct DenoiseSettings {
  int passes = 4;  // taps 1, 2, 4, 8 pixels apart
  int normalPower = 6;  // the normals' cosine to the 64th
  float sigmaDepth = 0.01f, sigmaAlbedo = 0.1f, sigmaLight = 4;
};

// Holds its buffers from image to image: on these machines a frame's worth of fresh pages (50 MB at 960x540)
// cost more page faults than the filter's arithmetic.
class Denoiser {
 public:
  explicit Denoiser(const DenoiseSettings& settings = {});
  ~Denoiser();
  Denoiser(const Denoiser&) = delete;
  Denoiser& operator=(const Denoiser&) = delete;

  // The filtered linear radiance of each pixel, plus its `kept` (row by row from the top), valid until the next
  // call. The variance of a pixel's mean is its samples' variance over their number; of one sample, the
  // variance of the luminance over its 3x3 neighbours.
  const std::vector<Eigen::Vector3f>& filter(const std::vector<PixelFeatures>& pixels, int width, int height);

 private:
  struct Buffers;
  DenoiseSettings settings_;
  std::unique_ptr<Buffers> buffers_;
};

}  // namespace surge
