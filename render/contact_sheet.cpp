#include "render/contact_sheet.h"

#include <algorithm>
#include <cmath>

#include "core/errors.h"

namespace surge {

namespace {

constexpr int kGutter = 4;
constexpr uint8_t kGutterLevel = 24;

// Shrinks by averaging the source pixels each destination pixel covers (whole pixels, nearest bounds).
Image shrink(const Image& source, int width, int height) {
  Image out;
  out.width = width;
  out.height = height;
  out.rgb.assign(size_t(width) * height * 3, 0);
  for (int y = 0; y < height; ++y) {
    const int sy0 = y * source.height / height, sy1 = std::max(sy0 + 1, (y + 1) * source.height / height);
    for (int x = 0; x < width; ++x) {
      const int sx0 = x * source.width / width, sx1 = std::max(sx0 + 1, (x + 1) * source.width / width);
      for (int k = 0; k < 3; ++k) {
        long sum = 0;
        for (int sy = sy0; sy < sy1; ++sy)
          for (int sx = sx0; sx < sx1; ++sx) sum += source.rgb[3 * (size_t(sy) * source.width + sx) + k];
        const long n = long(sy1 - sy0) * (sx1 - sx0);
        out.rgb[3 * (size_t(y) * width + x) + k] = uint8_t((sum + n / 2) / n);
      }
    }
  }
  return out;
}

}  // namespace

std::vector<int> contactSheetFrames(const std::vector<int>& frames, int count) {
  if (count <= 0 || frames.empty()) return {};
  if (frames.size() <= size_t(count)) return frames;
  std::vector<int> picked;
  for (int i = 0; i < count; ++i) {
    // The i-th of `count` evenly spaced positions from the first frame to the last, rounded.
    const size_t index = count == 1 ? 0 : size_t(std::lround(double(i) * (frames.size() - 1) / (count - 1)));
    picked.push_back(frames[index]);
  }
  return picked;
}

Image contactSheet(const std::vector<Image>& images, int columns, int cellWidth) {
  Image sheet;
  if (images.empty() || columns <= 0) return sheet;
  const Image& first = images.front();
  const int cellW = std::max(1, std::min(cellWidth, first.width));
  const int cellH = std::max(1, int(std::lround(double(cellW) * first.height / first.width)));
  columns = std::min<int>(columns, int(images.size()));
  const int rows = int((images.size() + columns - 1) / columns);
  sheet.width = columns * cellW + (columns + 1) * kGutter;
  sheet.height = rows * cellH + (rows + 1) * kGutter;
  sheet.rgb.assign(size_t(sheet.width) * sheet.height * 3, kGutterLevel);
  for (size_t i = 0; i < images.size(); ++i) {
    const Image cell = shrink(images[i], cellW, cellH);
    const int x0 = kGutter + int(i % columns) * (cellW + kGutter),
              y0 = kGutter + int(i / columns) * (cellH + kGutter);
    for (int y = 0; y < cellH; ++y)
      std::copy_n(&cell.rgb[3 * size_t(y) * cellW], 3 * size_t(cellW),
                  &sheet.rgb[3 * (size_t(y0 + y) * sheet.width + x0)]);
  }
  return sheet;
}

fs::path makeContactSheet(const fs::path& dir, const Scene& scene, int count) {
  const std::vector<int> frames = contactSheetFrames(listFrames(dir, "frames", "png"), count);
  if (frames.empty())
    throw InputError(dir.string(), "frames", "no frames/frame_NNNNN.png; run surge render first");
  std::vector<Image> images;
  for (int frame : frames) images.push_back(readPng(framePath(dir, "frames", frame, "png")));
  const int columns = 4;
  const Image sheet = contactSheet(images, columns, std::max(160, images.front().width / columns));
  const fs::path path = dir / (scene.name + "_contact_sheet.png");
  writePng(path, sheet);
  return path;
}

}  // namespace surge
