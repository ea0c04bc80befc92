// What the path tracer's settings cost and buy: for each setting (samples a pixel, denoiser on or off), the
// seconds a frame takes and the error of its image against a reference of the same frames rendered with many
// more samples. The error is the root mean square difference of the 8-bit sRGB values over every pixel and
// channel (what a viewer sees), and its PSNR. Prints a markdown table for docs/performance.md.
//
//   surge_render_quality RUN_DIR REFERENCE_DIR FRAMES SETTING...
// RUN_DIR holds scene.json and surface/frame_NNNNN.ply; REFERENCE_DIR/frames/frame_NNNNN.png the reference
// (scripts/bench_render_quality.sh makes it with `surge render`); FRAMES a comma-separated list; a SETTING is
// SAMPLES:DENOISE[:EDGE_SAMPLES], e.g. 8:0 for 8 samples unfiltered, 2:1:8 for 2 filtered and 8 at edges.
// Each setting renders its frames with one PathTracer, as `surge render` does a stage: the time includes
// building each frame's BVH.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "bench/bench_timing.h"
#include "core/files.h"
#include "render/renderer.h"

namespace {

std::vector<int> parseList(const std::string& text, char separator = ',') {
  std::vector<int> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, separator)) values.push_back(std::atoi(item.c_str()));
  return values;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: surge_render_quality RUN_DIR REFERENCE_DIR FRAMES SAMPLES:DENOISE...\n");
    return 2;
  }
  const surge::fs::path run = argv[1], reference = argv[2];
  const std::vector<int> frames = parseList(argv[3]);
  surge::Scene scene = surge::loadScene(run / "scene.json");
  std::vector<surge::TriangleMesh> meshes;
  std::vector<surge::Image> references;
  for (int f : frames) {
    meshes.push_back(surge::readMeshPly(surge::framePath(run, "surface", f, "ply")));
    references.push_back(surge::readPng(surge::framePath(reference, "frames", f, "png")));
  }
  std::printf("| samples | denoiser | edge samples (pixels) | s / frame | RMSE (8-bit) | PSNR (dB) | per frame |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  for (int a = 4; a < argc; ++a) {
    const std::string setting = argv[a];
    const std::vector<int> values = parseList(setting, ':');
    scene.render.samples = values.at(0);
    scene.render.denoise = values.size() > 1 ? values[1] : 0;
    scene.render.edge_samples = values.size() > 2 ? values[2] : 0;
    double seconds = 0, squares = 0, edgeShare = 0;
    std::string perFrame;
    surge::PathTracer tracer;
    for (size_t i = 0; i < frames.size(); ++i) {
      const auto start = surge::BenchClock::now();
      surge::RenderStats stats;
      const surge::Image image = tracer.render(meshes[i], {}, scene, frames[i], &stats);
      seconds += surge::secondsSince(start);
      edgeShare += double(stats.edgePixels) / (double(image.width) * image.height) / double(frames.size());
      const double e = std::sqrt(surge::meanSquaredDifference(image, references[i]));
      if (std::isnan(e)) {
        std::fprintf(stderr, "surge_render_quality: frame %d is %dx%d, its reference %dx%d\n", frames[i],
                     image.width, image.height, references[i].width, references[i].height);
        return 2;
      }
      squares += e * e;
      char text[32];
      std::snprintf(text, sizeof text, "%s%.2f", i ? ", " : "", e);
      perFrame += text;
    }
    const double error = std::sqrt(squares / double(frames.size()));
    char edges[48] = "-";
    if (scene.render.edge_samples > scene.render.samples)
      std::snprintf(edges, sizeof edges, "%d (%.1f%%)", scene.render.edge_samples, 100 * edgeShare);
    std::printf("| %d | %s | %s | %.2f | %.2f | %.1f | %s |\n", scene.render.samples,
                scene.render.denoise ? "on" : "off", edges, seconds / double(frames.size()), error,
                20 * std::log10(255.0 / error), perFrame.c_str());
    std::fflush(stdout);
  }
  return 0;
}
