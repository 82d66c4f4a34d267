// `clothsim fabric-test PRESET|SCENE.json [--tests cantilever,bias,cusick] [--out DIR]`: the
// standard fabric tests run virtually on a material (sim/study/fabric_tests.hpp,
// docs/fabric_test.md). Writes DIR/fabric_test_<name>/ whole or not at all: fabric_test.md (the
// table, beside each result the law's value and the measured one where the preset's source has
// one), fabric_test.csv, a picture per test and runs/ (the scenes and run folders behind them).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace clothsim {

struct FabricTestOptions {
  std::string target;                             // a preset name or a scene file (.json)
  std::vector<std::string> tests = {"cantilever", "bias", "cusick"};
  std::filesystem::path out_root = "out";
  std::vector<int> rings;                         // Cusick meshes, coarse to fine (empty: default_cusick_rings)
  double cusick_end = 3.0;                        // [s]
  double cusick_ramp = 0.0;                       // Cusick: gravity ramped in over this time [s] (0: at once)
  double imperfection = 0.0;                      // Cusick: seeded imperfection amplitude [m] (0: none)
  bool loose = false;                             // Cusick: the specimen lies loose on the support (no upper disc)
  bool quick = false;                             // coarse and short (seconds; for tests)
  bool render = true;
};

// Returns the exit code: 0, or 1 with "clothsim: error: ..." on stderr (bad options, a material
// that cannot be read, a run that fails) and no folder written.
int run_fabric_test(const FabricTestOptions& options);

}  // namespace clothsim
