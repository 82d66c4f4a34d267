// Preconditioners for the sleeve's implicit-Euler systems (written by sleeve_systems), compared in
// one conjugate-gradient loop: set-up time, iterations and time to relative residuals 1e-4, 1e-6
// and 1e-8, memory (docs/performance.md, "Multilevel preconditioners").
//
//   multilevel_bench --systems DIR --setup 20 --solve 20,21,23,25 --candidates cholesky,block_jacobi,...
//                    [--repeat 3] [--threads 2] [--max-iterations 1000]
//                    [--petsc LABEL "OPTIONS"]...      (with PETSc: candidate petsc:LABEL)
//                    [--multilevel LABEL "KEY=VALUE ..."]... (candidate ml:LABEL, sim/solver/multilevel_preconditioner.hpp;
//                                                             mcm:LABEL, the stale Cholesky factor between two V-cycles)
//                    (candidate warped: the stale factor turned per vertex with the cloth, z = Q C⁻¹ Qᵀ r)
//                    [--timing ROUNDS]   unit costs (product with A, applications, set-ups, refreshes) timed
//                                        in alternation, ROUNDS rounds, medians
//
// Every candidate is set up on DIR/step_<setup>.sys and then preconditions the solve of each
// DIR/step_<solve>.sys (a later step: the preconditioner is stale, as the simulator uses it). The
// conjugate gradients are the project's (sim/solver/pcg.cpp: same start, same residual norm
// relative to |b| on the free rows, product with A by symmetric_product on the TBB threads);
// only the preconditioner differs. Times are medians over --repeat runs; iteration counts do not
// vary. Memory: the growth of the resident set over the set-up (after malloc_trim), which counts
// what the set-up keeps and its allocator's leftovers.
#include "bench/system_io.hpp"
#include "sim/solver/cholesky_preconditioner.hpp"
#include "sim/solver/multilevel_preconditioner.hpp"
#include "sim/solver/pcg.hpp"

#include <Eigen/Dense>

#include <malloc.h>
#include <sys/resource.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#ifdef CLOTHSIM_HAVE_PETSC
#include <petscksp.h>
#endif

namespace clothsim {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

double resident_mib() {
  std::ifstream in("/proc/self/statm");
  long size = 0, resident = 0;
  in >> size >> resident;
  return static_cast<double>(resident) * 4096.0 / (1024.0 * 1024.0);
}

double peak_mib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

// Median wall time of `repeats` products with the system's matrix (symmetric_product, both cores) [ms].
double product_time(const bench::StepSystem& system, int repeats) {
  const Eigen::VectorXd mask = free_mask(system.free);
  Eigen::VectorXd y;
  std::vector<double> t;
  for (int k = 0; k < repeats; ++k) {
    const auto t0 = Clock::now();
    symmetric_product(system.a, system.start, mask, y);
    t.push_back(ms_since(t0));
  }
  return median(t);
}

// ---------------------------------------------------------------------------------------------
// Candidates

class Candidate {
 public:
  virtual ~Candidate() = default;
  virtual void setup(const bench::StepSystem& s) = 0;
  virtual void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) = 0;
  virtual std::string info() const { return ""; }
  // Brings the preconditioner up to a later step's matrix without a whole set-up (false: cannot).
  virtual bool refresh(const bench::StepSystem&) { return false; }
};

class BlockJacobiCandidate final : public Candidate {
 public:
  void setup(const bench::StepSystem& s) override { p_ = block_jacobi(s.a, s.free); }
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) override { p_(r, z); }

 private:
  Preconditioner p_;
};

class CholeskyCandidate final : public Candidate {
 public:
  void setup(const bench::StepSystem& s) override {
    if (!factor_.factorize(s.a, &s.free)) throw std::runtime_error("cholesky: not positive definite");
  }
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) override { factor_.apply(r, z); }
  std::string info() const override {
    std::ostringstream o;
    o << "L " << static_cast<double>(factor_.factor_entries()) / 1e6 << " M entries, " << factor_.factor_flops() / 1e9 << " GFlop"
      << (factor_.stored_in_half_precision() ? ", half-precision solves" : "");
    return o.str();
  }

 private:
  CholeskyPreconditioner factor_;
};

