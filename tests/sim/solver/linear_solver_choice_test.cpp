// "auto" solver settings (resolve_automatic): what the default picks, and that named settings
// are kept.
#include "sim/solver/linear_solver.hpp"

#include <gtest/gtest.h>

#include <string>

namespace clothsim {
namespace {

TEST(LinearSolverChoice, DefaultsAreAutomaticAndResolveToTheCholeskyPreconditionedCg) {
  const LinearSolverSettings defaults;
  EXPECT_EQ(defaults.type, LinearSolverType::automatic);
  EXPECT_EQ(defaults.preconditioner, PreconditionerType::automatic);
  for (Eigen::Index unknowns : {Eigen::Index{3}, Eigen::Index{7626}, Eigen::Index{300000}}) {
    const LinearSolverSettings s = resolve_automatic(defaults, unknowns);
    EXPECT_EQ(s.type, LinearSolverType::pcg) << unknowns;
    EXPECT_EQ(s.preconditioner, PreconditionerType::cholesky) << unknowns;
    EXPECT_EQ(s.tolerance, defaults.tolerance);
    EXPECT_EQ(s.max_iterations, defaults.max_iterations);
  }
}

TEST(LinearSolverChoice, NamedSettingsAreKept) {
  LinearSolverSettings named;
  named.type = LinearSolverType::pcg;
  named.preconditioner = PreconditionerType::block_jacobi;
  named.tolerance = 1e-6;
  const LinearSolverSettings s = resolve_automatic(named, 7626);
  EXPECT_EQ(s.type, LinearSolverType::pcg);
  EXPECT_EQ(s.preconditioner, PreconditionerType::block_jacobi);
  EXPECT_EQ(s.tolerance, 1e-6);
  named.type = LinearSolverType::cholmod;
  EXPECT_EQ(resolve_automatic(named, 7626).type, LinearSolverType::cholmod);
  // Only the preconditioner left automatic: the named type stays.
  named.type = LinearSolverType::pcg;
  named.preconditioner = PreconditionerType::automatic;
  EXPECT_EQ(resolve_automatic(named, 7626).preconditioner, PreconditionerType::cholesky);
}

TEST(LinearSolverChoice, TheSolverReportsTheResolvedSettings) {
  const LinearSolver solver(LinearSolverSettings{}, 300);
  EXPECT_EQ(solver.settings().type, LinearSolverType::pcg);
  EXPECT_EQ(solver.settings().preconditioner, PreconditionerType::cholesky);
}

TEST(LinearSolverChoice, SceneFileNames) {
  EXPECT_EQ(std::string(to_string(LinearSolverType::automatic)), "auto");
  EXPECT_EQ(std::string(to_string(LinearSolverType::pcg)), "pcg");
  EXPECT_EQ(std::string(to_string(LinearSolverType::cholmod)), "cholmod");
  EXPECT_EQ(std::string(to_string(PreconditionerType::automatic)), "auto");
  EXPECT_EQ(std::string(to_string(PreconditionerType::block_jacobi)), "block_jacobi");
  EXPECT_EQ(std::string(to_string(PreconditionerType::cholesky)), "cholesky");
}

}  // namespace
}  // namespace clothsim
