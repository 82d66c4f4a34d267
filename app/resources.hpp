// Where clothsim finds the files it ships with: the plotting scripts (scripts/) and the scenes the
// studies and `clothsim figures` start from (scenes/, with the meshes they reference).
#pragma once

#include <filesystem>
#include <string_view>

namespace clothsim {

// The folder `what` ("scripts" or "scenes"), looked up in this order:
//  1. <folder of the running executable>/../share/clothsim/<what>: an installed clothsim
//     (`cmake --install`: <prefix>/bin/clothsim and <prefix>/share/clothsim/), wherever the
//     prefix was installed or moved to;
//  2. <source tree>/<what>: a clothsim run from its build folder (the source tree it was built
//     from, compiled in as CLOTHSIM_SOURCE_DIR).
// The first that is a folder is returned; if neither is, the installed location (or the source
// one when the executable cannot be located), so that error messages name a path.
std::filesystem::path resource_dir(std::string_view what);

}  // namespace clothsim