// The stale Cholesky factor C of the set-up step, turned with the cloth: z = Q C⁻¹ Qᵀ r, where Q is
// block-diagonal with one rotation per vertex, the best fit (polar factor) of the turn of the
// vertex's neighbourhood (the vertices it couples to in A) from the set-up step's positions to the
// solved step's. A corotational stiffness turns with its elements, A_new ≈ Q A_old Qᵀ, so the
// turned factor should age more slowly than the plain one. Vertices with a prescribed component
// keep Q = I.
class WarpedCholeskyCandidate final : public Candidate {
 public:
  void setup(const bench::StepSystem& s) override {
    if (!factor_.factorize(s.a, &s.free)) throw std::runtime_error("warped: not positive definite");
    x0_ = s.positions;
    const Eigen::Index nv = s.a.rows() / 3;
    neighbours_.assign(static_cast<std::size_t>(nv), {});
    for (Eigen::Index col = 0; col < s.a.outerSize(); col += 3)
      for (Eigen::SparseMatrix<double>::InnerIterator it(s.a, col); it; ++it)
        if (it.row() % 3 == 0 && it.row() != col) neighbours_[static_cast<std::size_t>(col / 3)].push_back(static_cast<int>(it.row() / 3));
    q_.assign(static_cast<std::size_t>(nv), Eigen::Matrix3d::Identity());
    whole_.assign(static_cast<std::size_t>(nv), 0);
    for (Eigen::Index v = 0; v < nv; ++v) whole_[static_cast<std::size_t>(v)] = s.free[3 * v] && s.free[3 * v + 1] && s.free[3 * v + 2];
  }
  bool refresh(const bench::StepSystem& s) override {
    const Eigen::Index nv = s.a.rows() / 3;
    double worst = 0.0;
    for (Eigen::Index v = 0; v < nv; ++v) {
      if (!whole_[static_cast<std::size_t>(v)]) continue;
      Eigen::Matrix3d f = Eigen::Matrix3d::Zero();
      const Eigen::Vector3d xv = s.positions.segment<3>(3 * v), Xv = x0_.segment<3>(3 * v);
      for (int j : neighbours_[static_cast<std::size_t>(v)])
        f += (s.positions.segment<3>(3 * j) - xv) * (x0_.segment<3>(3 * j) - Xv).transpose();
      Eigen::JacobiSVD<Eigen::Matrix3d> svd(f, Eigen::ComputeFullU | Eigen::ComputeFullV);
      Eigen::Matrix3d u = svd.matrixU();
      if ((u * svd.matrixV().transpose()).determinant() < 0) u.col(2) = -u.col(2);
      q_[static_cast<std::size_t>(v)] = u * svd.matrixV().transpose();
      worst = std::max(worst, std::acos(std::clamp(0.5 * (q_[static_cast<std::size_t>(v)].trace() - 1.0), -1.0, 1.0)));
    }
    worst_turn_ = worst;
    return true;
  }
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) override {
    const Eigen::Index nv = r.size() / 3;
    t_.resize(r.size());
    for (Eigen::Index v = 0; v < nv; ++v) t_.segment<3>(3 * v) = q_[static_cast<std::size_t>(v)].transpose() * r.segment<3>(3 * v);
    factor_.apply(t_, u_);
    z.resize(r.size());
    for (Eigen::Index v = 0; v < nv; ++v) z.segment<3>(3 * v) = q_[static_cast<std::size_t>(v)] * u_.segment<3>(3 * v);
  }
  std::string info() const override {
    std::ostringstream o;
    o << "largest vertex turn " << worst_turn_ * 180.0 / M_PI << " deg";
    return o.str();
  }

 private:
  CholeskyPreconditioner factor_;
  Eigen::VectorXd x0_, t_, u_;
  std::vector<std::vector<int>> neighbours_;
  std::vector<Eigen::Matrix3d> q_;
  std::vector<char> whole_;
  double worst_turn_ = 0.0;
};

