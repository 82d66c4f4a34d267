// `clothsim fabric-test` as a user runs it (app/fabric_test.cpp, docs/fabric_test.md): a quick
// run publishes the report whole with a picture per test and the measured values of the preset's
// source; bad input names the option or the preset, exits 1 and leaves no folder.
#include "tests/support/process.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace clothsim {
namespace {

namespace fs = std::filesystem;
using testing::make_temp_dir;
using testing::read_file_bytes;
using testing::run_shell;
using testing::shell_quote;

const std::string kClothsim = CLOTHSIM_BINARY;

TEST(FabricTestCli, QuickRunWritesTheReportAndPictures) {
  const fs::path tmp = make_temp_dir("fabric_test_cli");
  ASSERT_EQ(run_shell(shell_quote(kClothsim) + " fabric-test polyester_faille_ortho --quick --out " + shell_quote(tmp.string()) +
                      " 2>/dev/null >/dev/null"),
            0);
  const fs::path dir = tmp / "fabric_test_polyester_faille_ortho";
  for (const char* f : {"fabric_test.md", "fabric_test.csv", "cantilever_warp.png", "cantilever_weft.png", "tensile_warp.png",
                        "tensile_weft.png", "tensile_bias.png", "cusick_r6.png", "cusick_r8.png"})
    EXPECT_TRUE(fs::exists(dir / f)) << f;
  const std::string csv = read_file_bytes(dir / "fabric_test.csv");
  EXPECT_EQ(csv.rfind("test,direction_deg,quantity,unit,virtual,law,measured\n", 0), 0u);
  // The faille's measured Cusick values stand beside the virtual ones.
  EXPECT_NE(csv.find("cusick,0,drape_coefficient,-,"), std::string::npos);
  EXPECT_NE(csv.find(",0.283\n"), std::string::npos);
  EXPECT_NE(csv.find(",7\n"), std::string::npos);
  // Nothing temporary is left next to it.
  for (const auto& e : fs::directory_iterator(tmp)) EXPECT_EQ(e.path().filename().string().rfind(".", 0), std::string::npos);
  fs::remove_all(tmp);
}

TEST(FabricTestCli, SceneFileMaterialAndOneTest) {
  const fs::path tmp = make_temp_dir("fabric_test_scene");
  std::ofstream(tmp / "woven.json") << R"({"name": "x", "analysis": "static", "mesh": {"primitive": "grid", "size": [1, 1], "divisions": [2, 2]},
    "material": {"stretch_modulus": {"warp": 5000, "weft": 3000, "shear": 60, "poisson": 0.25},
                 "bending_rigidity": {"warp": 1.2e-5, "weft": 0.9e-5, "twist": 0.5e-5}, "areal_density": 0.12,
                 "grain": {"warp_deg": 30}}})";
  ASSERT_EQ(run_shell(shell_quote(kClothsim) + " fabric-test " + shell_quote((tmp / "woven.json").string()) +
                      " --tests bias --quick --no-render --out " + shell_quote(tmp.string()) + " 2>/dev/null >/dev/null"),
            0);
  const std::string csv = read_file_bytes(tmp / "fabric_test_woven" / "fabric_test.csv");
  EXPECT_NE(csv.find("tensile,45,stretch_modulus"), std::string::npos);
  EXPECT_NE(csv.find("bias,45,shear_modulus,N/m,"), std::string::npos);
  EXPECT_EQ(csv.find("cantilever"), std::string::npos);
  // Three Cusick meshes: DC extrapolated to zero element size as well.
  ASSERT_EQ(run_shell(shell_quote(kClothsim) + " fabric-test " + shell_quote((tmp / "woven.json").string()) +
                      " --tests cusick --quick --rings 5,6,7 --no-render --out " + shell_quote((tmp / "c").string()) +
                      " 2>/dev/null >/dev/null"),
            0);
  const std::string cusick = read_file_bytes(tmp / "c" / "fabric_test_woven" / "fabric_test.csv");
  EXPECT_NE(cusick.find("cusick,0,drape_coefficient_extrapolated,-,"), std::string::npos) << cusick;
  EXPECT_NE(read_file_bytes(tmp / "c" / "fabric_test_woven" / "fabric_test.md").find("Extrapolated to zero element size"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(tmp / "fabric_test_woven" / "tensile_bias.png"));  // --no-render
  // By default the specimen is clamped (an annulus held up to the rim); --loose lays the whole
  // disc on the support.
  const std::string clamped = read_file_bytes(tmp / "c" / "fabric_test_woven" / "runs" / "cusick_r5.json");
  EXPECT_NE(clamped.find("\"ball\""), std::string::npos) << clamped;
  EXPECT_NE(read_file_bytes(tmp / "c" / "fabric_test_woven" / "fabric_test.md").find("clamped between the support disc"),
            std::string::npos);
  ASSERT_EQ(run_shell(shell_quote(kClothsim) + " fabric-test " + shell_quote((tmp / "woven.json").string()) +
                      " --tests cusick --quick --loose --rings 4,5 --no-render --out " + shell_quote((tmp / "l").string()) +
                      " 2>/dev/null >/dev/null"),
            0);
  const std::string loose = read_file_bytes(tmp / "l" / "fabric_test_woven" / "runs" / "cusick_r5.json");
  EXPECT_EQ(loose.find("\"boundary\""), std::string::npos) << loose;
  EXPECT_NE(read_file_bytes(tmp / "l" / "fabric_test_woven" / "fabric_test.md").find("lying loose on a support disc"),
            std::string::npos);
  fs::remove_all(tmp);
}

TEST(FabricTestCli, BadInputNamesTheProblemAndWritesNothing) {
  const fs::path tmp = make_temp_dir("fabric_test_bad");
  const auto fails_with = [&](const std::string& args, const std::string& message) {
    const fs::path err = tmp / "err.txt";
    const int code = run_shell(shell_quote(kClothsim) + " fabric-test " + args + " --out " + shell_quote((tmp / "out").string()) +
                               " >/dev/null 2>" + shell_quote(err.string()));
    EXPECT_EQ(code, 1) << args;
    EXPECT_NE(read_file_bytes(err).find(message), std::string::npos) << args << ": " << read_file_bytes(err);
    EXPECT_FALSE(fs::exists(tmp / "out")) << args;
  };
  fails_with("no_such_cloth", "material.preset");
  fails_with("cotton --tests cantilever,drape", "--tests: no test \"drape\"");
  fails_with("cotton --rings 24,16", "--rings");
  fails_with("cotton --rings 16,x", "--rings");
  fails_with("cotton --rings ,", "--rings: give at least one mesh");
  fails_with("cotton --imperfection -0.001", "--imperfection");
  fails_with("cotton --ramp -1", "--ramp");
  fails_with(shell_quote((tmp / "missing.json").string()), "missing.json");
  fs::remove_all(tmp);
}

}  // namespace
}  // namespace clothsim
