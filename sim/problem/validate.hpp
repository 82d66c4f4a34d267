// The checks of a Problem that involve more than one value or the model (cross-field rules,
// boundary rules, couples' lever arms, selections against the mesh), each in this one place. The
// scene loader reports them with the file's name; the static and dynamic drivers run them on
// problems built in code. (Each single value's type and range is checked where the scene file is
// read, with the value as written.)
#pragma once

#include "sim/problem/problem.hpp"

#include <optional>
#include <string>

namespace clothsim {

enum class Analysis { statics, dynamics };

struct ProblemIssue {
  std::string key;      // key path in the scene format ("loads.moments[0].select")
  std::string message;  // what is wrong, and what to do
  std::string text() const { return key + ": " + message; }
};

// The first issue of `problem` for `analysis`, or none.
std::optional<ProblemIssue> find_issue(const Problem& problem, Analysis analysis);

// Throws std::runtime_error("key: message") for the first issue.
void check_problem(const Problem& problem, Analysis analysis);

}  // namespace clothsim