class MultilevelCandidate final : public Candidate {
 public:
  explicit MultilevelCandidate(const std::string& options) : options_(options) {
    // "refresh=level0" / "refresh=galerkin": a bench option, not a setting.
    for (const char* mode : {"refresh=level0", "refresh=galerkin"}) {
      const auto at = options_.find(mode);
      if (at != std::string::npos) {
        refresh_ = std::string(mode).substr(8);
        options_.erase(at, std::string(mode).size());
      }
    }
  }
  bool refresh(const bench::StepSystem& s) override {
    if (refresh_.empty()) return false;
    if (!p_->refresh(s.a, refresh_ == "galerkin")) throw std::runtime_error("multilevel: refresh failed");
    return true;
  }
  void setup(const bench::StepSystem& s) override {
    MultilevelSettings settings = parse_multilevel_settings(options_);
    if (!p_) p_ = std::make_unique<MultilevelPreconditioner>(settings);
    if (!p_->setup(s.a, s.free, s.positions)) throw std::runtime_error("multilevel: set-up failed");
  }
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) override { p_->apply(r, z); }
  std::string info() const override { return p_ ? p_->describe() : ""; }

 private:
  std::string options_, refresh_;
  std::unique_ptr<MultilevelPreconditioner> p_;
};

// The stale Cholesky factor C between two V-cycles M of the multilevel preconditioner, symmetric
// multiplicative: z = M r, z += C (r − A z), z += M (r − A z). C is of the set-up step's matrix
// (stale later); M is refreshed (Galerkin, prolongators kept) to each solved step's matrix.
class CompositeCandidate final : public Candidate {
 public:
  explicit CompositeCandidate(const std::string& options) : settings_(parse_multilevel_settings(options)) {}
  void setup(const bench::StepSystem& s) override {
    if (!factor_.factorize(s.a, &s.free)) throw std::runtime_error("composite: Cholesky failed");
    if (!m_) m_ = std::make_unique<MultilevelPreconditioner>(settings_);
    if (!m_->setup(s.a, s.free, s.positions)) throw std::runtime_error("composite: multilevel set-up failed");
    a_ = &s.a;
    mask_ = free_mask(s.free);
  }
  bool refresh(const bench::StepSystem& s) override {
    if (!m_->refresh(s.a, true)) throw std::runtime_error("composite: refresh failed");
    a_ = &s.a;
    return true;
  }
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) override {
    m_->apply(r, z);
    symmetric_product(*a_, z, mask_, t_);
    factor_.apply(r - t_, u_);
    z += u_.cwiseProduct(mask_);
    symmetric_product(*a_, z, mask_, t_);
    m_->apply(r - t_, u_);
    z += u_;
  }
  std::string info() const override { return "M-C-M; M: " + (m_ ? m_->describe() : std::string()); }

 private:
  MultilevelSettings settings_;
  CholeskyPreconditioner factor_;
  std::unique_ptr<MultilevelPreconditioner> m_;
  const Eigen::SparseMatrix<double>* a_ = nullptr;
  Eigen::VectorXd mask_, t_, u_;
};

