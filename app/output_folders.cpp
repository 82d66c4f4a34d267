#include "app/output_folders.hpp"

#include "app/plotting.hpp"

#include <unistd.h>

#include <cstdint>
#include <fstream>
#include <iostream>
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

std::string publish_report(const std::filesystem::path& out_root, const std::string& folder,
                           const std::vector<ReportFile>& files, bool plot, const std::string& plot_script,
                           const std::string& png) {
  namespace fs = std::filesystem;
  std::string staging_name = ".";  // built with += (GCC 12 warns falsely on "." + std::string&&)
  staging_name += folder;
  staging_name += ".tmp-";
  staging_name += std::to_string(static_cast<long>(::getpid()));
  const fs::path staging = out_root / staging_name;
  const std::vector<fs::path> created = missing_folders(out_root);
  try {
    fs::create_directories(out_root);
    fs::remove_all(staging);
    fs::create_directory(staging);
    for (const ReportFile& f : files) write_text_file(staging / f.name, f.text);
    std::string plot_error;
    if (plot && !files.empty())
      plot_error = run_plot_script(plot_script, {(staging / files.front().name).string(), (staging / png).string()});
    if (const std::string warning = replace_folder(staging, out_root / folder); !warning.empty())
      std::cerr << "clothsim: warning: " << warning << '\n';
    return plot_error;
  } catch (...) {
    std::error_code ec;
    fs::remove_all(staging, ec);
    for (const fs::path& dir : created) fs::remove(dir, ec);  // deepest first; only if still empty
    throw;
  }
}

}  // namespace clothsim
