// Image comparison: identical images, a few changed pixels (largest, mean and fraction over the
// tolerance), the difference image, tolerance boundary and size mismatch.
#include "render/image_compare.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <stdexcept>

namespace clothsim::render {
namespace {

Image gradient(int width, int height) {
  Image image;
  image.width = width;
  image.height = height;
  for (int i = 0; i < width * height * 3; ++i)
    image.rgb.push_back(static_cast<std::uint8_t>(i % 200));
  return image;
}

TEST(ImageCompareTest, IdenticalImagesHaveInfinitePsnr) {
  const Image a = gradient(10, 8);
  Image diff;
  const CompareResult r = compare_images(a, a, 0, &diff);
  EXPECT_EQ(r.max_abs, 0);
  EXPECT_EQ(r.mean_abs, 0);
  EXPECT_EQ(r.fraction_over, 0);
  EXPECT_TRUE(std::isinf(r.psnr_db));
  EXPECT_GT(r.psnr_db, 0);
  EXPECT_EQ(diff.width, 10);
  EXPECT_EQ(diff.height, 8);
  EXPECT_EQ(diff.rgb, std::vector<std::uint8_t>(10 * 8 * 3, 0));
}

TEST(ImageCompareTest, ReportsChangedPixels) {
  const Image a = gradient(10, 8);
  Image b = a;
  b.rgb[pixel_offset(b, 1, 1) + 0] += 10;  // three pixels, one channel each
  b.rgb[pixel_offset(b, 5, 2) + 1] -= 10;
  b.rgb[pixel_offset(b, 9, 7) + 2] += 10;
  Image diff;
  const CompareResult r = compare_images(a, b, 5, &diff);
  EXPECT_EQ(r.max_abs, 10);
  EXPECT_DOUBLE_EQ(r.fraction_over, 3.0 / 80.0);
  EXPECT_DOUBLE_EQ(r.mean_abs, 3 * 10.0 / (80 * 3));
  const double mse = 3 * 100.0 / (80 * 3);
  EXPECT_NEAR(r.psnr_db, 10 * std::log10(255.0 * 255.0 / mse), 1e-9);
  EXPECT_EQ(diff.rgb[pixel_offset(diff, 1, 1)], 40);
  EXPECT_EQ(diff.rgb[pixel_offset(diff, 5, 2) + 1], 40);
  EXPECT_EQ(diff.rgb[pixel_offset(diff, 9, 7) + 2], 40);
  EXPECT_EQ(diff.rgb[pixel_offset(diff, 0, 0)], 0);
  // Differences equal to the tolerance are not counted; large ones saturate in the diff image.
  EXPECT_EQ(compare_images(a, b, 10, nullptr).fraction_over, 0);
  b.rgb[0] = static_cast<std::uint8_t>(a.rgb[0] + 150);
  compare_images(a, b, 0, &diff);
  EXPECT_EQ(diff.rgb[0], 255);
}

TEST(ImageCompareTest, SizeMismatchThrows) {
  EXPECT_THROW(compare_images(gradient(10, 8), gradient(8, 10), 0, nullptr), std::invalid_argument);
  Image broken = gradient(10, 8);
  broken.rgb.pop_back();
  EXPECT_THROW(compare_images(broken, gradient(10, 8), 0, nullptr), std::invalid_argument);
  EXPECT_THROW(compare_images(gradient(2, 2), gradient(2, 2), -1, nullptr), std::invalid_argument);
}

}  // namespace
}  // namespace clothsim::render
