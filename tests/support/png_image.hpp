#pragma once
// A figure's PNG read back with libpng, for the tests that check what `plot` draws: its size, and
// that something is drawn on it (not one colour, not almost all background).
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <png.h>

namespace delayspec::testing {

struct PngPixels {
  int width = 0, height = 0;
  std::vector<std::uint32_t> rgba;  // row by row, one word per pixel
  std::string error;                // libpng's message when the file could not be read
};

inline PngPixels read_png(const std::filesystem::path& path) {
  PngPixels out;
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&image, path.c_str())) {
    out.error = image.message;
    return out;
  }
  image.format = PNG_FORMAT_RGBA;
  out.rgba.resize(static_cast<size_t>(image.width) * image.height);
  if (!png_image_finish_read(&image, nullptr, out.rgba.data(), 0, nullptr)) {
    out.error = image.message;
    png_image_free(&image);
    out.rgba.clear();
    return out;
  }
  out.width = static_cast<int>(image.width);
  out.height = static_cast<int>(image.height);
  return out;
}

// How the pixels spread over colours: how many distinct ones, and the share of the pixels that
// are not the most common colour (the background).
struct PixelSpread {
  size_t colours = 0;
  double drawn_fraction = 0;
};

inline PixelSpread pixel_spread(const PngPixels& p) {
  std::map<std::uint32_t, size_t> count;
  for (const std::uint32_t c : p.rgba) ++count[c];
  size_t background = 0;
  for (const auto& [colour, n] : count) background = std::max(background, n);
  PixelSpread s;
  s.colours = count.size();
  s.drawn_fraction = p.rgba.empty() ? 0 : 1.0 - static_cast<double>(background) / static_cast<double>(p.rgba.size());
  return s;
}

}  // namespace delayspec::testing
