// One implicit-Euler system of a dynamic run on disk, for studying linear solvers apart from the
// simulator (bench/sleeve_systems.cpp writes them, bench/multilevel_bench.cpp reads them).
//
// Binary format (little-endian, the machine's own; version 1), in this order:
//   char[8]   "CSSYS001"
//   int64     n (rows = 3 · vertices), nnz (entries of A, full symmetric storage)
//   int32     segments, rings, step (the step this system advances to), 0 (padding)
//   double    dt, t (time at the start of the step)
//   int32     outer[n + 1], inner[nnz]     A in compressed columns (Eigen's default layout)
//   double    values[nnz]
//   double    b[n]          right-hand side M v + h f of the integrator (all rows)
//   double    start[n]      PCG's start: the extrapolated velocity on the free rows, the
//                           prescribed velocities on the constrained ones
//   double    solution[n]   the simulator's solution (tolerance 1e-8)
//   double    positions[n]  the vertices at the start of the step [m] (rigid-body modes)
//   uint8     free[n]       1: unknown of the solve, 0: prescribed
// Solving A x = b on the free rows from `start` (constrained entries fixed) is exactly the call
// the integrator makes: solve_pcg(A, b, free, start, tolerance, ...).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace clothsim::bench {

struct StepSystem {
  int segments = 0, rings = 0, step = 0;
  double dt = 0.0, t = 0.0;
  Eigen::SparseMatrix<double> a;
  Eigen::VectorXd b, start, solution, positions;
  std::vector<char> free;
};

namespace system_io_detail {
template <class T>
void put(std::ofstream& out, const T* data, std::size_t count) {
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(count * sizeof(T)));
}
template <class T>
void get(std::ifstream& in, T* data, std::size_t count, const std::string& path) {
  in.read(reinterpret_cast<char*>(data), static_cast<std::streamsize>(count * sizeof(T)));
  if (!in) throw std::runtime_error(path + ": truncated system file");
}
}  // namespace system_io_detail

// "1,5,20" -> {1, 5, 20} (the benches' step lists).
inline std::vector<int> parse_list(const std::string& text) {
  std::vector<int> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) out.push_back(std::stoi(item));
  return out;
}

inline void write_system(const std::string& path, const StepSystem& s) {
  using system_io_detail::put;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error(path + ": cannot write");
  if (!s.a.isCompressed()) throw std::runtime_error("write_system: matrix not compressed");
  const std::int64_t n = s.a.rows(), nnz = s.a.nonZeros();
  put(out, "CSSYS001", 8);
  put(out, &n, 1);
  put(out, &nnz, 1);
  const std::int32_t ints[4] = {s.segments, s.rings, s.step, 0};
  put(out, ints, 4);
  const double times[2] = {s.dt, s.t};
  put(out, times, 2);
  put(out, s.a.outerIndexPtr(), static_cast<std::size_t>(n + 1));
  put(out, s.a.innerIndexPtr(), static_cast<std::size_t>(nnz));
  put(out, s.a.valuePtr(), static_cast<std::size_t>(nnz));
  for (const Eigen::VectorXd* v : {&s.b, &s.start, &s.solution, &s.positions}) {
    if (v->size() != n) throw std::runtime_error("write_system: vector of the wrong size");
    put(out, v->data(), static_cast<std::size_t>(n));
  }
  put(out, s.free.data(), static_cast<std::size_t>(n));
  if (!out) throw std::runtime_error(path + ": write failed");
}

inline StepSystem read_system(const std::string& path) {
  using system_io_detail::get;
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot read");
  char magic[8];
  get(in, magic, 8, path);
  if (std::memcmp(magic, "CSSYS001", 8) != 0) throw std::runtime_error(path + ": not a CSSYS001 system file");
  std::int64_t n = 0, nnz = 0;
  get(in, &n, 1, path);
  get(in, &nnz, 1, path);
  if (n <= 0 || nnz <= 0 || n > (1LL << 31) || nnz > (1LL << 40)) throw std::runtime_error(path + ": bad sizes");
  StepSystem s;
  std::int32_t ints[4];
  get(in, ints, 4, path);
  s.segments = ints[0];
  s.rings = ints[1];
  s.step = ints[2];
  double times[2];
  get(in, times, 2, path);
  s.dt = times[0];
  s.t = times[1];
  std::vector<std::int32_t> outer(static_cast<std::size_t>(n + 1)), inner(static_cast<std::size_t>(nnz));
  std::vector<double> values(static_cast<std::size_t>(nnz));
  get(in, outer.data(), outer.size(), path);
  get(in, inner.data(), inner.size(), path);
  get(in, values.data(), values.size(), path);
  s.a = Eigen::Map<const Eigen::SparseMatrix<double>>(n, n, nnz, outer.data(), inner.data(), values.data());
  for (Eigen::VectorXd* v : {&s.b, &s.start, &s.solution, &s.positions}) {
    v->resize(n);
    get(in, v->data(), static_cast<std::size_t>(n), path);
  }
  s.free.resize(static_cast<std::size_t>(n));
  get(in, s.free.data(), s.free.size(), path);
  return s;
}

// Matrix Market copies (for tools outside this project): A's lower triangle as a symmetric
// coordinate matrix, and b, the free mask (1/0) and the positions as dense arrays.
inline void write_matrix_market(const std::string& prefix, const StepSystem& s) {
  {
    std::ofstream out(prefix + "_A.mtx");
    out.precision(17);
    long lower = 0;
    for (int j = 0; j < s.a.outerSize(); ++j)
      for (Eigen::SparseMatrix<double>::InnerIterator it(s.a, j); it; ++it)
        if (it.row() >= j) ++lower;
    out << "%%MatrixMarket matrix coordinate real symmetric\n" << s.a.rows() << ' ' << s.a.cols() << ' ' << lower << '\n';
    for (int j = 0; j < s.a.outerSize(); ++j)
      for (Eigen::SparseMatrix<double>::InnerIterator it(s.a, j); it; ++it)
        if (it.row() >= j) out << it.row() + 1 << ' ' << j + 1 << ' ' << it.value() << '\n';
  }
  auto dense = [&](const std::string& name, const Eigen::VectorXd& v) {
    std::ofstream out(prefix + "_" + name + ".mtx");
    out.precision(17);
    out << "%%MatrixMarket matrix array real general\n" << v.size() << " 1\n";
    for (Eigen::Index i = 0; i < v.size(); ++i) out << v(i) << '\n';
  };
  dense("b", s.b);
  dense("start", s.start);
  dense("positions", s.positions);
  Eigen::VectorXd mask(static_cast<Eigen::Index>(s.free.size()));
  for (std::size_t i = 0; i < s.free.size(); ++i) mask(static_cast<Eigen::Index>(i)) = s.free[i] ? 1.0 : 0.0;
  dense("free", mask);
}

}  // namespace clothsim::bench
