// Drawing a study's PNG with a plotting script from scripts/ (python3-matplotlib from Debian).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace clothsim {

// Runs `/usr/bin/python3 <scripts>/<script> <args...>` and waits for it, <scripts> being
// resource_dir("scripts") (app/resources.hpp). Returns an empty string on success, otherwise a
// message saying what failed (no python3, matplotlib missing, the script's exit status) and how
// to fix it.
std::string run_plot_script(const std::string& script, const std::vector<std::string>& args);

}  // namespace clothsim
