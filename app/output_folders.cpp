#include "app/output_folders.hpp"

#include "app/plotting.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

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

void check_folder_possible(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::path p = dir;
  while (!p.empty() && !std::filesystem::exists(p, ec) && p != p.parent_path()) p = p.parent_path();
  if (!p.empty() && std::filesystem::exists(p, ec) && !std::filesystem::is_directory(p, ec))
    throw std::runtime_error(dir.string() + ": cannot be a folder, " + p.string() + " is not a folder");
}

std::vector<std::filesystem::path> files_like(const std::filesystem::path& dir, const std::string& prefix,
                                              const std::string& suffix) {
  std::vector<std::filesystem::path> found;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.size() >= prefix.size() + suffix.size() && name.compare(0, prefix.size(), prefix) == 0 &&
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0)
      found.push_back(e.path());
  }
  std::sort(found.begin(), found.end());
  return found;
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
  std::error_code ec;
  try {
    write_text_file(tmp, text);
  } catch (...) {
    std::filesystem::remove(tmp, ec);  // a disk-full write leaves no half-written temporary behind
    throw;
  }
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

namespace clothsim {

namespace {
// The PID written in a lock file, or "".
std::string read_lock_pid(int fd) {
  char buffer[32] = {};
  const ssize_t n = ::pread(fd, buffer, sizeof(buffer) - 1, 0);
  if (n <= 0) return "";
  std::string pid(buffer, static_cast<std::size_t>(n));
  while (!pid.empty() && (pid.back() == '\n' || pid.back() == ' ')) pid.pop_back();
  return pid;
}
}  // namespace

bool process_alive(long pid) {
  if (pid <= 0) return false;
  return ::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH;
}

OutputLock::OutputLock(const std::filesystem::path& out_root, const std::string& name) {
  namespace fs = std::filesystem;
  fs::create_directories(out_root);
  std::string lock_name = ".";  // built with += (GCC 12 warns falsely on "." + std::string&&)
  lock_name += name;
  lock_name += ".lock";
  path_ = out_root / lock_name;
  // Another run may remove the lock file between our open() and flock(); then the lock we hold is
  // on a file that no longer has the name, so try again with a fresh one.
  for (int attempt = 0; attempt < 100; ++attempt) {
    const int fd = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0)
      throw std::runtime_error(path_.string() + ": cannot create the lock file of the output folder: " +
                               std::strerror(errno));
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int error = errno;
      const std::string pid = read_lock_pid(fd);
      ::close(fd);
      if (error == EWOULDBLOCK)
        throw std::runtime_error("the output folder " + (out_root / name).string() +
                                 " is in use by another clothsim run" + (pid.empty() ? "" : " (PID " + pid + ")") +
                                 "; wait for it to finish or choose another --out (lock file " + path_.string() + ")");
      throw std::runtime_error(path_.string() + ": cannot lock the output folder: " + std::strerror(error));
    }
    struct stat held {}, named {};
    if (::fstat(fd, &held) == 0 && ::stat(path_.c_str(), &named) == 0 && held.st_ino == named.st_ino &&
        held.st_dev == named.st_dev) {
      const std::string pid = std::to_string(static_cast<long>(::getpid())) + "\n";
      if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, pid.data(), pid.size(), 0) != static_cast<ssize_t>(pid.size())) {
        // The PID is only for the message of a run that finds the folder busy; the lock holds anyway.
      }
      fd_ = fd;
      return;
    }
    ::close(fd);
  }
  throw std::runtime_error(path_.string() + ": cannot lock the output folder (the lock file keeps changing)");
}

OutputLock::~OutputLock() {
  if (fd_ < 0) return;
  ::unlink(path_.c_str());  // while still holding the lock (see the constructor's retry)
  ::close(fd_);
}

std::vector<std::string> remove_dead_temporaries(const std::filesystem::path& out_root) {
  namespace fs = std::filesystem;
  std::vector<std::string> removed;
  std::error_code ec;
  const long own = static_cast<long>(::getpid());
  for (fs::directory_iterator it(out_root, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() < 2 || name[0] != '.') continue;
    // ".<name>.tmp-<pid>[-...]" or ".<name>.old-<pid>"
    std::size_t marker = name.rfind(".tmp-");
    if (marker == std::string::npos) marker = name.rfind(".old-");
    if (marker == std::string::npos || marker == 0) continue;
    const std::size_t digits = marker + 5;
    std::size_t stop = digits;
    while (stop < name.size() && name[stop] >= '0' && name[stop] <= '9') ++stop;
    if (stop == digits || stop - digits > 9 || (stop != name.size() && name[stop] != '-')) continue;
    const long pid = std::stol(name.substr(digits, stop - digits));
    if (pid == own || process_alive(pid)) continue;
    std::error_code remove_error;
    fs::remove_all(it->path(), remove_error);
    if (!remove_error)
      removed.push_back("removed " + it->path().string() + ", left by a run that is no longer running (PID " +
                        std::to_string(pid) + ")");
  }
  return removed;
}

int remove_temporary_files(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  int removed = 0;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() > 1 && name[0] == '.' && name.find(".tmp") != std::string::npos &&
        it->is_regular_file(ec)) {
      std::error_code remove_error;
      if (fs::remove(it->path(), remove_error)) ++removed;
    }
  }
  return removed;
}

bool overwrite_in_place(const std::filesystem::path& path, const std::string& text) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) return false;
  struct stat st {};
  if (::fstat(fd, &st) != 0 || static_cast<std::uintmax_t>(st.st_size) < text.size()) {
    ::close(fd);
    return false;
  }
  std::string padded = text;
  padded.resize(static_cast<std::size_t>(st.st_size), ' ');
  if (padded.size() > text.size()) padded.back() = '\n';
  const bool ok = ::pwrite(fd, padded.data(), padded.size(), 0) == static_cast<ssize_t>(padded.size());
  return ::close(fd) == 0 && ok;
}

}  // namespace clothsim
