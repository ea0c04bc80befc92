#include "render/image.h"

#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <ostream>
#include <string>

#include "core/errors.h"

namespace surge {

double meanSquaredDifference(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height || a.rgb.size() != b.rgb.size() || a.rgb.empty()) return NAN;
  double sum = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i) {
    const double d = double(a.rgb[i]) - double(b.rgb[i]);
    sum += d * d;
  }
  return sum / double(a.rgb.size());
}

uint8_t encodeSrgb(float linear) {
  const float c = std::clamp(linear, 0.0f, 1.0f);
  const float encoded = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
  return static_cast<uint8_t>(std::lround(encoded * 255.0f));
}

namespace {

void writeToStream(void* context, void* data, int size) {
  static_cast<std::ostream*>(context)->write(static_cast<const char*>(data), size);
}

}  // namespace

void writePng(const fs::path& path, const Image& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgb.size() != size_t(image.width) * size_t(image.height) * 3)
    throw RunError("cannot write " + path.string() + ": the image of " + std::to_string(image.width) + "x" +
                   std::to_string(image.height) + " pixels holds " + std::to_string(image.rgb.size()) +
                   " bytes");
  try {
    writeFileAtomically(path, [&](std::ostream& out) {
      if (!stbi_write_png_to_func(writeToStream, &out, image.width, image.height, 3, image.rgb.data(),
                                  image.width * 3))
        throw RunError("cannot encode " + path.string() + " as PNG");
    });
  } catch (const fs::filesystem_error& error) {  // for example a folder that cannot be created
    throw RunError("cannot write " + path.string() + ": " + error.code().message());
  }
}

Image readPng(const fs::path& path) {
  int width = 0, height = 0, channels = 0;
  uint8_t* pixels = stbi_load(path.string().c_str(), &width, &height, &channels, 3);
  if (!pixels)
    throw InputError(path.string(), std::string("cannot be read as an image: ") + stbi_failure_reason());
  Image image;
  image.width = width;
  image.height = height;
  image.rgb.assign(pixels, pixels + size_t(width) * size_t(height) * 3);
  stbi_image_free(pixels);
  return image;
}

}  // namespace surge