#ifdef CLOTHSIM_HAVE_PETSC
#define PCHECK(call)                                                                   \
  do {                                                                                 \
    PetscErrorCode ierr_ = (call);                                                     \
    if (ierr_) throw std::runtime_error(std::string("PETSc error in ") + #call);      \
  } while (0)

// A PETSc preconditioner (PCGAMG, PCHYPRE/BoomerAMG, PCML, ...) on the free rows of A, with the
// rigid-body modes of the free vertices as its near-null space. `options` are PETSc options
// without prefix ("-pc_type gamg -pc_gamg_threshold 0.01"); they are given the candidate's prefix.
class PetscCandidate final : public Candidate {
 public:
  PetscCandidate(const std::string& label, const std::string& options) : prefix_(label + "_") {
    std::istringstream in(options);
    std::string word, prefixed;
    while (in >> word) prefixed += (word.size() > 1 && word[0] == '-' && !std::isdigit(word[1]) ? "-" + prefix_ + word.substr(1) : word) + " ";
    PCHECK(PetscOptionsInsertString(nullptr, prefixed.c_str()));
  }
  ~PetscCandidate() override {
    if (pc_) PCDestroy(&pc_);
    if (mat_) MatDestroy(&mat_);
    if (x_) VecDestroy(&x_);
    if (y_) VecDestroy(&y_);
  }
  void setup(const bench::StepSystem& s) override {
    const Eigen::Index n = s.a.rows();
    index_.assign(static_cast<std::size_t>(n), -1);
    rows_.clear();
    bool blocks = true;
    for (Eigen::Index i = 0; i < n; ++i)
      if (s.free[static_cast<std::size_t>(i)]) {
        index_[static_cast<std::size_t>(i)] = static_cast<int>(rows_.size());
        rows_.push_back(static_cast<int>(i));
      }
    for (Eigen::Index v = 0; v < n / 3; ++v) {
      const int f = s.free[3 * v] + s.free[3 * v + 1] + s.free[3 * v + 2];
      if (f != 0 && f != 3) blocks = false;
    }
    const PetscInt m = static_cast<PetscInt>(rows_.size());
    // The free rows and columns, in CSR (A symmetric: column j of the CSC storage is row j).
    std::vector<PetscInt> ia(static_cast<std::size_t>(m + 1), 0), ja;
    std::vector<PetscScalar> va;
    for (PetscInt r = 0; r < m; ++r) {
      const int j = rows_[static_cast<std::size_t>(r)];
      for (Eigen::SparseMatrix<double>::InnerIterator it(s.a, j); it; ++it) {
        const int c = index_[static_cast<std::size_t>(it.row())];
        if (c < 0) continue;
        ja.push_back(c);
        va.push_back(it.value());
      }
      ia[static_cast<std::size_t>(r + 1)] = static_cast<PetscInt>(ja.size());
    }
    if (mat_) MatDestroy(&mat_);
    PCHECK(MatCreate(PETSC_COMM_SELF, &mat_));
    PCHECK(MatSetSizes(mat_, m, m, m, m));
    PCHECK(MatSetType(mat_, MATSEQAIJ));
    if (blocks) PCHECK(MatSetBlockSize(mat_, 3));
    PCHECK(MatSeqAIJSetPreallocationCSR(mat_, ia.data(), ja.data(), va.data()));
    PCHECK(MatSetOption(mat_, MAT_SYMMETRIC, PETSC_TRUE));
    PCHECK(MatSetOption(mat_, MAT_SPD, PETSC_TRUE));
    if (blocks) {  // rigid-body modes from the free vertices' positions
      Vec coords;
      PCHECK(VecCreateSeq(PETSC_COMM_SELF, m, &coords));
      PCHECK(VecSetBlockSize(coords, 3));
      PetscScalar* c;
      PCHECK(VecGetArray(coords, &c));
      for (PetscInt r = 0; r < m; ++r) c[r] = s.positions(rows_[static_cast<std::size_t>(r)]);
      PCHECK(VecRestoreArray(coords, &c));
      MatNullSpace nearnull;
      PCHECK(MatNullSpaceCreateRigidBody(coords, &nearnull));
      PCHECK(MatSetNearNullSpace(mat_, nearnull));
      PCHECK(MatNullSpaceDestroy(&nearnull));
      PCHECK(VecDestroy(&coords));
    }
    if (!pc_) {
      PCHECK(PCCreate(PETSC_COMM_SELF, &pc_));
      PCHECK(PCSetOptionsPrefix(pc_, prefix_.c_str()));
    }
    PCHECK(PCSetOperators(pc_, mat_, mat_));
    PCHECK(PCSetFromOptions(pc_));
    PCHECK(PCSetUp(pc_));
    if (!x_) {
      PCHECK(VecCreateSeq(PETSC_COMM_SELF, m, &x_));
      PCHECK(VecDuplicate(x_, &y_));
    }
  }
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) override {
    PetscScalar* xa;
    PCHECK(VecGetArray(x_, &xa));
    for (std::size_t k = 0; k < rows_.size(); ++k) xa[k] = r(rows_[k]);
    PCHECK(VecRestoreArray(x_, &xa));
    PCHECK(PCApply(pc_, x_, y_));
    z.setZero(r.size());
    const PetscScalar* ya;
    PCHECK(VecGetArrayRead(y_, &ya));
    for (std::size_t k = 0; k < rows_.size(); ++k) z(rows_[k]) = ya[k];
    PCHECK(VecRestoreArrayRead(y_, &ya));
  }
  std::string info() const override {
    PCType type;
    PCGetType(pc_, &type);
    std::string out = type ? type : "?";
    PetscInt levels = 0;
    if (type && std::string(type) == PCGAMG) {
      PCMGGetLevels(pc_, &levels);
      out += ", " + std::to_string(levels) + " levels";
      // Operator complexity: entries of all levels' matrices over the finest.
      double total = 0.0, finest = 0.0;
      for (PetscInt l = 0; l < levels; ++l) {
        KSP smoother;
        Mat op;
        PCMGGetSmoother(pc_, l, &smoother);
        KSPGetOperators(smoother, &op, nullptr);
        MatInfo mi;
        MatGetInfo(op, MAT_LOCAL, &mi);
        total += mi.nz_used;
        if (l == levels - 1) finest = mi.nz_used;
        PetscInt rows, cols;
        MatGetSize(op, &rows, &cols);
        out += (l == 0 ? " [" : ", ") + std::to_string(rows);
      }
      out += "], operator complexity " + std::to_string(total / std::max(finest, 1.0)).substr(0, 4);
    }
    return out;
  }

 private:
  std::string prefix_;
  std::vector<int> index_, rows_;
  Mat mat_ = nullptr;
  PC pc_ = nullptr;
  Vec x_ = nullptr, y_ = nullptr;
};
#endif

