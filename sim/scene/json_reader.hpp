// The scene files' JSON reader (internal to sim/scene/): parsing with the duplicate-key check,
// the --set overrides, and the typed, checked access to the tree through which every key of a scene
// is read (Reader: every failure a SceneError naming the file and the key path). The sections'
// keys, types, defaults and ranges are read in read_settings.cpp; meshes and the problem are
// built from what was read in build_mesh.cpp and scene.cpp.
#pragma once

#include "sim/core/log.hpp"
#include "sim/scene/scene.hpp"

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace clothsim::scene_io {

using Json = nlohmann::json;

std::string join_key(const std::string& path, const std::string& key);

std::string join_index(const std::string& path, std::size_t index);

// A string as a JSON string literal (quoted, escaped). Bytes that are not UTF-8 (a file name, a
// long string cut inside a character by describe) become U+FFFD: dump() would throw.
std::string quote(const std::string& s);

// A double in its shortest round-trip form.
std::string format_number(double v);

std::string format_point(const Eigen::Vector3d& p);

// "a, b, c" or, quoted, "\"a\", \"b\", \"c\"".
std::string format_list(const std::vector<std::string>& items, bool quoted);

// What a JSON value is, for "(got ...)" in type errors.
std::string describe(const Json& j);

// At most this many characters, so that the output folder and its temporary siblings
// (".<name>.tmp-<pid>", ".<name>.old-<pid>") fit a file name (255 bytes on common file systems).
constexpr std::size_t kMaxNameLength = 200;

bool is_safe_name(const std::string& name);

// `text` with every control character (below 0x20, and 0x7f) written as \uXXXX.
std::string printable(const std::string& text);

// " (set by --set a=1, --set b=2)" for the overrides whose key paths are related to `path`, or "".
std::string override_note(const std::string& path, const std::vector<std::pair<std::string, std::string>>& overrides);

// "; did you mean \"x\"?" when `given` is close to one of `allowed`, otherwise "".
std::string did_you_mean(const std::string& given, const std::vector<std::string>& allowed);

// Typed, checked access to the JSON tree; every failure throws SceneError naming file and key.
class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  // Control characters (a NUL in a key would cut the message short) are written as \uXXXX. A
  // problem at a key that a --set override wrote (or inside it, or around it) names the override.
  [[noreturn]] void fail(const std::string& path, const std::string& problem) const {
    throw SceneError(printable(file_ + ": " + (path.empty() ? std::string() : path + ": ") + problem +
                               override_note(path, overrides_)));
  }

  // The key paths (as in messages: "boundary[0].rotation") that --set overrides wrote, each with
  // its argument as given.
  void set_overrides(std::vector<std::pair<std::string, std::string>> overrides) { overrides_ = std::move(overrides); }

  // `j` must be an object whose keys are all in `allowed`.
  void check_object(const Json& j, const std::string& path,
                    const std::vector<std::string>& allowed) const {
    if (!j.is_object()) fail(path, "expected an object (got " + describe(j) + ")");
    for (auto it = j.begin(); it != j.end(); ++it) {
      bool known = false;
      for (const std::string& a : allowed) known = known || a == it.key();
      if (!known)
        fail(join_key(path, it.key()),
             "unknown key (allowed: " + format_list(allowed, false) + ")" + did_you_mean(it.key(), allowed));
    }
  }

  const Json* find(const Json& object, const std::string& key) const {
    auto it = object.find(key);
    return it == object.end() ? nullptr : &*it;
  }

  const Json& require(const Json& object, const std::string& path, const std::string& key) const {
    const Json* j = find(object, key);
    if (j == nullptr) fail(join_key(path, key), "required key is missing");
    return *j;
  }

  const Json& array(const Json& j, const std::string& path) const {
    if (!j.is_array()) fail(path, "expected an array (got " + describe(j) + ")");
    return j;
  }

  double number(const Json& j, const std::string& path) const {
    if (!j.is_number()) fail(path, "expected a number (got " + describe(j) + ")");
    const double v = j.get<double>();
    if (!std::isfinite(v)) fail(path, "must be a finite number");
    return v;
  }

  int integer(const Json& j, const std::string& path) const {
    if (!j.is_number_integer()) fail(path, "expected an integer (got " + describe(j) + ")");
    const bool fits = j.is_number_unsigned()
                          ? j.get<std::uint64_t>() <= static_cast<std::uint64_t>(std::numeric_limits<int>::max())
                          : (j.get<std::int64_t>() >= std::numeric_limits<int>::min() &&
                             j.get<std::int64_t>() <= std::numeric_limits<int>::max());
    if (!fits) fail(path, "integer out of range (got " + j.dump() + ")");
    return static_cast<int>(j.get<std::int64_t>());
  }

  bool boolean(const Json& j, const std::string& path) const {
    if (!j.is_boolean()) fail(path, "expected true or false (got " + describe(j) + ")");
    return j.get<bool>();
  }

  std::string string(const Json& j, const std::string& path) const {
    if (!j.is_string()) fail(path, "expected a string (got " + describe(j) + ")");
    return j.get<std::string>();
  }

  // One of `allowed`; `what` names the thing in the error ("value", "component", ...).
  std::string choice(const Json& j, const std::string& path, const std::vector<std::string>& allowed,
                     const std::string& what = "value") const {
    if (!j.is_string())
      fail(path, "expected a string (got " + describe(j) + "; allowed: " + format_list(allowed, true) + ")");
    const std::string s = j.get<std::string>();
    for (const std::string& a : allowed)
      if (a == s) return s;
    fail(path, "unknown " + what + " " + quote(s) + " (allowed: " + format_list(allowed, true) + ")" +
                   did_you_mean(s, allowed));
  }

  Eigen::Vector3d vec3(const Json& j, const std::string& path) const {
    if (!j.is_array() || j.size() != 3)
      fail(path, "expected an array of 3 numbers (got " + describe(j) + ")");
    Eigen::Vector3d v;
    for (int k = 0; k < 3; ++k) {
      const auto idx = static_cast<std::size_t>(k);
      if (!j[idx].is_number())
        fail(path, "expected an array of 3 numbers (element " + std::to_string(k) + " is " +
                       describe(j[idx]) + ")");
      v[k] = number(j[idx], join_index(path, idx));
    }
    return v;
  }

  // Number > 0 (`unit` like "[m]").
  double positive(const Json& j, const std::string& path, const std::string& unit) const {
    const double v = number(j, path);
    if (!(v > 0)) fail(path, "must be > 0 " + unit + " (got " + j.dump() + ")");
    return v;
  }

  double non_negative(const Json& j, const std::string& path, const std::string& unit) const {
    const double v = number(j, path);
    if (!(v >= 0)) fail(path, "must be >= 0 " + unit + " (got " + j.dump() + ")");
    return v;
  }

  int integer_at_least(const Json& j, const std::string& path, int minimum) const {
    const int v = integer(j, path);
    if (v < minimum)
      fail(path, "must be an integer >= " + std::to_string(minimum) + " (got " + j.dump() + ")");
    return v;
  }

  // An array of exactly `n` elements.
  const Json& sized_array(const Json& j, const std::string& path, std::size_t n,
                          const std::string& of) const {
    if (!j.is_array() || j.size() != n)
      fail(path, "expected an array of " + std::to_string(n) + " " + of + " (got " + describe(j) + ")");
    return j;
  }

 private:
  std::string file_;
  std::vector<std::pair<std::string, std::string>> overrides_;
};

Json parse_file(const Reader& r, const std::filesystem::path& file);

Json parse_text(const Reader& r, const std::string& text);

// `text`, shortened to its first 80 characters for an error message.
std::string shortened(const std::string& text);

// Applies one --set argument "key.path=value" to `root`; returns the key path in the messages'
// form ("boundary[0].rotation"). The value is JSON if it parses as JSON, otherwise the text as a
// string; null removes the key (or the array element). Missing objects on the way are created;
// an index equal to an array's length appends. Throws SceneError("--set <argument>: ...").
std::string apply_override(Json& root, const std::string& argument, const LogFn& log);

}  // namespace clothsim::scene_io
