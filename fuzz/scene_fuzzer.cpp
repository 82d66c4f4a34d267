// libFuzzer target: the scene loader (load_scene_text) on arbitrary bytes, as a scene file in a
// private temporary folder that holds the only OBJ files a scene may name. See docs/fuzzing.md.
#include "fuzz/fuzz_inputs.hpp"

#include <stdlib.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>
#include <system_error>

namespace {

std::filesystem::path g_dir;

void remove_dir() {
  std::error_code ec;
  std::filesystem::remove_all(g_dir, ec);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  std::string pattern = (std::filesystem::temp_directory_path() / "clothsim_fuzz_scene_XXXXXX").string();
  if (::mkdtemp(pattern.data()) == nullptr) {
    std::perror("fuzz_scene: mkdtemp");
    std::abort();
  }
  g_dir = pattern;
  clothsim::fuzz::write_scene_obj_files(g_dir);
  std::atexit(remove_dir);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  clothsim::fuzz::run_scene_input(std::string_view(reinterpret_cast<const char*>(data), size), g_dir);
  return 0;
}
