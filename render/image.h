// 8-bit sRGB images and their PNG files (stb_image_write / stb_image, from Debian's shared libstb).
#pragma once

#include <cstdint>
#include <vector>

#include "core/files.h"

namespace surge {

struct Image {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;  // sRGB 8-bit, row by row from the top, 3 bytes a pixel
};

// Linear light in [0, 1] (clamped outside) to an 8-bit sRGB value, rounded to nearest.
uint8_t encodeSrgb(float linear);

// The mean of the squared differences of two images' 8-bit values over every pixel and channel (the square of
// the RMS image error of docs/performance.md); NaN if their sizes differ.
double meanSquaredDifference(const Image& a, const Image& b);

// Writes a PNG atomically (the file appears whole or not at all); throws RunError on failure.
void writePng(const fs::path& path, const Image& image);

// Reads a PNG (or any format stb_image knows) as 8-bit RGB; throws InputError naming the file on failure.
Image readPng(const fs::path& path);

}  // namespace surge
