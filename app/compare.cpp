// clothsim compare: pairs of PNG images, their statistics (render/image_compare.hpp) and the
// report.
#include "app/compare.hpp"

#include "app/command_output.hpp"
#include "app/output_folders.hpp"
#include "render/png_io.hpp"

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <map>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

namespace clothsim {
namespace {

namespace fs = std::filesystem;

// The marker of a --diff folder.
const char* const kReportName = "compare.txt";

std::string size_text(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

std::string fixed(double v, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, v);
  return buffer;
}

// The PNG files directly in `dir` (not hidden), by file name.
std::map<std::string, fs::path> png_files(const fs::path& dir) {
  std::map<std::string, fs::path> files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name.empty() || name.front() == '.' || entry.path().extension() != ".png") continue;
    if (entry.is_regular_file(ec)) files[name] = entry.path();
  }
  return files;
}

}  // namespace

ImageComparison compare_pictures(const std::string& name, const render::Image& a, const render::Image& b,
                                 const ImageTolerance& tolerance, render::Image* diff) {
  ImageComparison c;
  c.name = name;
  c.width_a = a.width;
  c.height_a = a.height;
  c.width_b = b.width;
  c.height_b = b.height;
  if (diff != nullptr) *diff = render::Image{};
  if (a.width != b.width || a.height != b.height) return c;
  c.stats = render::compare_images(a, b, tolerance.channel, diff);
  c.same = c.stats.fraction_over <= tolerance.max_fraction;
  return c;
}

std::string describe(const ImageComparison& c, const ImageTolerance& tolerance) {
  std::string line = c.name + ": ";
  if (!c.in_a) return line + "DIFFERENT: only in B";
  if (!c.in_b) return line + "DIFFERENT: only in A";
  if (c.width_a != c.width_b || c.height_a != c.height_b)
    return line + "DIFFERENT: size " + size_text(c.width_a, c.height_a) + " vs " + size_text(c.width_b, c.height_b);
  return line + (c.same ? "same, " : "DIFFERENT, ") + describe_statistics(c, tolerance);
}

std::string describe_statistics(const ImageComparison& c, const ImageTolerance& tolerance) {
  const long pixels = static_cast<long>(c.width_a) * c.height_a;
  const long over = static_cast<long>(c.stats.fraction_over * static_cast<double>(pixels) + 0.5);
  return size_text(c.width_a, c.height_a) + ", largest channel difference " +
         std::to_string(static_cast<int>(c.stats.max_abs)) + ", mean " + fixed(c.stats.mean_abs, 3) + ", " +
         fixed(100 * c.stats.fraction_over, 3) + " % of the pixels (" + std::to_string(over) +
         ") differ by more than " + std::to_string(tolerance.channel);
}

std::string describe(const ImageTolerance& tolerance) {
  char percent[64];
  std::snprintf(percent, sizeof percent, "%g", 100 * tolerance.max_fraction);
  return "a pixel differs if a channel differs by more than " + std::to_string(tolerance.channel) +
         " (of 255); images are the same if at most " + percent + " % of their pixels differ";
}

int compare_command(const fs::path& a, const fs::path& b, const ImageTolerance& tolerance, const fs::path& diff) {
  try {
    for (const fs::path& p : {a, b})
      if (!fs::exists(p)) throw std::runtime_error(p.string() + ": no such file or folder");
    const bool folders = fs::is_directory(a);
    if (folders != fs::is_directory(b))
      throw std::runtime_error("compare two PNG files or two folders (" + a.string() + " is " +
                               (folders ? "a folder" : "a file") + ", " + b.string() + " is " +
                               (folders ? "a file" : "a folder") + ")");
    if (!folders) {
      if (!diff.empty() && fs::is_directory(diff))
        throw std::runtime_error("--diff: " + diff.string() + " is a folder; comparing two files writes one PNG file");
      render::Image picture;
      const ImageComparison c = compare_pictures(a.filename().string() + " vs " + b.filename().string(),
                                                 render::read_png(a.string()), render::read_png(b.string()),
                                                 tolerance, diff.empty() ? nullptr : &picture);
      std::cout << describe(c, tolerance) << '\n';
      if (!diff.empty()) {
        if (picture.rgb.empty()) {
          std::cout << "no difference image: the sizes differ\n";
        } else {
          render::write_png(diff.string(), picture);
          std::cout << "difference image (4 x |A - B| per channel): " << diff.string() << '\n';
        }
      }
      return c.same ? kExitSame : kExitDifferent;
    }

    const std::map<std::string, fs::path> in_a = png_files(a), in_b = png_files(b);
    if (in_a.empty() && in_b.empty())
      throw std::runtime_error(a.string() + " and " + b.string() + " hold no PNG images");
    std::vector<std::string> names;
    for (const auto& [name, path] : in_a) names.push_back(name);
    for (const auto& [name, path] : in_b)
      if (in_a.count(name) == 0) names.push_back(name);
    std::sort(names.begin(), names.end());

    const fs::path diff_dir = diff.empty() ? fs::path() : output_folder_path(diff, "--diff");
    std::string report = "clothsim compare " + a.string() + " " + b.string() + "\n" + describe(tolerance) + "\n";
    int same = 0;
    // Compares every pair, writing each difference image into `staging` (none if empty) at once,
    // so that only one pair of images is in memory.
    const auto compare_all = [&](const fs::path& staging) {
      for (const std::string& name : names) {
        const auto ia = in_a.find(name), ib = in_b.find(name);
        ImageComparison c;
        c.name = name;
        if (ia == in_a.end() || ib == in_b.end()) {
          c.in_a = ia != in_a.end();
          c.in_b = ib != in_b.end();
        } else {
          render::Image picture;
          c = compare_pictures(name, render::read_png(ia->second.string()), render::read_png(ib->second.string()),
                               tolerance, staging.empty() ? nullptr : &picture);
          if (!picture.rgb.empty()) render::write_png((staging / name).string(), picture);
        }
        same += c.same ? 1 : 0;
        const std::string line = describe(c, tolerance);
        std::cout << line << '\n';
        report += line + "\n";
      }
    };
    const auto summary = [&] {
      return "compare: " + std::to_string(names.size()) + " image(s): " + std::to_string(same) + " the same, " +
             std::to_string(names.size() - static_cast<std::size_t>(same)) + " different (" + describe(tolerance) +
             ")";
    };
    if (diff_dir.empty()) {
      compare_all(fs::path());
    } else {
      publish_folder(diff_dir, kReportName, "--diff", [&](const fs::path& staging) {
        compare_all(staging);
        write_text_file(staging / kReportName, report + summary() + "\n");
      });
    }
    std::cout << summary() << '\n';
    if (!diff_dir.empty())
      std::cout << "difference images (4 x |A - B| per channel) and " << kReportName << ": " << diff_dir.string()
                << '\n';
    const int different = static_cast<int>(names.size()) - same;
    return different == 0 ? kExitSame : kExitDifferent;
  } catch (const std::exception& e) {
    std::cerr << "clothsim: error: " << e.what() << '\n';
    return kExitError;
  }
}

}  // namespace clothsim
