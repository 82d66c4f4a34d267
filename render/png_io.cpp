// libpng-based PNG reading and writing. libpng reports errors by longjmp: the functions that
// call it keep only trivially destructible locals between setjmp and the libpng calls, and turn
// a failure into a C++ exception after control is back in ordinary code.
#include "render/png_io.hpp"

#include <png.h>
#include <zlib.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <system_error>
#include <vector>

namespace clothsim::render {
namespace {

struct ErrorBuffer {
  char message[256] = "unknown libpng error";
};

void on_png_error(png_structp png, png_const_charp message) {
  auto* buffer = static_cast<ErrorBuffer*>(png_get_error_ptr(png));
  if (buffer != nullptr && message != nullptr) {
    std::snprintf(buffer->message, sizeof(buffer->message), "%s", message);
  }
  png_longjmp(png, 1);
}

void on_png_warning(png_structp, png_const_charp) {}

// Encodes rows into an open file. Returns false (with the message in `error`) on failure.
bool encode(std::FILE* file, int width, int height, png_bytep* rows, ErrorBuffer* error) {
  png_structp png =
      png_create_write_struct(PNG_LIBPNG_VER_STRING, error, on_png_error, on_png_warning);
  if (png == nullptr) return false;
  png_infop info = png_create_info_struct(png);
  if (info == nullptr) {
    png_destroy_write_struct(&png, nullptr);
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_init_io(png, file);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8,
               PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  // Every row Paeth-filtered and run-length deflated: libpng's default (all five filters tried
  // on every row, deflate level 6) took 4-5 times as long on 1280 x 720 frames for files
  // 5-15 % smaller (docs/performance.md, Rendering). The bytes depend only on the pixels.
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_PAETH);
  png_set_compression_strategy(png, Z_RLE);
  png_write_info(png, info);
  png_write_image(png, rows);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

struct Decoded {
  png_uint_32 width = 0;
  png_uint_32 height = 0;
};

// Decodes an open PNG in two steps: read_header() reads the size and sets up conversion to
// 8-bit RGB, then read_rows() decodes into rows the caller has allocated.
class Decoder {
 public:
  Decoder(std::FILE* file, ErrorBuffer* error) : file_(file), error_(error) {}
  Decoder(const Decoder&) = delete;
  Decoder& operator=(const Decoder&) = delete;
  ~Decoder() {
    if (png_ != nullptr)
      png_destroy_read_struct(&png_, info_ != nullptr ? &info_ : nullptr, nullptr);
  }

  bool read_header(Decoded* out) {
    png_ = png_create_read_struct(PNG_LIBPNG_VER_STRING, error_, on_png_error, on_png_warning);
    if (png_ == nullptr) return false;
    info_ = png_create_info_struct(png_);
    if (info_ == nullptr) return false;
    if (setjmp(png_jmpbuf(png_))) return false;
    png_init_io(png_, file_);
    png_read_info(png_, info_);
    const int color_type = png_get_color_type(png_, info_);
    if (png_get_bit_depth(png_, info_) == 16) png_set_strip_16(png_);
    if (color_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png_);
    if (color_type == PNG_COLOR_TYPE_GRAY || color_type == PNG_COLOR_TYPE_GRAY_ALPHA) {
      png_set_expand_gray_1_2_4_to_8(png_);
      png_set_gray_to_rgb(png_);
    }
    if ((color_type & PNG_COLOR_MASK_ALPHA) != 0) png_set_strip_alpha(png_);
    if (png_get_valid(png_, info_, PNG_INFO_tRNS) != 0) {
      // Transparency chunks would otherwise be expanded into an alpha channel: ignore them.
      png_set_tRNS_to_alpha(png_);
      png_set_strip_alpha(png_);
    }
    png_set_interlace_handling(png_);
    png_read_update_info(png_, info_);
    if (png_get_channels(png_, info_) != 3 || png_get_bit_depth(png_, info_) != 8) {
      std::snprintf(error_->message, sizeof(error_->message),
                    "unsupported PNG format (cannot convert to 8-bit RGB)");
      return false;
    }
    out->width = png_get_image_width(png_, info_);
    out->height = png_get_image_height(png_, info_);
    return true;
  }

  bool read_rows(png_bytep* rows) {
    if (setjmp(png_jmpbuf(png_))) return false;
    png_read_image(png_, rows);
    png_read_end(png_, nullptr);
    return true;
  }

 private:
  std::FILE* file_;
  ErrorBuffer* error_;
  png_structp png_ = nullptr;
  png_infop info_ = nullptr;
};

std::string temporary_path_for(const std::string& path) {
  static std::atomic<unsigned long> counter{0};
  return path + ".tmp-" + std::to_string(static_cast<long>(::getpid())) + "-" +
         std::to_string(counter.fetch_add(1));
}

}  // namespace

void write_png(const std::string& path, const Image& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgb.size() !=
          3 * static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height)) {
    throw std::invalid_argument("write_png " + path + ": image size " +
                                std::to_string(image.width) + " x " + std::to_string(image.height) +
                                " does not match its " + std::to_string(image.rgb.size()) +
                                " bytes");
  }
  std::vector<png_bytep> rows(static_cast<std::size_t>(image.height));
  const std::size_t stride = 3 * static_cast<std::size_t>(image.width);
  for (std::size_t y = 0; y < rows.size(); ++y) {
    // libpng only reads the rows when writing.
    rows[y] = const_cast<png_bytep>(image.rgb.data() + y * stride);
  }

