// PNG reading and writing: exact and byte-deterministic round trip, conversion of grey and RGBA
// files (built here by an independent minimal encoder), and errors that name the path.
#include "render/png_io.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

namespace clothsim::render {
namespace {

namespace fs = std::filesystem;

class PngIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("clothsim_png_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

Image test_pattern(int width, int height) {
  Image image;
  image.width = width;
  image.height = height;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      image.rgb.push_back(static_cast<std::uint8_t>(x * 37 + y));
      image.rgb.push_back(static_cast<std::uint8_t>(y * 91 + 3 * x));
      image.rgb.push_back(static_cast<std::uint8_t>((x ^ y) * 13));
    }
  }
  return image;
}

std::vector<char> file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// --- A minimal independent PNG encoder (stored deflate blocks, filter 0) ---

std::uint32_t crc32(const std::vector<std::uint8_t>& bytes) {
  std::uint32_t crc = 0xffffffffu;
  for (const std::uint8_t byte : bytes) {
    crc ^= byte;
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

void put32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<std::uint8_t>(v >> shift));
}

void chunk(std::vector<std::uint8_t>& out, const char* type,
           const std::vector<std::uint8_t>& data) {
  put32(out, static_cast<std::uint32_t>(data.size()));
  std::vector<std::uint8_t> typed(type, type + 4);
  typed.insert(typed.end(), data.begin(), data.end());
  out.insert(out.end(), typed.begin(), typed.end());
  put32(out, crc32(typed));
}

// color_type: 0 grey, 2 RGB, 4 grey+alpha, 6 RGBA; `samples` holds rows without filter bytes.
void write_raw_png(const std::string& path, int width, int height, std::uint8_t color_type,
                   const std::vector<std::uint8_t>& samples) {
  const std::size_t row = samples.size() / static_cast<std::size_t>(height);
  std::vector<std::uint8_t> raw;
  for (int y = 0; y < height; ++y) {
    raw.push_back(0);
    const auto begin =
        samples.begin() + static_cast<std::ptrdiff_t>(row * static_cast<std::size_t>(y));
    raw.insert(raw.end(), begin, begin + static_cast<std::ptrdiff_t>(row));
  }
  ASSERT_LT(raw.size(), 65535u);
  std::vector<std::uint8_t> z = {0x78, 0x01, 0x01};  // zlib header; final stored block
  const auto len = static_cast<std::uint16_t>(raw.size());
  const auto nlen = static_cast<std::uint16_t>(~len);
  z.insert(z.end(), {static_cast<std::uint8_t>(len & 0xff), static_cast<std::uint8_t>(len >> 8),
                     static_cast<std::uint8_t>(nlen & 0xff), static_cast<std::uint8_t>(nlen >> 8)});
  z.insert(z.end(), raw.begin(), raw.end());
  std::uint32_t a = 1, b = 0;
  for (const std::uint8_t byte : raw) {
    a = (a + byte) % 65521u;
    b = (b + a) % 65521u;
  }
  put32(z, (b << 16) | a);

  std::vector<std::uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  std::vector<std::uint8_t> ihdr;
  put32(ihdr, static_cast<std::uint32_t>(width));
  put32(ihdr, static_cast<std::uint32_t>(height));
  ihdr.insert(ihdr.end(), {8, color_type, 0, 0, 0});
  chunk(png, "IHDR", ihdr);
  chunk(png, "IDAT", z);
  chunk(png, "IEND", {});
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
}

TEST_F(PngIoTest, RoundTripIsExact) {
  const Image image = test_pattern(37, 23);
  write_png(path("a.png"), image);
  const Image back = read_png(path("a.png"));
  EXPECT_EQ(back.width, image.width);
  EXPECT_EQ(back.height, image.height);
  EXPECT_EQ(back.rgb, image.rgb);
}

TEST_F(PngIoTest, EqualImagesGiveIdenticalFilesAndNoTemporaryIsLeft) {
  const Image image = test_pattern(16, 9);
  write_png(path("a.png"), image);
  write_png(path("b.png"), image);
  EXPECT_EQ(file_bytes(path("a.png")), file_bytes(path("b.png")));
  write_png(path("a.png"), test_pattern(5, 5));  // overwriting replaces the file
  EXPECT_EQ(read_png(path("a.png")).width, 5);
  int files = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir_)) ++files;
  EXPECT_EQ(files, 2);
}

TEST_F(PngIoTest, ReadsRawRgbFromIndependentEncoder) {
  const Image image = test_pattern(7, 4);
  write_raw_png(path("rgb.png"), 7, 4, 2, image.rgb);
  EXPECT_EQ(read_png(path("rgb.png")).rgb, image.rgb);
}

TEST_F(PngIoTest, ConvertsGreyAndRgbaToRgb) {
  write_raw_png(path("grey.png"), 3, 2, 0, {0, 100, 255, 7, 8, 9});
  const Image grey = read_png(path("grey.png"));
  ASSERT_EQ(grey.width, 3);
  ASSERT_EQ(grey.height, 2);
  EXPECT_EQ(grey.rgb, (std::vector<std::uint8_t>{0, 0, 0, 100, 100, 100, 255, 255, 255, 7, 7, 7, 8,
                                                 8, 8, 9, 9, 9}));
  write_raw_png(path("rgba.png"), 2, 1, 6, {10, 20, 30, 0, 40, 50, 60, 255});
  EXPECT_EQ(read_png(path("rgba.png")).rgb, (std::vector<std::uint8_t>{10, 20, 30, 40, 50, 60}));
  write_raw_png(path("grey_alpha.png"), 2, 1, 4, {10, 0, 200, 255});
  EXPECT_EQ(read_png(path("grey_alpha.png")).rgb,
            (std::vector<std::uint8_t>{10, 10, 10, 200, 200, 200}));
}

TEST_F(PngIoTest, ReadErrorsNameThePath) {
  const std::string missing = path("missing.png");
  try {
    read_png(missing);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
  const std::string text = path("text.png");
  std::ofstream(text) << "not a png at all";
  try {
    read_png(text);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
  }
  // A valid PNG cut short.
  write_png(path("full.png"), test_pattern(40, 40));
  std::vector<char> bytes = file_bytes(path("full.png"));
  bytes.resize(bytes.size() / 2);
  const std::string truncated = path("truncated.png");
  std::ofstream(truncated, std::ios::binary)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  try {
    read_png(truncated);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(truncated), std::string::npos) << e.what();
  }
}

TEST_F(PngIoTest, WriteFailureNamesThePathAndLeavesNoFile) {
  const std::string in_missing_dir = path("no_such_dir/a.png");
  try {
    write_png(in_missing_dir, test_pattern(4, 4));
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(in_missing_dir), std::string::npos) << e.what();
  }
  // The target is a non-empty directory: encoding succeeds but the final rename fails.
  const std::string occupied = path("occupied");
  fs::create_directories(fs::path(occupied) / "inside");
  EXPECT_THROW(write_png(occupied, test_pattern(4, 4)), std::runtime_error);
  int files = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir_)) ++files;
  EXPECT_EQ(files, 1);  // only the directory itself
  Image inconsistent = test_pattern(4, 4);
  inconsistent.rgb.pop_back();
  EXPECT_THROW(write_png(path("bad.png"), inconsistent), std::invalid_argument);
  EXPECT_FALSE(fs::exists(path("bad.png")));
}

}  // namespace
}  // namespace clothsim::render
