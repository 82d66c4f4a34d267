// libFuzzer target: the OBJ reader (read_obj_text) on arbitrary bytes. See docs/fuzzing.md.
#include "fuzz/fuzz_inputs.hpp"

#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  clothsim::fuzz::run_obj_input(std::string_view(reinterpret_cast<const char*>(data), size));
  return 0;
}
