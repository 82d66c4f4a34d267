#include "app/resources.hpp"

#include <system_error>

#ifndef CLOTHSIM_SOURCE_DIR
#error "CLOTHSIM_SOURCE_DIR must be defined (app/CMakeLists.txt)"
#endif

namespace clothsim {

std::filesystem::path resource_dir(std::string_view what) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path executable = fs::read_symlink("/proc/self/exe", ec);
  const fs::path installed =
      ec || executable.empty() ? fs::path() : executable.parent_path().parent_path() / "share" / "clothsim" / what;
  if (!installed.empty() && fs::is_directory(installed, ec)) return installed;
  const fs::path source = fs::path(CLOTHSIM_SOURCE_DIR) / what;
  if (fs::is_directory(source, ec)) return source;
  return installed.empty() ? source : installed;
}

}  // namespace clothsim
