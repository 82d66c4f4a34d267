// An 8-bit RGB image in memory: the output of the renderer and the unit of PNG I/O and image
// comparison. Rows are stored top row first, pixels left to right, 3 bytes (R, G, B) each.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace clothsim::render {

struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;  // width · height · 3 bytes, top row first
};

// Index of the red byte of pixel (x, y) (x to the right, y downwards from the top row).
inline std::size_t pixel_offset(const Image& image, int x, int y) {
  return (static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) +
          static_cast<std::size_t>(x)) *
         3;
}

// The RGB triple of pixel (x, y); no bounds check.
inline std::array<std::uint8_t, 3> pixel(const Image& image, int x, int y) {
  const std::size_t i = pixel_offset(image, x, y);
  return {image.rgb[i], image.rgb[i + 1], image.rgb[i + 2]};
}

}  // namespace clothsim::render