// ---------------------------------------------------------------------------------------------
// The conjugate gradients of sim/solver/pcg.cpp (iterate()), recording when the relative residual
// first falls below each of the tolerances.

struct Trace {
  static constexpr int kLevels = 3;
  static constexpr double kTolerance[kLevels] = {1e-4, 1e-6, 1e-8};
  int iterations[kLevels] = {-1, -1, -1};
  double ms[kLevels] = {0, 0, 0};
  double final_residual = 0.0;
  double error = 0.0;  // |x − simulator's solution| / |solution| on the free rows at the end
};

Trace pcg(const bench::StepSystem& s, Candidate& candidate, int max_iterations) {
  const Eigen::VectorXd mask = free_mask(s.free);
  Eigen::VectorXd x = s.start;
  const auto t0 = Clock::now();
  Trace trace;
  const double scale = std::max(s.b.cwiseProduct(mask).norm(), 1e-300);
  Eigen::VectorXd r(x.size()), z(x.size()), p(x.size()), q(x.size());
  symmetric_product(s.a, x, mask, q);
  r = s.b.cwiseProduct(mask) - q;
  auto record = [&](int k) {
    const double res = r.norm() / scale;
    trace.final_residual = res;
    for (int l = 0; l < Trace::kLevels; ++l)
      if (trace.iterations[l] < 0 && res <= Trace::kTolerance[l]) {
        trace.iterations[l] = k;
        trace.ms[l] = ms_since(t0);
      }
    return trace.iterations[Trace::kLevels - 1] >= 0;
  };
  if (!record(0)) {
    candidate.apply(r, z);
    z = z.cwiseProduct(mask);
    p = z;
    double rz = r.dot(z);
    for (int k = 1; k <= max_iterations; ++k) {
      symmetric_product(s.a, p, mask, q);
      const double pq = p.dot(q);
      if (!(pq > 0.0) || !std::isfinite(pq)) break;
      const double alpha = rz / pq;
      x += alpha * p;
      r -= alpha * q;
      if (record(k)) break;
      candidate.apply(r, z);
      z = z.cwiseProduct(mask);
      const double rz_next = r.dot(z);
      p = z + (rz_next / rz) * p;
      rz = rz_next;
    }
  }
  trace.error = (x - s.solution).cwiseProduct(mask).norm() / std::max(s.solution.cwiseProduct(mask).norm(), 1e-300);
  return trace;
}

std::vector<std::string> parse_names(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) out.push_back(item);
  return out;
}

std::string system_path(const std::string& dir, int step) {
  char name[64];
  std::snprintf(name, sizeof name, "/step_%04d.sys", step);
  return dir + name;
}

