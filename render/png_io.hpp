// Reading and writing 8-bit RGB PNG files with libpng. Written files carry no timestamp or
// text chunks, so equal images give byte-identical files (rows Paeth-filtered, run-length
// deflated: fast to write, see png_io.cpp).
#pragma once

#include <string>

#include "render/image.hpp"

namespace clothsim::render {

// Writes `image` as an 8-bit RGB PNG. The data go to a temporary file next to `path` that is
// then renamed over it, so a failure never leaves a partial file at `path`. Throws
// std::invalid_argument for an inconsistent image and std::runtime_error naming the path if
// the file cannot be written.
void write_png(const std::string& path, const Image& image);

// Reads an 8-bit (or lower bit depth) grey, grey+alpha, palette, RGB or RGBA PNG and converts it
// to RGB (grey is replicated, alpha is dropped, 16-bit samples keep their high byte). Throws
// std::runtime_error naming the path if the file is missing, not a PNG or corrupt.
Image read_png(const std::string& path);

}  // namespace clothsim::render
