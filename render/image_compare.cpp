// Channel-wise image comparison statistics and difference images.
#include "render/image_compare.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>

namespace clothsim::render {
namespace {

constexpr int kDiffGain = 4;

void check_consistent(const Image& image, const char* name) {
  if (image.width < 0 || image.height < 0 ||
      image.rgb.size() !=
          3 * static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height)) {
    throw std::invalid_argument(std::string("compare_images: image ") + name + " of " +
                                std::to_string(image.width) + " x " + std::to_string(image.height) +
                                " holds " + std::to_string(image.rgb.size()) + " bytes");
  }
}

}  // namespace

CompareResult compare_images(const Image& a, const Image& b, int tolerance, Image* diff) {
  check_consistent(a, "a");
  check_consistent(b, "b");
  if (a.width != b.width || a.height != b.height) {
    throw std::invalid_argument("compare_images: sizes differ: " + std::to_string(a.width) + " x " +
                                std::to_string(a.height) + " vs " + std::to_string(b.width) +
                                " x " + std::to_string(b.height));
  }
  if (tolerance < 0) throw std::invalid_argument("compare_images: negative tolerance");
  if (diff != nullptr) {
    diff->width = a.width;
    diff->height = a.height;
    diff->rgb.assign(a.rgb.size(), 0);
  }
  const std::size_t pixels = a.rgb.size() / 3;
  int max_abs = 0;
  std::size_t over = 0;
  double abs_sum = 0, squared_sum = 0;
  for (std::size_t p = 0; p < pixels; ++p) {
    bool pixel_over = false;
    for (std::size_t c = 3 * p; c < 3 * p + 3; ++c) {
      const int d = std::abs(int{a.rgb[c]} - int{b.rgb[c]});
      max_abs = std::max(max_abs, d);
      pixel_over = pixel_over || d > tolerance;
      abs_sum += d;
      squared_sum += static_cast<double>(d) * d;
      if (diff != nullptr) diff->rgb[c] = static_cast<std::uint8_t>(std::min(255, kDiffGain * d));
    }
    if (pixel_over) ++over;
  }
  CompareResult result;
  result.max_abs = max_abs;
  result.fraction_over = pixels > 0 ? static_cast<double>(over) / static_cast<double>(pixels) : 0;
  result.mean_abs = a.rgb.empty() ? 0 : abs_sum / static_cast<double>(a.rgb.size());
  const double mse = a.rgb.empty() ? 0 : squared_sum / static_cast<double>(a.rgb.size());
  result.psnr_db =
      mse > 0 ? 10.0 * std::log10(255.0 * 255.0 / mse) : std::numeric_limits<double>::infinity();
  return result;
}

}  // namespace clothsim::render