int run(int argc, char** argv) {
  std::string dir;
  int setup_step = 20, repeat = 3, threads = 0, max_iterations = 1000;
  std::vector<int> solve_steps;
  std::vector<std::string> candidates;
  std::map<std::string, std::string> petsc_options, multilevel_options;
  int timing_rounds = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error(arg + " needs a value");
      return argv[++i];
    };
    if (arg == "--systems") dir = value();
    else if (arg == "--setup") setup_step = std::stoi(value());
    else if (arg == "--solve") solve_steps = bench::parse_list(value());
    else if (arg == "--candidates") candidates = parse_names(value());
    else if (arg == "--repeat") repeat = std::stoi(value());
    else if (arg == "--threads") threads = std::stoi(value());
    else if (arg == "--max-iterations") max_iterations = std::stoi(value());
    else if (arg == "--timing") timing_rounds = std::stoi(value());
    else if (arg == "--petsc") {
      const std::string label = value();
      petsc_options[label] = value();
    } else if (arg == "--multilevel") {
      const std::string label = value();
      multilevel_options[label] = value();
    } else {
      std::cerr << "multilevel_bench: unknown argument " << arg << " (see the comment at the top of bench/multilevel_bench.cpp)\n";
      return 2;
    }
  }
  if (dir.empty() || (candidates.empty() && timing_rounds == 0)) throw std::runtime_error("--systems and --candidates are required");
  if (solve_steps.empty()) solve_steps = {setup_step};
  std::unique_ptr<tbb::global_control> limit;
  if (threads > 0) limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);

  const bench::StepSystem setup_system = bench::read_system(system_path(dir, setup_step));
  std::vector<bench::StepSystem> solves;
  for (int st : solve_steps) solves.push_back(st == setup_step ? setup_system : bench::read_system(system_path(dir, st)));
  const Eigen::Index n = setup_system.a.rows();
  long free_count = 0;
  for (char f : setup_system.free) free_count += f != 0;
  std::printf("# %d x %d sleeve: %ld vertices, %ld unknowns, %ld entries of A; set-up on step %d; threads %d\n",
              setup_system.segments, setup_system.rings, static_cast<long>(n / 3), free_count,
              static_cast<long>(setup_system.a.nonZeros()), setup_step, threads);
  std::printf("# product with A (symmetric_product): %.3f ms (median of 21)\n", product_time(setup_system, 21));
  if (timing_rounds > 0) {
    // Unit costs, alternating: each round times every operation once, in the same minutes.
    const Eigen::VectorXd mask = free_mask(setup_system.free);
    CholeskyPreconditioner factor;
    if (!factor.factorize(setup_system.a, &setup_system.free)) throw std::runtime_error("cholesky failed");  // analysis
    MultilevelPreconditioner multilevel(parse_multilevel_settings(""));
    if (!multilevel.setup(setup_system.a, setup_system.free, setup_system.positions)) throw std::runtime_error("multilevel failed");
    const char* names[] = {"product with A", "Cholesky apply", "multilevel apply (V-cycle)", "Cholesky factorisation (analysis reused)",
                           "multilevel set-up", "multilevel refresh, level 0", "multilevel refresh, Galerkin"};
    std::vector<double> t[7];
    Eigen::VectorXd y, z;
    for (int round = 0; round < timing_rounds; ++round) {
      auto time = [&](int k, auto&& f) {
        const auto t0 = Clock::now();
        f();
        t[k].push_back(ms_since(t0));
      };
      for (int rep = 0; rep < 5; ++rep) time(0, [&] { symmetric_product(setup_system.a, setup_system.b, mask, y); });
      for (int rep = 0; rep < 3; ++rep) time(1, [&] { factor.apply(setup_system.b, z); });
      for (int rep = 0; rep < 3; ++rep) time(2, [&] { multilevel.apply(setup_system.b, z); });
      time(3, [&] { factor.factorize(setup_system.a, &setup_system.free); });
      time(4, [&] { multilevel.setup(setup_system.a, setup_system.free, setup_system.positions); });
      time(5, [&] { multilevel.refresh(setup_system.a, false); });
      time(6, [&] { multilevel.refresh(setup_system.a, true); });
    }
    std::printf("| operation | median ms | min ms | in products with A |\n|---|--:|--:|--:|\n");
    const double unit = median(t[0]);
    for (int k = 0; k < 7; ++k)
      std::printf("| %s | %.3f | %.3f | %.1f |\n", names[k], median(t[k]), *std::min_element(t[k].begin(), t[k].end()),
                  median(t[k]) / unit);
    std::printf("# multilevel: %s; Cholesky: %ld entries\n", multilevel.describe().c_str(), factor.factor_entries());
    std::printf("# peak resident set %.0f MiB\n", peak_mib());
    if (candidates.empty()) return 0;
  }
  std::printf("| candidate | set-up step | solve step | set-up ms | it 1e-4 | ms 1e-4 | it 1e-6 | ms 1e-6 | it 1e-8 | ms 1e-8 | "
              "memory MiB | apply ms | A·x ms | error | notes |\n|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|---|\n");
  std::fflush(stdout);
  for (const std::string& name : candidates) {
    malloc_trim(0);
    const double rss0 = resident_mib();
    std::unique_ptr<Candidate> c;
    if (name == "block_jacobi") c = std::make_unique<BlockJacobiCandidate>();
    else if (name == "cholesky") c = std::make_unique<CholeskyCandidate>();
    else if (name == "warped") c = std::make_unique<WarpedCholeskyCandidate>();
    else if (name.rfind("mcm:", 0) == 0) {
      const std::string label = name.substr(4);
      if (!multilevel_options.count(label)) throw std::runtime_error("no --multilevel options for " + label);
      c = std::make_unique<CompositeCandidate>(multilevel_options[label]);
    } else if (name.rfind("ml:", 0) == 0) {
      const std::string label = name.substr(3);
      if (!multilevel_options.count(label)) throw std::runtime_error("no --multilevel options for " + label);
      c = std::make_unique<MultilevelCandidate>(multilevel_options[label]);
    }
#ifdef CLOTHSIM_HAVE_PETSC
    else if (name.rfind("petsc:", 0) == 0) {
      const std::string label = name.substr(6);
      if (!petsc_options.count(label)) throw std::runtime_error("no --petsc options for " + label);
      c = std::make_unique<PetscCandidate>(label, petsc_options[label]);
    }
#endif
    else throw std::runtime_error("unknown candidate " + name);
    std::vector<double> setup_ms;
    for (int k = 0; k < repeat; ++k) {
      const auto t0 = Clock::now();
      c->setup(setup_system);
      setup_ms.push_back(ms_since(t0));
    }
    malloc_trim(0);
    const double memory = resident_mib() - rss0;
    double apply_ms = 0.0;
    {
      Eigen::VectorXd z;
      std::vector<double> t;
      for (int k = 0; k < 7; ++k) {
        const auto t0 = Clock::now();
        c->apply(setup_system.b, z);
        t.push_back(ms_since(t0));
      }
      apply_ms = median(t);
    }
    const double product_ms = product_time(setup_system, 7);  // in the same minutes: the unit of cost
    for (const bench::StepSystem& s : solves) {
      double refresh_ms = 0.0;
      if (s.step != setup_step) {
        const auto t0 = Clock::now();
        if (c->refresh(s)) refresh_ms = ms_since(t0);
      }
      Trace first;
      std::vector<double> ms[Trace::kLevels];
      for (int k = 0; k < repeat; ++k) {
        const Trace t = pcg(s, *c, max_iterations);
        if (k == 0) first = t;
        for (int l = 0; l < Trace::kLevels; ++l) ms[l].push_back(t.ms[l]);
      }
      std::printf("| %s | %d | %d | %.1f |", name.c_str(), setup_step, s.step, refresh_ms > 0 ? refresh_ms : median(setup_ms));
      for (int l = 0; l < Trace::kLevels; ++l) {
        if (first.iterations[l] < 0) std::printf(" >%d | – |", max_iterations);
        else std::printf(" %d | %.1f |", first.iterations[l], median(ms[l]));
      }
      std::printf(" %.1f | %.2f | %.3f | %.1e | %s%s |\n", memory, apply_ms, product_ms, first.error, refresh_ms > 0 ? "(refreshed: set-up column is the refresh) " : "", c->info().c_str());
      std::fflush(stdout);
    }
  }
  std::printf("# peak resident set %.0f MiB\n", peak_mib());
  return 0;
}

}  // namespace
}  // namespace clothsim

int main(int argc, char** argv) {
#ifdef CLOTHSIM_HAVE_PETSC
  int pargc = 1;
  char** pargv = argv;
  if (PetscInitialize(&pargc, &pargv, nullptr, nullptr)) return 1;
#endif
  int rc = 1;
  try {
    rc = clothsim::run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "multilevel_bench: " << e.what() << "\n";
  }
#ifdef CLOTHSIM_HAVE_PETSC
  PetscFinalize();
#endif
  return rc;
}
