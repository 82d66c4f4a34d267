#include "app/plotting.hpp"

#include "app/resources.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace clothsim {

std::string run_plot_script(const std::string& script, const std::vector<std::string>& args) {
  const std::string python = "/usr/bin/python3";
  const std::filesystem::path path = resource_dir("scripts") / script;
  std::error_code ec;
  if (!std::filesystem::exists(python, ec))
    return python + " not found; install Debian's python3-matplotlib (scripts/install_deps.sh)";
  if (!std::filesystem::exists(path, ec)) return "plotting script " + path.string() + " not found";
  std::vector<std::string> argv_storage = {python, path.string()};
  argv_storage.insert(argv_storage.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_storage) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0) return std::string("cannot start ") + python + ": " + std::strerror(errno);
  if (pid == 0) {
    execv(python.c_str(), argv.data());
    _exit(127);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return std::string("waiting for the plotting script failed: ") + std::strerror(errno);
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return "";
  if (WIFEXITED(status) && WEXITSTATUS(status) == 3)
    return "python3-matplotlib is not installed; run scripts/install_deps.sh";
  return path.filename().string() + " failed (exit status " +
         std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ")";
}

}  // namespace clothsim
