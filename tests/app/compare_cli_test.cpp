// clothsim compare A B: two PNG files or two folders of PNGs compared pairwise by name, through
// the built binary: identical and changed images, the tolerance options, the difference image
// (file and folder), size mismatches, images present on one side only, and the exit codes
// (0 same, 1 different, 2 usage or input errors) with messages naming the file or option.
#include "render/image.hpp"
#include "render/png_io.hpp"

#include "tests/support/cli_fixture.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <string>

namespace clothsim {
namespace {

namespace fs = std::filesystem;
using testing::CliResult;
using testing::contains;

// A w × h gradient.
render::Image gradient(int w, int h) {
  render::Image image;
  image.width = w;
  image.height = h;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) image.rgb.push_back(static_cast<std::uint8_t>((7 * x + 11 * y + 50 * c) % 256));
  return image;
}

// `image` with the red channel of its first `n` pixels changed by `by` (0 < by < 128): up, or
// down where up would pass 255.
render::Image changed(render::Image image, int n, int by) {
  for (std::size_t i = 0; i < 3 * static_cast<std::size_t>(n); i += 3) {
    const int v = image.rgb[i];
    image.rgb[i] = static_cast<std::uint8_t>(v + by <= 255 ? v + by : v - by);
  }
  return image;
}

class CompareCliTest : public testing::CliFixture {
 protected:
  fs::path png(const std::string& name, const render::Image& image) const {
    const fs::path path = dir_ / name;
    fs::create_directories(path.parent_path());
    render::write_png(path.string(), image);
    return path;
  }
};

TEST_F(CompareCliTest, IdenticalFilesAreTheSame) {
  const fs::path a = png("a.png", gradient(40, 30)), b = png("b.png", gradient(40, 30));
  const CliResult r = run("compare " + q(a) + " " + q(b));
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_TRUE(contains(r.out, "a.png vs b.png: same, 40x30, largest channel difference 0, mean 0.000, 0.000 % of the "
                              "pixels (0) differ by more than 8"))
      << r.out;
}

// 12 of 1200 pixels (1 %) changed by 100: different with the default tolerance (0.5 %), the same
// with --max-differing 1 or --tolerance 100; a change of 8 is within the default channel tolerance.
TEST_F(CompareCliTest, ChangedPixelsAgainstTheTolerance) {
  const fs::path a = png("a.png", gradient(40, 30)), b = png("b.png", changed(gradient(40, 30), 12, 100));
  CliResult r = run("compare " + q(a) + " " + q(b));
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_TRUE(contains(r.out, "DIFFERENT, 40x30, largest channel difference 100, mean 0.333, 1.000 % of the pixels (12) "
                              "differ by more than 8"))
      << r.out;
  r = run("compare " + q(a) + " " + q(b) + " --max-differing 1");
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  r = run("compare " + q(a) + " " + q(b) + " --tolerance 100");
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  r = run("compare " + q(a) + " " + q(b) + " --tolerance 99");
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  const fs::path c = png("c.png", changed(gradient(40, 30), 1200, 8));
  r = run("compare " + q(a) + " " + q(c));
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_TRUE(contains(r.out, "largest channel difference 8")) << r.out;
  r = run("compare " + q(a) + " " + q(c) + " --tolerance 7");
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
}

TEST_F(CompareCliTest, DiffImageOfTwoFiles) {
  const fs::path a = png("a.png", gradient(40, 30)), b = png("b.png", changed(gradient(40, 30), 12, 10));
  const fs::path diff = dir_ / "diff.png";
  const CliResult r = run("compare " + q(a) + " " + q(b) + " --diff " + q(diff));
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_TRUE(contains(r.out, diff.string())) << r.out;
  const render::Image d = render::read_png(diff.string());
  ASSERT_EQ(d.width, 40);
  ASSERT_EQ(d.height, 30);
  EXPECT_EQ(d.rgb[0], 40);  // 4 x 10
  EXPECT_EQ(d.rgb[1], 0);
  EXPECT_EQ(d.rgb[3 * 12], 0);  // the 13th pixel is unchanged
}

TEST_F(CompareCliTest, SizeMismatchIsADifference) {
  const fs::path a = png("a.png", gradient(40, 30)), b = png("b.png", gradient(30, 40));
  const fs::path diff = dir_ / "diff.png";
  const CliResult r = run("compare " + q(a) + " " + q(b) + " --diff " + q(diff));
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_TRUE(contains(r.out, "DIFFERENT: size 40x30 vs 30x40")) << r.out;
  EXPECT_TRUE(contains(r.out, "no difference image: the sizes differ")) << r.out;
  EXPECT_FALSE(fs::exists(diff));
}

TEST_F(CompareCliTest, InputErrorsExitTwoNamingTheFile) {
  const fs::path a = png("a.png", gradient(40, 30));
  const fs::path missing = dir_ / "missing.png";
  CliResult r = run("compare " + q(a) + " " + q(missing));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.err, "clothsim: error: " + missing.string() + ": no such file or folder")) << r.err;
  const fs::path corrupt = write("corrupt.png", "not a png");
  r = run("compare " + q(a) + " " + q(corrupt));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.err, corrupt.string())) << r.err;
  fs::create_directories(dir_ / "folder");
  r = run("compare " + q(a) + " " + q(dir_ / "folder"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.err, "compare two PNG files or two folders")) << r.err;
  r = run("compare " + q(a) + " " + q(a) + " --tolerance 300");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.err, "--tolerance")) << r.err;
  r = run("compare " + q(a) + " " + q(a) + " --max-differing -1");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  r = run("compare " + q(a));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.err, "clothsim: error: ")) << r.err;
  r = run("compare " + q(a) + " " + q(a) + " --diff " + q(dir_ / "folder"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.err, "--diff: ")) << r.err;
  r = run("compare --help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_TRUE(contains(r.out, "--max-differing")) << r.out;
}

