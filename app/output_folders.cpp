#include "app/output_folders.hpp"

#include <unistd.h>

#include <cstdint>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <system_error>

namespace clothsim {

std::vector<std::filesystem::path> missing_folders(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> missing;
  std::error_code ec;
  for (std::filesystem::path p = dir; !p.empty() && !std::filesystem::exists(p, ec); p = p.parent_path()) {
    missing.push_back(p);
    if (p == p.parent_path()) break;
  }
  return missing;
}

void write_text_file(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  out.close();
  if (!out) throw std::runtime_error(path.string() + ": cannot write the file");
}

void write_atomically(const std::filesystem::path& path, const std::string& text) {
  std::string name = ".";  // built with += (GCC 12 warns falsely on "." + std::string&&)
  name += path.filename().string();
  name += ".tmp-";
  name += std::to_string(static_cast<long>(::getpid()));
  const std::filesystem::path tmp = path.parent_path() / name;
  write_text_file(tmp, text);
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw std::runtime_error(path.string() + ": cannot write the file (rename failed)");
  }
}

std::string read_text_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + ": cannot read the file");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string replace_folder(const std::filesystem::path& staging, const std::filesystem::path& target) {
  namespace fs = std::filesystem;
  std::string old_name = ".";  // built with += (GCC 12 warns falsely on "." + std::string&&)
  old_name += target.filename().string();
  old_name += ".old-";
  old_name += std::to_string(static_cast<long>(::getpid()));
  const fs::path old = target.parent_path() / old_name;
  std::error_code ec;
  const bool replacing = fs::exists(fs::symlink_status(target));
  if (replacing) {
    fs::remove_all(old, ec);
    fs::rename(target, old);
  }
  try {
    fs::rename(staging, target);
  } catch (...) {
    if (replacing) fs::rename(old, target, ec);
    throw;
  }
  if (replacing && fs::remove_all(old, ec) == static_cast<std::uintmax_t>(-1))
    return "could not remove the previous output " + old.string() + ": " + ec.message();
  return "";
}

}  // namespace clothsim
