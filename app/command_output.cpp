#include "app/command_output.hpp"

#include "app/output_folders.hpp"

#include <unistd.h>

#include <iostream>
#include <stdexcept>
#include <system_error>
#include <vector>

namespace clothsim {

namespace fs = std::filesystem;

fs::path output_folder_path(const fs::path& dir, const std::string& what) {
  if (dir.empty()) throw std::runtime_error(what + ": the folder must not be empty");
  fs::path p = fs::absolute(dir).lexically_normal();
  if (!p.has_filename() && p.has_relative_path()) p = p.parent_path();  // "out/" → "out"
  if (!p.has_relative_path()) throw std::runtime_error(what + ": " + dir.string() + ": cannot write the root folder");
  return p;
}

bool replaceable_folder(const fs::path& dir, const std::string& marker) {
  std::error_code ec;
  if (!fs::is_directory(fs::symlink_status(dir, ec))) return false;
  if (fs::is_empty(dir, ec) && !ec) return true;
  return fs::is_regular_file(fs::symlink_status(dir / marker, ec));
}

void publish_folder(const fs::path& target, const std::string& marker, const std::string& what,
                    const std::function<void(const fs::path&)>& write) {
  std::error_code ec;
  if (fs::exists(fs::symlink_status(target, ec)) && !replaceable_folder(target, marker))
    throw std::runtime_error(what + ": " + target.string() +
                             " exists and was not written by this command (it holds no " + marker +
                             "); choose a new folder or remove it");
  std::string name = ".";  // built with += (GCC 12 warns falsely on "." + std::string&&)
  name += target.filename().string();
  name += ".tmp-";
  name += std::to_string(static_cast<long>(::getpid()));
  const fs::path staging = target.parent_path() / name;
  const std::vector<fs::path> created = missing_folders(target.parent_path());
  try {
    fs::create_directories(target.parent_path());
    fs::remove_all(staging);
    fs::create_directory(staging);
    write(staging);
    if (!fs::is_regular_file(staging / marker))
      throw std::logic_error("publish_folder: the output of " + what + " lacks its " + marker);
    if (const std::string warning = replace_folder(staging, target); !warning.empty())
      std::cerr << "clothsim: warning: " << warning << '\n';
  } catch (...) {
    fs::remove_all(staging, ec);
    for (const fs::path& dir : created) fs::remove(dir, ec);  // deepest first; only if empty
    throw;
  }
}

bool remove_replaceable_folder(const fs::path& dir, const std::string& marker) {
  if (!replaceable_folder(dir, marker)) return false;
  std::error_code ec;
  fs::remove_all(dir, ec);
  return !ec;
}

}  // namespace clothsim
