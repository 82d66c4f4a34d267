#include "app/checkpoint.hpp"

#include "app/output_folders.hpp"

#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace clothsim {

namespace {

constexpr std::string_view kMagic = "clothsim checkpoint\n";
constexpr std::string_view kEnd = "end\n";
// 2: RunTotals::contact_response_factorizations; 3: the coupled pattern; 4: RunTotals::contact as
// ContactCounters; 5: ContactCounters::relinearisations, IntegratorCheckpoint::contact_last_step;
// 6: stats.csv's direct_fallbacks column (a run of version 5 resumed would get rows longer than its
// header) and ContactCounters' step times (first solve, Newton's solves, line search, candidates,
// fail-safe, steps with and without contact).
constexpr std::uint32_t kVersion = 6;

class Writer {
 public:
  template <typename T>
  void put(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    bytes_.append(reinterpret_cast<const char*>(&value), sizeof(T));
  }
  void put(const Eigen::VectorXd& v) {
    put(static_cast<std::uint64_t>(v.size()));
    bytes_.append(reinterpret_cast<const char*>(v.data()), static_cast<std::size_t>(v.size()) * sizeof(double));
  }
  void text(std::string_view s) { bytes_.append(s); }
  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
};

class Reader {
 public:
  Reader(std::string bytes, std::string path) : bytes_(std::move(bytes)), path_(std::move(path)) {}
  template <typename T>
  T get() {
    static_assert(std::is_trivially_copyable_v<T>);
    need(sizeof(T));
    T value;
    std::memcpy(&value, bytes_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return value;
  }
  Eigen::VectorXd vector() {
    const auto n = get<std::uint64_t>();
    if (n > (bytes_.size() - at_) / sizeof(double)) fail("a vector longer than the file");
    Eigen::VectorXd v(static_cast<Eigen::Index>(n));
    if (n > 0) std::memcpy(v.data(), bytes_.data() + at_, n * sizeof(double));  // an empty v has data() == nullptr
    at_ += n * sizeof(double);
    return v;
  }
  void expect(std::string_view s, const char* what) {
    if (bytes_.compare(at_, s.size(), s) != 0) fail(what);
    at_ += s.size();
  }
  bool at_end() const { return at_ == bytes_.size(); }
  [[noreturn]] void fail(const std::string& what) const {
    throw std::runtime_error(path_ + ": not a usable clothsim checkpoint (" + what + ")");
  }

 private:
  void need(std::size_t n) const {
    if (bytes_.size() - at_ < n) fail("truncated");
  }
  std::string bytes_;
  std::string path_;
  std::size_t at_ = 0;
};

}  // namespace

std::uint64_t fnv1a(std::string_view data, std::uint64_t hash) {
  for (const char c : data) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 1099511628211ull;
  }
  return hash;
}

// A pattern (per node, its coupled nodes) as one vector: per node its count, then the nodes.
Eigen::VectorXd flatten(const std::vector<std::vector<int>>& pattern) {
  std::vector<double> out;
  for (const std::vector<int>& row : pattern) {
    out.push_back(static_cast<double>(row.size()));
    out.insert(out.end(), row.begin(), row.end());
  }
  return Eigen::Map<const Eigen::VectorXd>(out.data(), static_cast<Eigen::Index>(out.size()));
}

std::vector<std::vector<int>> unflatten(const Eigen::VectorXd& flat, Reader& r) {
  std::vector<std::vector<int>> pattern;
  for (Eigen::Index at = 0; at < flat.size();) {
    const double count = flat(at++);
    if (!(count >= 0) || count > static_cast<double>(flat.size() - at)) r.fail("a coupled pattern that does not add up");
    std::vector<int> row;
    for (Eigen::Index k = 0; k < static_cast<Eigen::Index>(count); ++k) row.push_back(static_cast<int>(flat(at++)));
    pattern.push_back(std::move(row));
  }
  return pattern;
}

void write_checkpoint(const std::filesystem::path& path, const RunCheckpoint& c) {
  Writer w;
  w.text(kMagic);
  w.put(kVersion);
  w.put(static_cast<std::uint32_t>(sizeof(double)));
  w.put(c.fingerprint);
  const SimulatorCheckpoint& s = c.sim;
  w.put(s.state.x);
  w.put(s.state.v);
  w.put(s.state.t);
  w.put(static_cast<std::int64_t>(s.state.step));
  w.put(s.integrator.u);
  w.put(s.integrator.v_previous);
  w.put(s.integrator.external_work);
  w.put(s.integrator.boundary_work);
  w.put(flatten(s.integrator.coupled_pattern));
  w.put(static_cast<std::uint8_t>(s.integrator.contact_last_step));
  w.put(s.solver.factored_values);
  w.put(static_cast<std::int64_t>(s.solver.solves_since_factor));
  w.put(s.solver.iterations_since_factor);
  w.put(static_cast<std::uint8_t>(s.solver.refactor_next));
  w.put(c.totals);
  w.put(c.wall_seconds);
  w.put(c.probes_bytes);
  w.put(c.stats_bytes);
  w.put(static_cast<std::int64_t>(c.images_written));
  w.put(c.spool_bytes);
  w.put(c.bounds_lo);
  w.put(c.bounds_hi);
  w.text(kEnd);
  write_atomically(path, w.bytes());
}

RunCheckpoint read_checkpoint(const std::filesystem::path& path) {
  Reader r(read_text_file(path), path.string());
  r.expect(kMagic, "no checkpoint header");
  if (const auto version = r.get<std::uint32_t>(); version != kVersion)
    r.fail("format version " + std::to_string(version) + ", this clothsim reads version " + std::to_string(kVersion));
  if (r.get<std::uint32_t>() != sizeof(double)) r.fail("written on another kind of machine");
  RunCheckpoint c;
  c.fingerprint = r.get<std::uint64_t>();
  SimulatorCheckpoint& s = c.sim;
  s.state.x = r.vector();
  s.state.v = r.vector();
  s.state.t = r.get<double>();
  s.state.step = static_cast<int>(r.get<std::int64_t>());
  s.integrator.u = r.vector();
  s.integrator.v_previous = r.vector();
  s.integrator.external_work = r.get<double>();
  s.integrator.boundary_work = r.get<double>();
  s.integrator.coupled_pattern = unflatten(r.vector(), r);
  s.integrator.contact_last_step = r.get<std::uint8_t>() != 0;
  s.solver.factored_values = r.vector();
  s.solver.solves_since_factor = static_cast<int>(r.get<std::int64_t>());
  s.solver.iterations_since_factor = r.get<double>();
  s.solver.refactor_next = r.get<std::uint8_t>() != 0;
  c.totals = r.get<RunTotals>();
  c.wall_seconds = r.get<double>();
  c.probes_bytes = r.get<std::uint64_t>();
  c.stats_bytes = r.get<std::uint64_t>();
  c.images_written = static_cast<int>(r.get<std::int64_t>());
  c.spool_bytes = r.get<std::uint64_t>();
  for (float& v : c.bounds_lo) v = r.get<float>();
  for (float& v : c.bounds_hi) v = r.get<float>();
  r.expect(kEnd, "no end marker");
  if (!r.at_end()) r.fail("data after the end marker");
  return c;
}

}  // namespace clothsim
