// Mesh convergence of the centre deflection of square Kirchhoff plates (side a = 1 m,
// E = 1e7 Pa, ν = 0.3, t = 0.01 m) against the classical series solutions (Timoshenko &
// Woinowsky-Krieger): hinged or clamped edges, uniform load q = 1 N/m² or a centre point load
// P = 1 N, one- and three-point quadrature, grids 8² … 64² (--max 128 adds 128²).
// Prints a Markdown table to stdout; --csv FILE also writes the rows as CSV.
#include "sim/study/plates.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

namespace clothsim {
namespace {

constexpr Quadrature kRules[] = {Quadrature::one_point, Quadrature::three_point};

constexpr double kSide = 1.0;  // a [m]

struct Row {
  std::string case_name, quadrature, mesh;
  int vertices = 0, dofs = 0;
  double deflection = 0, reference = 0, error_percent = 0;
  std::optional<double> order;
  double assemble_seconds = 0, solve_seconds = 0;
};

struct Options {
  int max_divisions = 64;
  std::string csv_path;
};

[[noreturn]] void usage_error(const std::string& message) {
  std::cerr << "plate_convergence: " << message << "\nusage: plate_convergence [--max N] [--csv FILE]\n"
            << "  --max N     largest grid (a power of two >= 8; default 64)\n"
            << "  --csv FILE  also write the rows as CSV to FILE\n";
  std::exit(2);
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") usage_error("mesh convergence of square plates");
    if (i + 1 >= argc) usage_error("missing value after " + arg);
    const std::string value = argv[++i];
    if (arg == "--max") {
      char* end = nullptr;
      const long n = std::strtol(value.c_str(), &end, 10);
      if (*end != '\0' || n < 8 || n > 1024 || (n & (n - 1)) != 0)
        usage_error("--max must be a power of two between 8 and 1024, got '" + value + "'");
      o.max_divisions = static_cast<int>(n);
    } else if (arg == "--csv") {
      o.csv_path = value;
    } else {
      usage_error("unknown option " + arg);
    }
  }
  return o;
}

std::string format(const char* fmt, double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, x);
  return buf;
}

Row run(const AnalyticPlate& c, Quadrature rule, int divisions) {
  const Problem p = plate_problem(c, divisions, rule, kSide);
  const int centre = nearest_vertex(p.mesh, Eigen::Vector3d::Zero());
  const StaticResult r = solve_static(p);

  Row row;
  row.case_name = c.label;
  row.quadrature = to_string(rule);
  row.mesh = std::to_string(divisions) + "×" + std::to_string(divisions);
  row.vertices = p.mesh.num_vertices();
  row.dofs = r.dofs;
  row.deflection = -r.limit_displacement(centre, 2);  // downward deflection, positive [m]
  row.reference = plate_reference_deflection(c, p, kSide);
  row.error_percent = 100.0 * (row.deflection - row.reference) / row.reference;
  row.assemble_seconds = r.assemble_seconds;
  row.solve_seconds = r.solve_seconds;
  return row;
}

void write_markdown(std::ostream& out, const Row& r) {
  out << "| " << r.case_name << " | " << r.quadrature << " | " << r.mesh << " | " << r.vertices << " | " << r.dofs
      << " | " << format("%.6e", r.deflection) << " | " << format("%.6e", r.reference) << " | "
      << format("%+.4f", r.error_percent) << " | " << (r.order ? format("%.2f", *r.order) : "") << " | "
      << format("%.3f", r.assemble_seconds) << " | " << format("%.3f", r.solve_seconds) << " |\n";
}

void write_csv(std::ostream& out, const Row& r) {
  out << '"' << r.case_name << "\"," << r.quadrature << ',' << r.mesh << ',' << r.vertices << ',' << r.dofs << ','
      << format("%.9e", r.deflection) << ',' << format("%.9e", r.reference) << ','
      << format("%.6f", r.error_percent) << ',' << (r.order ? format("%.4f", *r.order) : "") << ','
      << format("%.6f", r.assemble_seconds) << ',' << format("%.6f", r.solve_seconds) << '\n';
}

int main_impl(int argc, char** argv) {
  const Options opt = parse(argc, argv);
  std::ofstream csv;
  if (!opt.csv_path.empty()) {
    csv.open(opt.csv_path);
    if (!csv) {
      std::cerr << "plate_convergence: cannot write " << opt.csv_path << '\n';
      return 1;
    }
    csv << "case,quadrature,mesh,vertices,dofs,centre_deflection_m,reference_m,error_percent,observed_order,"
           "assemble_s,solve_s\n";
  }

  std::cout << "| case | quadrature | mesh | vertices | dofs | centre deflection [m] | reference [m] | error % "
               "| observed order | assemble s | solve s |\n"
            << "|---|---|---|--:|--:|--:|--:|--:|--:|--:|--:|\n";
  for (const AnalyticPlate& c : kAnalyticPlates) {
    for (const Quadrature rule : kRules) {
      std::optional<double> previous_error;
      for (int n = 8; n <= opt.max_divisions; n *= 2) {
        Row row = run(c, rule, n);
        const double error = std::abs(row.error_percent);
        if (previous_error && error > 0) row.order = std::log2(*previous_error / error);
        previous_error = error;
        write_markdown(std::cout, row);
        std::cout.flush();
        if (csv) write_csv(csv, row);
      }
    }
  }
  return 0;
}

}  // namespace
}  // namespace clothsim

int main(int argc, char** argv) {
  try {
    return clothsim::main_impl(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "plate_convergence: " << e.what() << '\n';
    return 1;
  }
}
