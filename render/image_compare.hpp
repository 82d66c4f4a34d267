// Comparing two RGB images of equal size: largest channel difference, fraction of pixels beyond
// a tolerance, PSNR, and an optional amplified difference image for inspection.
#pragma once

#include "render/image.hpp"

namespace clothsim::render {

struct CompareResult {
  double max_abs = 0;        // largest per-channel absolute difference, 0..255
  double mean_abs = 0;       // mean per-channel absolute difference, 0..255
  double fraction_over = 0;  // fraction of pixels with some channel differing by > tolerance
  double psnr_db = 0;        // 10 log10(255² / mean squared channel error); +inf if identical
};

// Compares a and b channel by channel. If `diff` is not null it receives an image of the same
// size holding min(255, 4 · |a − b|) per channel. Throws std::invalid_argument if the sizes
// differ or an image's byte count does not match its size, or if tolerance is negative.
CompareResult compare_images(const Image& a, const Image& b, int tolerance, Image* diff = nullptr);

}  // namespace clothsim::render
