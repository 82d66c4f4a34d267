// `clothsim compare A B`: compares two PNG images, or the PNG images of two folders (a run's
// frame_NNNN.png / limit.png, a `clothsim render` output, ...) pairwise by file name, with
// per-image pixel statistics, difference images and a pass/fail verdict within a tolerance. The
// same comparison decides `clothsim golden check` (app/golden.hpp).
#pragma once

#include "render/image.hpp"
#include "render/image_compare.hpp"

#include <filesystem>
#include <string>

namespace clothsim {

// When two images count as the same. The defaults are the project's golden-image tolerance
// (tests/golden/README.md): a pixel differs if one of its channels differs by more than 8 of
// 255, and at most 0.5 % of the pixels may differ.
struct ImageTolerance {
  int channel = 8;              // --tolerance N, 0..255
  double max_fraction = 0.005;  // --max-differing P (in percent on the command line), 0..1
};

// The exit codes of `clothsim compare` and `clothsim golden`.
inline constexpr int kExitSame = 0;       // every image within the tolerance
inline constexpr int kExitDifferent = 1;  // some image differs, has another size, or is missing
inline constexpr int kExitError = 2;      // usage error, unreadable input, output not writable

// The comparison of one pair of images.
struct ImageComparison {
  std::string name;  // what is compared (the file name when comparing folders)
  bool in_a = true, in_b = true;  // false: the image exists in one folder only
  int width_a = 0, height_a = 0, width_b = 0, height_b = 0;
  render::CompareResult stats;  // when both exist and have the same size
  bool same = false;            // within the tolerance (never for a size mismatch or a missing image)
};

// Compares two decoded images; `diff`, if not null and the sizes agree, receives
// min(255, 4 · |a − b|) per channel (and is left empty otherwise).
ImageComparison compare_pictures(const std::string& name, const render::Image& a, const render::Image& b,
                                 const ImageTolerance& tolerance, render::Image* diff);

// One line for the report: "NAME: same|DIFFERENT, WxH, largest channel difference M, mean X,
// P % of the pixels (K) differ by more than N", or the size mismatch, or "only in A|B".
std::string describe(const ImageComparison& c, const ImageTolerance& tolerance);

// The statistics part of describe() for a pair of equal size: "WxH, largest channel difference
// M, mean X, P % of the pixels (K) differ by more than N".
std::string describe_statistics(const ImageComparison& c, const ImageTolerance& tolerance);

// What the tolerance means, for report headers: "a pixel differs if a channel differs by more
// than 8 (of 255); images are the same if at most 0.5 % of their pixels differ".
std::string describe(const ImageTolerance& tolerance);

// `clothsim compare A B [--diff PATH]`: A and B both PNG files or both folders. Prints one line
// per pair and a summary to stdout. `diff` (empty: none) is a PNG file for two files, a folder for
// two folders (published whole, with one difference image per pair of equal size under the
// frame's name and the report compare.txt; an existing folder is replaced only if it holds a
// compare.txt). Returns kExitSame, kExitDifferent or kExitError (message on stderr).
int compare_command(const std::filesystem::path& a, const std::filesystem::path& b, const ImageTolerance& tolerance,
                    const std::filesystem::path& diff);

}  // namespace clothsim