  const std::string temporary = temporary_path_for(path);
  std::FILE* file = std::fopen(temporary.c_str(), "wb");
  if (file == nullptr) {
    throw std::runtime_error("write_png: cannot open " + path +
                             " for writing: " + std::strerror(errno));
  }
  ErrorBuffer error;
  bool ok = encode(file, image.width, image.height, rows.data(), &error);
  std::string reason = ok ? "" : error.message;
  if (std::fflush(file) != 0 && ok) {
    ok = false;
    reason = std::strerror(errno);
  }
  if (std::fclose(file) != 0 && ok) {
    ok = false;
    reason = std::strerror(errno);
  }
  std::error_code ec;
  if (ok) {
    std::filesystem::rename(temporary, path, ec);
    if (ec) {
      ok = false;
      reason = ec.message();
    }
  }
  if (!ok) {
    std::filesystem::remove(temporary, ec);
    throw std::runtime_error("write_png: writing " + path + " failed: " + reason);
  }
}

Image read_png(const std::string& path) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) {
    throw std::runtime_error("read_png: cannot open " + path + ": " + std::strerror(errno));
  }
  unsigned char signature[8] = {};
  const bool is_png = std::fread(signature, 1, sizeof(signature), file) == sizeof(signature) &&
                      png_sig_cmp(signature, 0, sizeof(signature)) == 0;
  if (!is_png) {
    std::fclose(file);
    throw std::runtime_error("read_png: " + path + " is not a PNG file");
  }
  std::rewind(file);

  ErrorBuffer error;
  Image image;
  bool ok = false;
  {
    Decoder decoder(file, &error);
    Decoded header;
    if (decoder.read_header(&header)) {
      image.width = static_cast<int>(header.width);
      image.height = static_cast<int>(header.height);
      const std::size_t stride = 3 * static_cast<std::size_t>(header.width);
      image.rgb.resize(stride * header.height);
      std::vector<png_bytep> rows(header.height);
      for (std::size_t y = 0; y < rows.size(); ++y) rows[y] = image.rgb.data() + y * stride;
      ok = decoder.read_rows(rows.data());
    }
  }
  std::fclose(file);
  if (!ok) throw std::runtime_error("read_png: reading " + path + " failed: " + error.message);
  return image;
}

}  // namespace clothsim::render
