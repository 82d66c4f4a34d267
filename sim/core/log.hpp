// The log callback through which the simulation core reports what it did (mesh preparation,
// selections): one line per call, no newline. The application decides where lines go.
#pragma once

#include <functional>
#include <string>

namespace clothsim {

using LogFn = std::function<void(const std::string&)>;

}  // namespace clothsim
