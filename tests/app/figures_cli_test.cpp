// `clothsim figures`: runs the built binary in quick mode (2-frame runs, tiny panels) into a fresh
// temporary folder and checks what it publishes — the montage's pixel size from the layout rule
// (columns × panel width; title + panel + label rows), the scene files as run (the material patch
// applied, the name set), figN.md and figures.md naming the shipped scene of each panel — that a
// second call reuses the completed runs and writes the same PNG bytes, and that bad arguments are
// errors that write nothing.
#include "sim/scene/scene.hpp"
#include "tests/support/process.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <stdlib.h>
#include <sys/wait.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace {

namespace fs = std::filesystem;
using clothsim::testing::read_file_bytes;
using clothsim::testing::run_shell;
using clothsim::testing::shell_quote;

// Width and height from a PNG's IHDR chunk (bytes 16–23, big-endian).
std::pair<uint32_t, uint32_t> png_size(const std::string& bytes) {
  EXPECT_GE(bytes.size(), 24u);
  EXPECT_EQ(bytes.substr(1, 3), "PNG");
  auto be32 = [&](size_t at) {
    return (uint32_t(uint8_t(bytes[at])) << 24) | (uint32_t(uint8_t(bytes[at + 1])) << 16) |
           (uint32_t(uint8_t(bytes[at + 2])) << 8) | uint32_t(uint8_t(bytes[at + 3]));
  };
  return {be32(16), be32(20)};
}

class FiguresCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = clothsim::testing::make_temp_dir("clothsim_figures_cli_");
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  int figures(const std::string& args) {
    const fs::path out_file = dir_ / "stdout.txt", err_file = dir_ / "stderr.txt";
    const int code = run_shell(shell_quote(CLOTHSIM_BINARY) + " figures " + args + " >" +
                               shell_quote(out_file.string()) + " 2>" + shell_quote(err_file.string()));
    out_ = read_file_bytes(out_file);
    err_ = read_file_bytes(err_file);
    return code;
  }
  fs::path dir_;
  std::string out_, err_;
};

TEST_F(FiguresCli, QuickFigure10IsPublishedLabelledAndReproducible) {
  if (!clothsim::testing::has_matplotlib())
    GTEST_SKIP() << "/usr/bin/python3 has no matplotlib (scripts/install_deps.sh installs python3-matplotlib)";
  const fs::path out = dir_ / "out";
  ASSERT_EQ(figures("10 --quick --size 64x48 --out " + shell_quote(out.string())), 0) << err_;
  const fs::path root = out / "figures";
  const std::string png = read_file_bytes(root / "fig10.png");
  // Fig. 10 has 4 panels in one row: 4 × 64 px wide; 40 px title + 48 px panel + 58 px labels high.
  const auto [width, height] = png_size(png);
  EXPECT_EQ(width, 4u * 64u);
  EXPECT_EQ(height, 40u + 48u + 58u);

  // The scene as run: the shipped sleeve_catenary.json with the material replaced and the name set.
  const clothsim::Scene shipped = clothsim::load_scene(fs::path(CLOTHSIM_SOURCE_DIR) / "scenes/sleeve_catenary.json", {});
  const clothsim::Scene knit = clothsim::load_scene(root / "scenes/catenary_gray_interlock.json", {});
  EXPECT_EQ(knit.name, "catenary_gray_interlock");
  EXPECT_NEAR(knit.problem.material.stretch_modulus, 23.93, 0.005);  // the gray_interlock preset's E·t (table: 4 digits)
  EXPECT_NE(knit.problem.material.stretch_modulus, shipped.problem.material.stretch_modulus);
  EXPECT_EQ(knit.problem.mesh.num_vertices(), 494);
  EXPECT_TRUE(fs::exists(root / "runs/catenary_mesh/frame_0000.png"));

  const std::string md = read_file_bytes(root / "fig10.md");
  EXPECT_NE(md.find("`scenes/sleeve_catenary.json`, with `{\"material\":{\"preset\":\"gray_interlock\"}}`"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("Quick mode"), std::string::npos);
  const std::string index = read_file_bytes(root / "figures.md");
  EXPECT_NE(index.find(md), std::string::npos);
  for (const auto& entry : fs::directory_iterator(root))
    EXPECT_NE(entry.path().filename().string().front(), '.') << "temporary file left: " << entry.path();

  // Again: every run is reused (same scene, same options) and the montage is byte-identical.
  ASSERT_EQ(figures("10 --quick --size 64x48 --out " + shell_quote(out.string())), 0) << err_;
  EXPECT_NE(err_.find("run catenary_gray_interlock: reusing"), std::string::npos) << err_;
  EXPECT_EQ(read_file_bytes(root / "fig10.png"), png);
}

TEST_F(FiguresCli, BadArgumentsAreErrorsThatWriteNothing) {
  const fs::path out = dir_ / "out";
  EXPECT_EQ(figures("2 --out " + shell_quote(out.string())), 1);
  EXPECT_NE(err_.find("no figure 2 (allowed: 1 7 8 9 10 11 12)"), std::string::npos) << err_;
  EXPECT_EQ(figures("7 --size 64x48abc --out " + shell_quote(out.string())), 1);
  EXPECT_NE(err_.find("--size"), std::string::npos) << err_;
  EXPECT_EQ(figures("seven --out " + shell_quote(out.string())), 1);
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