// Two run folders: frames compared by name, a frame in one folder only is a difference, other
// files are ignored; --diff DIR gets one image per pair and compare.txt, and is replaced by the
// next comparison; a folder that compare did not write is refused and left alone.
TEST_F(CompareCliTest, Folders) {
  png("a/frame_0000.png", gradient(40, 30));
  png("a/frame_0001.png", gradient(40, 30));
  png("b/frame_0000.png", gradient(40, 30));
  png("b/frame_0001.png", gradient(40, 30));
  write("a/summary.json", "{}");
  CliResult r = run("compare " + q(dir_ / "a") + " " + q(dir_ / "b"));
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_TRUE(contains(r.out, "frame_0000.png: same")) << r.out;
  EXPECT_TRUE(contains(r.out, "compare: 2 image(s): 2 the same, 0 different")) << r.out;

  png("b/frame_0001.png", changed(gradient(40, 30), 100, 50));
  png("b/frame_0002.png", gradient(40, 30));
  png("a/limit.png", gradient(40, 30));
  png("b/limit.png", gradient(20, 30));
  const fs::path diff = dir_ / "diff";
  r = run("compare " + q(dir_ / "a") + " " + q(dir_ / "b") + " --diff " + q(diff));
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_TRUE(contains(r.out, "frame_0000.png: same")) << r.out;
  EXPECT_TRUE(contains(r.out, "frame_0001.png: DIFFERENT, 40x30")) << r.out;
  EXPECT_TRUE(contains(r.out, "frame_0002.png: DIFFERENT: only in B")) << r.out;
  EXPECT_TRUE(contains(r.out, "limit.png: DIFFERENT: size 40x30 vs 20x30")) << r.out;
  EXPECT_TRUE(contains(r.out, "compare: 4 image(s): 1 the same, 3 different")) << r.out;
  EXPECT_TRUE(fs::exists(diff / "frame_0000.png"));
  EXPECT_EQ(render::read_png((diff / "frame_0001.png").string()).rgb[0], 200);  // 4 x 50
  EXPECT_FALSE(fs::exists(diff / "frame_0002.png"));
  EXPECT_FALSE(fs::exists(diff / "limit.png"));
  EXPECT_TRUE(contains(testing::read_file_bytes(diff / "compare.txt"), "frame_0002.png: DIFFERENT: only in B"));

  fs::remove(dir_ / "b/frame_0002.png");
  r = run("compare " + q(dir_ / "b") + " " + q(dir_ / "a") + " --diff " + q(diff));  // replaces diff/
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_TRUE(contains(r.out, "limit.png: DIFFERENT: size 20x30 vs 40x30")) << r.out;
  EXPECT_FALSE(contains(testing::read_file_bytes(diff / "compare.txt"), "only in B"));

  write("mine/notes.txt", "keep me");
  r = run("compare " + q(dir_ / "a") + " " + q(dir_ / "b") + " --diff " + q(dir_ / "mine"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.err, "--diff: " + (dir_ / "mine").string() + " exists and was not written by this command"))
      << r.err;
  EXPECT_EQ(testing::read_file_bytes(dir_ / "mine/notes.txt"), "keep me");
  EXPECT_FALSE(fs::exists(dir_ / "mine/compare.txt"));

  fs::create_directories(dir_ / "empty1");
  fs::create_directories(dir_ / "empty2");
  r = run("compare " + q(dir_ / "empty1") + " " + q(dir_ / "empty2"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.err, "hold no PNG images")) << r.err;
}

}  // namespace
}  // namespace clothsim
