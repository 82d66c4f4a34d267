// Scene loader: parses a scene file with nlohmann::json, checks every key, type and range (the
// messages carry the file and the key path), builds the mesh, the Problem and, for dynamic
// scenes, the Problem.
#include "sim/scene/scene.hpp"
#include "sim/scene/render_settings_json.hpp"

#include "sim/mesh/cracks.hpp"
#include "sim/mesh/imperfection.hpp"

#include "sim/mesh/generators.hpp"
#include "sim/mesh/grain.hpp"
#include "sim/mesh/obj_io.hpp"
#include "sim/problem/validate.hpp"
#include "sim/setup/setup.hpp"
#include "sim/shell/material_presets.hpp"

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <system_error>
#include <utility>

namespace clothsim {
namespace {

using Json = nlohmann::json;

const char* const kAxes[3] = {"x", "y", "z"};

// Top-level keys that only a dynamic scene may have.
const char* const kDynamicOnlyKeys[] = {"time", "damping", "solver", "corotational", "initial", "output", "collision",
                                        "obstacles"};

const char* const kNeedsDynamic = "needs \"analysis\": \"dynamic\" (this scene is static)";

std::string join_key(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

std::string join_index(const std::string& path, std::size_t index) {
  return path + "[" + std::to_string(index) + "]";
}

// A string as a JSON string literal (quoted, escaped). Bytes that are not UTF-8 (a file name, a
// long string cut inside a character by describe) become U+FFFD: dump() would throw.
std::string quote(const std::string& s) { return Json(s).dump(-1, ' ', false, Json::error_handler_t::replace); }

// A double in its shortest round-trip form.
std::string format_number(double v) { return Json(v).dump(); }

std::string format_point(const Eigen::Vector3d& p) {
  std::string out = "[";
  for (int k = 0; k < 3; ++k) out.append(k > 0 ? ", " : "").append(format_number(p[k]));
  return out.append("]");
}

// "a, b, c" or, quoted, "\"a\", \"b\", \"c\"".
std::string format_list(const std::vector<std::string>& items, bool quoted) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (i > 0) out += ", ";
    out += quoted ? quote(items[i]) : items[i];
  }
  return out;
}

// What a JSON value is, for "(got ...)" in type errors.
std::string describe(const Json& j) {
  switch (j.type()) {
    case Json::value_t::array: return "an array of " + std::to_string(j.size());
    case Json::value_t::object: return "an object";
    case Json::value_t::string: {
      const std::string s = j.get<std::string>();
      return s.size() > 40 ? quote(s.substr(0, 40) + "...") : quote(s);
    }
    default: return j.dump();
  }
}

// At most this many characters, so that the output folder and its temporary siblings
// (".<name>.tmp-<pid>", ".<name>.old-<pid>") fit a file name (255 bytes on common file systems).
constexpr std::size_t kMaxNameLength = 200;

bool is_safe_name(const std::string& name) {
  if (name.empty() || name.front() == '.' || name.size() > kMaxNameLength) return false;
  for (char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-' || c == '.';
    if (!ok) return false;
  }
  return true;
}

// Finds the first repeated key of any object while the parser runs (nlohmann keeps the last
// value silently), and remembers its key path.
class DuplicateKeyFinder {
 public:
  bool on_event(nlohmann::json::parse_event_t event, Json& parsed) {
    using E = nlohmann::json::parse_event_t;
    switch (event) {
      case E::object_start:
        element_starts();
        stack_.push_back({false, {}, 0, {}});
        break;
      case E::array_start:
        element_starts();
        stack_.push_back({true, {}, 0, {}});
        break;
      case E::object_end:
      case E::array_end:
        if (!stack_.empty()) stack_.pop_back();
        break;
      case E::key:
        if (!stack_.empty() && parsed.is_string()) {
          Frame& top = stack_.back();
          top.key = parsed.get<std::string>();
          if (!top.keys.insert(top.key).second && first_.empty()) first_ = path();
        }
        break;
      case E::value:
        element_starts();
        break;
    }
    return true;
  }
  const std::string& first_duplicate() const { return first_; }

 private:
  struct Frame {
    bool array;
    std::string key;        // current key (objects)
    std::size_t count;      // elements started so far (arrays)
    std::set<std::string> keys;
  };
  void element_starts() {
    if (!stack_.empty() && stack_.back().array) ++stack_.back().count;
  }
  std::string path() const {
    std::string p;
    for (const Frame& f : stack_) p = f.array ? join_index(p, f.count - 1) : join_key(p, f.key);
    return p;
  }
  std::vector<Frame> stack_;
  std::string first_;
};

// `text` with every control character (below 0x20, and 0x7f) written as \uXXXX.
std::string printable(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7f) {
      char buffer[8];
      std::snprintf(buffer, sizeof buffer, "\\u%04x", static_cast<unsigned>(u));
      out += buffer;
    } else {
      out += c;
    }
  }
  return out;
}

// Whether key path `a` is `b` or contains it or lies inside it ("time" and "time.end";
// "boundary[0]" and "boundary[0].fix[1]"; not "time" and "timestep").
bool paths_related(const std::string& a, const std::string& b) {
  const std::string& shorter = a.size() <= b.size() ? a : b;
  const std::string& longer = a.size() <= b.size() ? b : a;
  if (shorter.empty() || longer.compare(0, shorter.size(), shorter) != 0) return false;
  return longer.size() == shorter.size() || longer[shorter.size()] == '.' || longer[shorter.size()] == '[';
}

// " (set by --set a=1, --set b=2)" for the overrides whose key paths are related to `path`, or "".
std::string override_note(const std::string& path, const std::vector<std::pair<std::string, std::string>>& overrides) {
  std::string note;
  for (const auto& [key, argument] : overrides)
    if (paths_related(path, key)) note += (note.empty() ? " (set by --set " : ", --set ") + argument;
  return note.empty() ? note : note + ")";
}

// "; did you mean \"x\"?" when `given` is close to one of `allowed`, otherwise "".
std::string did_you_mean(const std::string& given, const std::vector<std::string>& allowed) {
  const std::string best = closest_name(given, allowed);
  return best.empty() ? best : "; did you mean " + quote(best) + "?";
}

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

Json parse_text(const Reader& r, const std::string& text);

Json parse_file(const Reader& r, const std::filesystem::path& file) {
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec)) r.fail("", "is a directory, not a scene file");
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    const bool exists = std::filesystem::exists(file, ec);
    r.fail("", exists ? "cannot open the scene file for reading" : "cannot open the scene file (no such file)");
  }
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) r.fail("", "cannot read the scene file");
  return parse_text(r, text.str());
}

Json parse_text(const Reader& r, const std::string& text) {
  DuplicateKeyFinder duplicates;
  Json j;
  try {
    j = Json::parse(text, [&duplicates](int, nlohmann::json::parse_event_t event, Json& parsed) {
      return duplicates.on_event(event, parsed);
    });
  } catch (const nlohmann::json::exception& e) {
    std::string message = e.what();
    // Drop nlohmann's "[json.exception.parse_error.101] " tag.
    if (!message.empty() && message.front() == '[') {
      const auto close = message.find("] ");
      if (close != std::string::npos) message = message.substr(close + 2);
    }
    // nlohmann quotes everything it read of the bad token ("last read: '...'"): keep its end only.
    constexpr std::size_t kShown = 60;
    if (const auto at = message.find("last read: '"); at != std::string::npos) {
      const auto from = at + 12, to = message.rfind('\'');
      if (to != std::string::npos && to > from && to - from > kShown)
        message = message.substr(0, from) + "..." + message.substr(to - kShown);
    }
    r.fail("", "malformed JSON: " + message);
  }
  if (!duplicates.first_duplicate().empty())
    r.fail(duplicates.first_duplicate(), "duplicate key (each key may appear only once)");
  if (!j.is_object()) r.fail("", "expected a JSON object at the top level (got " + describe(j) + ")");
  return j;
}

// `text`, shortened to its first 80 characters for an error message.
std::string shortened(const std::string& text) {
  return text.size() > 80 ? text.substr(0, 77) + "..." : text;
}

// One step of an override's key path: an object key, or an array index written "[n]" (an object
// key of digits may also index an array: "boundary.0.fix").
struct KeyStep {
  std::string key;
  bool bracket = false;
};

[[noreturn]] void override_fail(const std::string& shown, const std::string& problem) {
  throw SceneError(printable(shown + ": " + problem));
}

// Applies one --set argument "key.path=value" to `root`; returns the key path in the messages'
// form ("boundary[0].rotation"). The value is JSON if it parses as JSON, otherwise the text as a
// string; null removes the key (or the array element). Missing objects on the way are created;
// an index equal to an array's length appends. Throws SceneError("--set <argument>: ...").
std::string apply_override(Json& root, const std::string& argument, const LogFn& log) {
  const std::string shown = "--set " + shortened(argument);
  const std::size_t equals = argument.find('=');
  if (equals == std::string::npos || equals == 0)
    override_fail(shown, "expected KEY=VALUE, e.g. --set time.end=0.5 or --set boundary[0].rotation=clamped");
  const std::string key = argument.substr(0, equals), text = argument.substr(equals + 1);

  // The key path: names separated by '.', each optionally followed by [n] indices.
  std::vector<KeyStep> steps;
  std::size_t pos = 0;
  while (true) {
    const std::size_t end = key.find_first_of(".[", pos);
    const std::string name = key.substr(pos, end == std::string::npos ? std::string::npos : end - pos);
    if (name.empty())
      override_fail(shown, "empty key name in " + quote(shortened(key)) + " (write a.b.c, a[0].b or a.0.b)");
    steps.push_back({name, false});
    pos = end;
    while (pos != std::string::npos && key[pos] == '[') {
      const std::size_t close = key.find(']', pos);
      const std::string index = close == std::string::npos ? "" : key.substr(pos + 1, close - pos - 1);
      if (index.empty() || index.size() > 9 || index.find_first_not_of("0123456789") != std::string::npos)
        override_fail(shown, "malformed index in " + quote(shortened(key)) + " (write [0], [1], ...)");
      steps.push_back({index, true});
      pos = close + 1 < key.size() ? close + 1 : std::string::npos;
    }
    if (pos == std::string::npos) break;
    if (key[pos] != '.') override_fail(shown, "expected '.' or '[' after ']' in " + quote(shortened(key)));
    ++pos;
  }

  // The value: JSON, or else the text as a string (a value that starts like JSON must be JSON).
  Json value;
  bool is_json = false;
  {
    DuplicateKeyFinder duplicates;
    try {
      value = Json::parse(text, [&duplicates](int, nlohmann::json::parse_event_t event, Json& parsed) {
        return duplicates.on_event(event, parsed);
      });
      is_json = true;
    } catch (const nlohmann::json::exception& e) {
      const std::size_t first = text.find_first_not_of(" \t\r\n");
      if (first != std::string::npos && (text[first] == '[' || text[first] == '{' || text[first] == '"')) {
        std::string message = e.what();
        const auto close = message.find("] ");
        if (!message.empty() && message.front() == '[' && close != std::string::npos) message = message.substr(close + 2);
        override_fail(shown, "the value is not valid JSON: " + shortened(message));
      }
    }
    if (!duplicates.first_duplicate().empty())
      override_fail(shown, "the value repeats the key " + quote(duplicates.first_duplicate()));
  }
  if (!is_json) value = text;
  const bool remove = value.is_null();

  Json* node = &root;
  std::string path;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const KeyStep& step = steps[i];
    const bool last = i + 1 == steps.size();
    const bool digits = step.key.find_first_not_of("0123456789") == std::string::npos && step.key.size() <= 9;
    if (node->is_object() && !step.bracket) {
      const std::string here = join_key(path, step.key);
      if (last) {
        if (remove)
          node->erase(step.key);
        else
          (*node)[step.key] = value;
        path = here;
        break;
      }
      if (!node->contains(step.key)) {
        if (remove) return here;  // nothing to remove
        (*node)[step.key] = Json::object();
      }
      node = &(*node)[step.key];
      path = here;
    } else if (node->is_array() && digits) {
      const auto index = static_cast<std::size_t>(std::stoul(step.key));
      const std::string here = join_index(path, index);
      if (index > node->size() || (index == node->size() && remove))
        override_fail(shown, (path.empty() ? std::string("the scene") : path) + " has " + std::to_string(node->size()) +
                                 (node->size() == 1 ? " element" : " elements") + "; index " + std::to_string(index) +
                                 " is out of range (" + std::to_string(node->size()) + " appends one)");
      if (last) {
        if (remove)
          node->erase(index);
        else if (index == node->size())
          node->push_back(value);
        else
          (*node)[index] = value;
        path = here;
        break;
      }
      if (index == node->size()) node->push_back(Json::object());
      node = &(*node)[index];
      path = here;
    } else if (node->is_array()) {
      override_fail(shown, path + " is an array: index it by number (" + path + "[0]." + step.key + " or " + path +
                               ".0." + step.key + "), not by " + quote(step.key));
    } else if (node->is_object()) {
      override_fail(shown, (path.empty() ? std::string("the scene") : path) + " is an object: " +
                               quote("[" + step.key + "]") + " indexes an array; write " + join_key(path, step.key));
    } else {
      override_fail(shown,
                    path + " is " + describe(*node) + ", not an object or array, so it has no key " + quote(step.key));
    }
  }
  if (log) log("--set " + path + (remove ? ": removed" : " = " + shortened(value.dump())));
  return path;
}

// "mesh.max_vertices": the largest vertex count the scene may have (default kDefaultMaxVertices),
// read first so that no mesh (nor obstacle OBJ) larger than that is ever allocated.
long long read_max_vertices(const Reader& r, const Json& root) {
  const Json* mesh = r.find(root, "mesh");
  if (mesh == nullptr || !mesh->is_object()) return kDefaultMaxVertices;
  const Json* v = r.find(*mesh, "max_vertices");
  return v == nullptr ? kDefaultMaxVertices : r.integer_at_least(*v, "mesh.max_vertices", 3);
}

// Fails at `path` if a generated mesh would have more than `max_vertices` vertices (`count`,
// computed in 64 bits by the caller before anything is allocated).
void check_vertex_count(const Reader& r, const std::string& path, const std::string& what, long long count,
                        long long max_vertices) {
  if (count > max_vertices)
    r.fail(path, what + " has " + std::to_string(count) + " vertices, more than mesh.max_vertices = " +
                     std::to_string(max_vertices) + " (raise mesh.max_vertices to allow it)");
}

// "material.grain": {"warp_deg": deg} (docs/materials.md, Grain): how the warp lies on the mesh.
struct GrainSpec {
  bool given = false;     // the key is present
  double warp_deg = 0.0;  // [deg], from the mesh's reference direction
  std::string needed_by;  // the key that needs the grain when it is not given ("material", "render.texture")
};

// The grain of an OBJ mesh: from its texture coordinates, or an error naming what is missing
// when the scene needs one (`need`: an orthotropic material or a "grain" key).
void obj_grain(const Reader& r, TriMesh& mesh, const GrainSpec& grain, bool need, const std::string& file) {
  if (!need) return;
  if (mesh.uv.empty()) {
    if (grain.given)
      r.fail("material.grain", "the mesh " + quote(file) +
                                   " has no texture coordinates (vt on every face) to measure the grain from");
    r.fail(grain.needed_by, std::string(grain.needed_by == "material" ? "an orthotropic material" : "\"grain\"") +
                                " needs the grain direction, and the mesh " + quote(file) +
                                " has no texture coordinates (vt on every face) to measure it from");
  }
  try {
    mesh.warp = uv_warp(mesh, grain.warp_deg);
  } catch (const std::exception& e) {
    r.fail(grain.given ? "material.grain" : grain.needed_by, quote(file) + ": " + e.what());
  }
}

TriMesh build_mesh_shape(const Reader& r, const Json& j, const std::filesystem::path& folder, const LogFn& log,
                         long long max_vertices, const GrainSpec& grain, bool need_grain) {
  const std::string path = "mesh";
  if (!j.is_object()) r.fail(path, "expected an object (got " + describe(j) + ")");
  const bool has_obj = j.contains("obj");
  const bool has_primitive = j.contains("primitive");
  if (has_obj && has_primitive) r.fail(path, "give either \"obj\" or \"primitive\", not both");
  if (!has_obj && !has_primitive)
    r.fail(path, "needs \"obj\" (a file) or \"primitive\" (allowed: \"grid\", \"cylinder\")");

  if (has_obj) {
    r.check_object(j, path, {"obj", "rotate", "translate", "max_vertices"});  // (the others: build_mesh)
    const std::string key = "mesh.obj";
    const std::string name = r.string(j["obj"], key);
    if (name.empty()) r.fail(key, "expected a non-empty file path");
    const std::filesystem::path obj = folder / name;
    try {
      TriMesh mesh = read_obj(obj.string(), max_vertices);
      log("mesh: " + obj.string() + ": " + std::to_string(mesh.num_vertices()) + " vertices, " +
          std::to_string(mesh.num_triangles()) + " triangles");
      obj_grain(r, mesh, grain, need_grain, name);
      return mesh;
    } catch (const SceneError&) {
      throw;
    } catch (const MeshLimitError& e) {
      r.fail(key, std::string(e.what()) + " (mesh.max_vertices = " + std::to_string(max_vertices) +
                      "; raise it to read larger meshes)");
    } catch (const std::exception& e) {
      r.fail(key, e.what());
    }
  }

  const std::string primitive = r.choice(j["primitive"], "mesh.primitive", {"grid", "cylinder"}, "primitive");
  TriMesh mesh;
  try {
    if (primitive == "grid") {
      r.check_object(j, path, {"primitive", "size", "divisions", "rotate", "translate", "max_vertices"});
      const Json& size = r.sized_array(r.require(j, path, "size"), "mesh.size", 2, "numbers");
      const Json& div = r.sized_array(r.require(j, path, "divisions"), "mesh.divisions", 2, "integers");
      const double sx = r.positive(size[0], "mesh.size[0]", "[m]");
      const double sy = r.positive(size[1], "mesh.size[1]", "[m]");
      const int dx = r.integer_at_least(div[0], "mesh.divisions[0]", 1);
      const int dy = r.integer_at_least(div[1], "mesh.divisions[1]", 1);
      check_vertex_count(r, "mesh.divisions", "a " + std::to_string(dx) + " x " + std::to_string(dy) + " grid",
                         (static_cast<long long>(dx) + 1) * (static_cast<long long>(dy) + 1), max_vertices);
      mesh = make_grid(sx, sy, dx, dy);
      if (need_grain) mesh.warp = grid_warp(mesh, grain.warp_deg);
      log("mesh: grid " + format_number(sx) + " m x " + format_number(sy) + " m, " + std::to_string(dx) +
          " x " + std::to_string(dy) + " divisions");
    } else {
      r.check_object(j, path,
                     {"primitive", "radius", "length", "segments", "rings", "angle_deg", "rotate", "translate",
                      "max_vertices"});
      const double radius = r.positive(r.require(j, path, "radius"), "mesh.radius", "[m]");
      const double length = r.positive(r.require(j, path, "length"), "mesh.length", "[m]");
      double angle = 360.0;
      if (const Json* a = r.find(j, "angle_deg")) {
        angle = r.positive(*a, "mesh.angle_deg", "[deg]");
        if (angle > 360.0) r.fail("mesh.angle_deg", "must be <= 360 [deg] (got " + a->dump() + ")");
      }
      const int segments = r.integer_at_least(r.require(j, path, "segments"), "mesh.segments", angle < 360.0 ? 1 : 3);
      const int rings = r.integer_at_least(r.require(j, path, "rings"), "mesh.rings", 2);
      check_vertex_count(r, "mesh", "a cylinder" + std::string(angle < 360.0 ? " panel" : "") + " of " +
                                        std::to_string(segments) + " segments x " + std::to_string(rings) + " rings",
                         (static_cast<long long>(segments) + (angle < 360.0 ? 1 : 0)) * static_cast<long long>(rings),
                         max_vertices);
      mesh = angle < 360.0 ? make_cylinder_panel(radius, length, angle, segments, rings)
                           : make_cylinder(radius, length, segments, rings);
      if (need_grain) mesh.warp = cylinder_warp(mesh, grain.warp_deg);
      log("mesh: cylinder r = " + format_number(radius) + " m, L = " + format_number(length) + " m, " +
          (angle < 360.0 ? "open panel of " + format_number(angle) + " deg, " : std::string()) +
          std::to_string(segments) + " segments, " + std::to_string(rings) + " rings");
    }
  } catch (const SceneError&) {
    throw;
  } catch (const std::exception& e) {
    r.fail(path, e.what());
  }
  return mesh;
}

// The mesh with its optional placement: "rotate": {"axis": [x, y, z], "angle_deg": a} about the
// origin, then "translate": [x, y, z] [m].
TriMesh build_mesh(const Reader& r, const Json& j, const std::filesystem::path& folder, const LogFn& log,
                   long long max_vertices, const GrainSpec& grain, bool need_grain) {
  if (!j.is_object()) r.fail("mesh", "expected an object (got " + describe(j) + ")");
  Json shape = j;
  shape.erase("max_vertices");  // (read by read_max_vertices)
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  if (const Json* rot = r.find(j, "rotate")) {
    r.check_object(*rot, "mesh.rotate", {"axis", "angle_deg"});
    const Eigen::Vector3d axis = r.vec3(r.require(*rot, "mesh.rotate", "axis"), "mesh.rotate.axis");
    if (!(axis.norm() > 0)) r.fail("mesh.rotate.axis", "must be a non-zero vector");
    const double angle = r.number(r.require(*rot, "mesh.rotate", "angle_deg"), "mesh.rotate.angle_deg");
    rotation = Eigen::AngleAxisd(angle * M_PI / 180.0, axis.normalized()).toRotationMatrix();
    shape.erase("rotate");
  }
  if (const Json* tr = r.find(j, "translate")) {
    translation = r.vec3(*tr, "mesh.translate");
    shape.erase("translate");
  }
  TriMesh mesh = build_mesh_shape(r, shape, folder, log, max_vertices, grain, need_grain);
  if (j.contains("rotate") || j.contains("translate")) {
    for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v)
      mesh.vertices.row(v) = (rotation * mesh.vertices.row(v).transpose() + translation).transpose();
    for (Eigen::Vector3d& w : mesh.warp) w = rotation * w;  // the grain turns with the mesh
    if (!mesh.vertices.allFinite())
      r.fail(j.contains("translate") ? "mesh.translate" : "mesh.rotate",
             "the placed mesh has a coordinate beyond the range of a double (overflow)");
    log("mesh: placed (rotated, then translated)");
  }
  return mesh;
}

// The orthotropic parts of "material" (scenes/README.md, Material): "stretch_modulus" and
// "bending_rigidity" as objects, or as numbers (isotropic) beside an object or an orthotropic
// preset. `base` is the material the other keys made (solid or preset); `poisson_json` the
// "poisson_ratio" key, if given.
ShellMaterial read_orthotropic(const Reader& r, const Json& j, const ShellMaterial& base, const Json* poisson_json,
                               double poisson) {
  Orthotropy o = base.orthotropic() ? *base.orthotropy : isotropic_orthotropy(base);
  bool twist_set = base.orthotropic();  // an orthotropic preset's twist stays unless its bending is replaced
  bool membrane_orthotropic = base.orthotropic();
  const Json* stretch = r.find(j, "stretch_modulus");
  if (stretch != nullptr && stretch->is_object()) {
    const std::string path = "material.stretch_modulus";
    r.check_object(*stretch, path, {"warp", "weft", "shear", "poisson"});
    o.warp_stretch = r.positive(r.require(*stretch, path, "warp"), path + ".warp", "[N/m]");
    o.weft_stretch = r.positive(r.require(*stretch, path, "weft"), path + ".weft", "[N/m]");
    o.shear_stretch = r.positive(r.require(*stretch, path, "shear"), path + ".shear", "[N/m]");
    o.poisson = r.non_negative(r.require(*stretch, path, "poisson"), path + ".poisson", "[-]");
    if (!(o.poisson * o.poisson < o.warp_stretch / o.weft_stretch))
      r.fail(path + ".poisson", "makes the membrane law indefinite: poisson^2 must be < warp/weft = " +
                                    format_number(o.warp_stretch / o.weft_stretch) + " (got " +
                                    format_number(o.poisson) + "; nu_warp,weft * nu_weft,warp must be < 1)");
    membrane_orthotropic = true;
  } else if (stretch != nullptr) {
    const double e = r.positive(*stretch, "material.stretch_modulus", "[N/m]");
    const double nu = poisson_json != nullptr ? poisson : o.poisson;
    o.warp_stretch = o.weft_stretch = e;
    o.shear_stretch = e / (2.0 * (1.0 + nu));
    o.poisson = nu;
    membrane_orthotropic = false;
  }
  if (poisson_json != nullptr && membrane_orthotropic)
    r.fail("material.poisson_ratio", std::string("cannot be combined with an orthotropic membrane (") +
                                         (stretch != nullptr ? "stretch_modulus as an object" : "an orthotropic preset") +
                                         "): give its Poisson ratio as stretch_modulus.poisson");
  const Json* bending = r.find(j, "bending_rigidity");
  if (bending != nullptr && bending->is_object()) {
    const std::string path = "material.bending_rigidity";
    r.check_object(*bending, path, {"warp", "weft", "twist"});
    o.warp_bending = r.positive(r.require(*bending, path, "warp"), path + ".warp", "[N·m]");
    o.weft_bending = r.positive(r.require(*bending, path, "weft"), path + ".weft", "[N·m]");
    twist_set = false;
    if (const Json* t = r.find(*bending, "twist")) {
      o.twist = r.positive(*t, path + ".twist", "[N·m]");
      twist_set = true;
    }
  } else if (bending != nullptr) {
    o.warp_bending = o.weft_bending = r.positive(*bending, "material.bending_rigidity", "[N·m]");
    twist_set = false;
  }
  if (!twist_set) o.twist = default_twist(o.warp_bending, o.weft_bending, o.poisson);
  if (!(o.poisson * o.poisson < o.warp_bending / o.weft_bending))
    r.fail("material.bending_rigidity", "with the membrane's poisson " + format_number(o.poisson) +
                                            " the bending law is indefinite: poisson^2 must be < warp/weft = " +
                                            format_number(o.warp_bending / o.weft_bending));
  ShellMaterial m = base;
  set_orthotropy(m, o);
  return m;
}

ShellMaterial read_material(const Reader& r, const Json* j, GrainSpec& grain) {
  double youngs = 1e7, poisson = 0.3, thickness = 0.001, density = 1000.0;
  if (j == nullptr) return ShellMaterial::from_solid(youngs, poisson, thickness, density);
  const std::string path = "material";
  r.check_object(*j, path,
                 {"preset", "youngs_modulus", "poisson_ratio", "thickness", "density", "stretch_modulus",
                  "bending_rigidity", "areal_density", "grain"});
  if (const Json* g = r.find(*j, "grain")) {
    r.check_object(*g, "material.grain", {"warp_deg"});
    grain.given = true;
    if (const Json* w = r.find(*g, "warp_deg")) grain.warp_deg = r.number(*w, "material.grain.warp_deg");
  }
  const Json* preset = r.find(*j, "preset");
  std::string preset_name;
  if (preset != nullptr) {
    preset_name = r.choice(*preset, "material.preset", material_preset_names(), "preset");
    // A preset is given by its stretch modulus, bending rigidity and areal density directly; it
    // has no Young's modulus, thickness or density to combine with.
    for (const char* solid : {"youngs_modulus", "thickness", "density"})
      if (r.find(*j, solid) != nullptr)
        r.fail(join_key(path, solid), "cannot be combined with \"preset\" (a preset sets stretch_modulus, "
                                      "bending_rigidity, poisson_ratio and areal_density; override those instead)");
  }
  if (const Json* v = r.find(*j, "youngs_modulus")) youngs = r.positive(*v, "material.youngs_modulus", "[Pa]");
  const Json* poisson_json = r.find(*j, "poisson_ratio");
  if (poisson_json != nullptr) {
    poisson = r.number(*poisson_json, "material.poisson_ratio");
    if (!(poisson >= 0 && poisson < 0.5))
      r.fail("material.poisson_ratio", "must be >= 0 and < 0.5 (got " + poisson_json->dump() + ")");
  }
  if (const Json* v = r.find(*j, "thickness")) thickness = r.positive(*v, "material.thickness", "[m]");
  if (const Json* v = r.find(*j, "density")) density = r.non_negative(*v, "material.density", "[kg/m³]");

  ShellMaterial m = ShellMaterial::from_solid(youngs, poisson, thickness, density);
  if (preset != nullptr) {
    m = *material_preset(preset_name);
    if (poisson_json != nullptr && !m.orthotropic()) m.poisson_ratio = poisson;
  }
  const Json* stretch = r.find(*j, "stretch_modulus");
  const Json* bending = r.find(*j, "bending_rigidity");
  const bool object_form = (stretch != nullptr && stretch->is_object()) || (bending != nullptr && bending->is_object());
  if (object_form || m.orthotropic()) {
    m = read_orthotropic(r, *j, m, poisson_json, poisson);
  } else {
    if (stretch != nullptr) m.stretch_modulus = r.positive(*stretch, "material.stretch_modulus", "[N/m]");
    if (bending != nullptr) m.bending_rigidity = r.positive(*bending, "material.bending_rigidity", "[N·m]");
  }
  if (const Json* v = r.find(*j, "areal_density"))
    m.areal_density = r.non_negative(*v, "material.areal_density", "[kg/m²]");
  const std::string problem = validate(m);
  if (!problem.empty()) r.fail(path, problem);
  return m;
}

Quadrature read_numerics(const Reader& r, const Json* j) {
  if (j == nullptr) return Quadrature::one_point;
  r.check_object(*j, "numerics", {"quadrature"});
  const Json* q = r.find(*j, "quadrature");
  if (q == nullptr) return Quadrature::one_point;
  const std::string s = r.choice(*q, "numerics.quadrature", {"one_point", "three_point", "six_point"});
  if (s == "three_point") return Quadrature::three_point;
  if (s == "six_point") return Quadrature::six_point;
  return Quadrature::one_point;
}

std::string bounding_box(const Eigen::MatrixX3d& v) {
  if (v.rows() == 0) return "empty";
  const Eigen::Vector3d lo = v.colwise().minCoeff().transpose();
  const Eigen::Vector3d hi = v.colwise().maxCoeff().transpose();
  return "[" + format_point(lo) + ", " + format_point(hi) + "]";
}

Motion read_motion(const Reader& r, const Json& item, const std::string& path) {
  if (!item.is_object()) r.fail(path, "expected an object (got " + describe(item) + ")");
  const std::string type = r.choice(r.require(item, path, "type"), join_key(path, "type"),
                                    {"rotate", "translate", "hold"}, "motion type");
  Motion m;
  if (type == "rotate") {
    r.check_object(item, path, {"type", "axis", "center", "angle_deg", "start", "end"});
    m.type = Motion::Type::rotate;
  } else if (type == "translate") {
    r.check_object(item, path, {"type", "displacement", "start", "end"});
    m.type = Motion::Type::translate;
  } else {
    r.check_object(item, path, {"type", "start", "end"});
    m.type = Motion::Type::hold;
  }
  m.start = r.non_negative(r.require(item, path, "start"), join_key(path, "start"), "[s]");
  const std::string end_path = join_key(path, "end");
  m.end = r.number(r.require(item, path, "end"), end_path);
  if (!(m.end >= m.start))
    r.fail(end_path, "must be >= start = " + format_number(m.start) + " [s] (got " + format_number(m.end) + ")");
  if (m.type == Motion::Type::rotate) {
    const std::string axis_path = join_key(path, "axis");
    m.axis = r.vec3(r.require(item, path, "axis"), axis_path);
    if (!(m.axis.norm() > 0)) r.fail(axis_path, "must be a non-zero vector (got " + format_point(m.axis) + ")");
    if (const Json* c = r.find(item, "center")) m.center = r.vec3(*c, join_key(path, "center"));
    m.angle_deg = r.number(r.require(item, path, "angle_deg"), join_key(path, "angle_deg"));
  } else if (m.type == Motion::Type::translate) {
    m.displacement = r.vec3(r.require(item, path, "displacement"), join_key(path, "displacement"));
  }
  const std::string problem = validate(m);
  if (!problem.empty()) r.fail(path, problem);
  return m;
}

// A boundary translated by more than this many times the mesh's size (its bounding-box diagonal)
// is refused: no cloth scene moves a boundary that far, and such a motion (a slip in an exponent:
// -1e9 m) stretched the cloth past anything the contact and the solver can follow, growing to
// gigabytes before it failed with a message that named no key.
constexpr double kMaxTravel = 1000.0;

void check_travel(const Reader& r, const Motion& m, const std::string& path, const TriMesh& mesh,
                  const char* what = "the boundary") {
  if (m.type != Motion::Type::translate || mesh.vertices.rows() == 0) return;
  const double size = (mesh.vertices.colwise().maxCoeff() - mesh.vertices.colwise().minCoeff()).norm();
  const double travel = m.displacement.stableNorm();  // (finite for components near the largest double)
  if (travel <= kMaxTravel * size) return;
  r.fail(join_key(path, "displacement"), std::string("moves ") + what + " by " + format_number(travel) + " m, more than " +
                                             format_number(kMaxTravel) + " times the mesh's size (" + format_number(size) +
                                             " m, its bounding-box diagonal); is the unit metres?");
}

// `select`: {"box": [[xmin, ymin, zmin], [xmax, ymax, zmax]]} → the control vertices in the
// closed box (at least one).
std::vector<int> read_selection(const Reader& r, const Json& item, const std::string& path, const TriMesh& mesh) {
  const std::string select_path = join_key(path, "select");
  const Json& select = r.require(item, path, "select");
  r.check_object(select, select_path, {"box"});
  const std::string box_path = join_key(select_path, "box");
  const Json& box = r.require(select, select_path, "box");
  if (!box.is_array() || box.size() != 2)
    r.fail(box_path, "expected an array of 2 points [[xmin, ymin, zmin], [xmax, ymax, zmax]] (got " +
                         describe(box) + ")");
  const Eigen::Vector3d lo = r.vec3(box[0], join_index(box_path, 0));
  const Eigen::Vector3d hi = r.vec3(box[1], join_index(box_path, 1));
  for (int k = 0; k < 3; ++k)
    if (lo[k] > hi[k])
      r.fail(box_path, std::string("min must be <= max in every component (got ") + kAxes[k] + "min = " +
                           format_number(lo[k]) + " > " + kAxes[k] + "max = " + format_number(hi[k]) + ")");
  std::vector<int> vertices = select_box(mesh.vertices, lo, hi);
  if (vertices.empty())
    r.fail(box_path, "selects no vertex of the mesh (mesh bounding box: " + bounding_box(mesh.vertices) + ")");
  return vertices;
}

std::vector<BoundaryCondition> read_boundary(const Reader& r, const Json* j, const TriMesh& mesh, bool dynamic,
                                             const LogFn& log) {
  std::vector<BoundaryCondition> out;
  if (j == nullptr) return out;
  r.array(*j, "boundary");
  for (std::size_t i = 0; i < j->size(); ++i) {
    const std::string path = join_index("boundary", i);
    const Json& item = (*j)[i];
    r.check_object(item, path, {"select", "fix", "rotation", "motion"});
    BoundaryCondition bc;
    bc.vertices = read_selection(r, item, path, mesh);

    if (const Json* fix = r.find(item, "fix")) {
      const std::string fix_path = join_key(path, "fix");
      r.array(*fix, fix_path);
      bc.fix = {false, false, false};
      for (std::size_t c = 0; c < fix->size(); ++c) {
        const std::string component = r.choice((*fix)[c], join_index(fix_path, c), {"x", "y", "z"}, "component");
        const auto axis = static_cast<std::size_t>(component[0] - 'x');
        if (bc.fix[axis]) r.fail(join_index(fix_path, c), "duplicate component " + quote(component));
        bc.fix[axis] = true;
      }
    }
    if (const Json* rotation = r.find(item, "rotation")) {
      const std::string kind = r.choice(*rotation, join_key(path, "rotation"), {"free", "clamped", "symmetry"});
      bc.clamped = kind == "clamped";
      bc.symmetric = kind == "symmetry";
    }
    if (const Json* motion = r.find(item, "motion")) {
      const std::string motion_path = join_key(path, "motion");
      if (!dynamic) r.fail(motion_path, kNeedsDynamic);
      r.array(*motion, motion_path);
      for (std::size_t m = 0; m < motion->size(); ++m) {
        bc.motion.push_back(read_motion(r, (*motion)[m], join_index(motion_path, m)));
        check_travel(r, bc.motion.back(), join_index(motion_path, m), mesh);
      }
      if (!bc.motion.empty() && !bc.fix[0] && !bc.fix[1] && !bc.fix[2])
        r.fail(motion_path, "has no effect: the motion drives the fixed components and \"fix\" is empty");
    }

    log(path + ": " + std::to_string(bc.vertices.size()) + " vertices");
    out.push_back(std::move(bc));
  }
  return out;
}

// "vertex 12 at [x, y, z] (0.01 m from the requested point)" for snapped points.
std::string describe_snap(const Eigen::MatrixX3d& vertices, int v, const Eigen::Vector3d& at) {
  const Eigen::Vector3d p = vertices.row(v).transpose();
  return "vertex " + std::to_string(v) + " at " + format_point(p) + " (" + format_number((p - at).norm()) +
         " m from the requested point)";
}

// A probe or point load must lie on or near the mesh: fails naming `path` if `point` is further
// from its nearest vertex than the diagonal of the mesh's bounding box.
void check_near_mesh(const Reader& r, const Eigen::MatrixX3d& vertices, int vertex, const Eigen::Vector3d& point,
                     const std::string& path) {
  if (vertex < 0) r.fail(path, "the mesh has no vertices");
  const double diagonal = (vertices.colwise().maxCoeff() - vertices.colwise().minCoeff()).norm();
  const double distance = (vertices.row(vertex).transpose() - point).stableNorm();
  if (!(distance <= diagonal))
    r.fail(path, "[" + format_number(point.x()) + ", " + format_number(point.y()) + ", " + format_number(point.z()) +
                     "] is " + format_number(distance) + " m from the nearest vertex, further than the mesh's size (" +
                     format_number(diagonal) + " m, its bounding box's diagonal); give a point on or near the mesh");
}

void read_loads(const Reader& r, const Json* j, Problem& problem, double* ramp_time, const LogFn& log) {
  if (j == nullptr) return;
  r.check_object(*j, "loads", {"gravity", "surface_load", "pressure", "point_loads", "moments", "ramp_time"});
  if (const Json* ramp = r.find(*j, "ramp_time")) {
    if (ramp_time == nullptr) r.fail("loads.ramp_time", "needs \"analysis\": \"dynamic\" (this scene is static)");
    *ramp_time = r.non_negative(*ramp, "loads.ramp_time", "[s]");
  }
  if (const Json* moments = r.find(*j, "moments")) {
    r.array(*moments, "loads.moments");
    for (std::size_t i = 0; i < moments->size(); ++i) {
      const std::string path = join_index("loads.moments", i);
      const Json& item = (*moments)[i];
      r.check_object(item, path, {"select", "moment"});
      MomentLoad load;
      load.vertices = read_selection(r, item, path, problem.mesh);
      load.moment = r.vec3(r.require(item, path, "moment"), join_key(path, "moment"));
      log(path + ": " + std::to_string(load.vertices.size()) + " vertices");
      problem.moments.push_back(std::move(load));
    }
  }
  if (const Json* g = r.find(*j, "gravity")) problem.gravity = r.vec3(*g, "loads.gravity");
  if (const Json* s = r.find(*j, "surface_load")) problem.surface_load = r.vec3(*s, "loads.surface_load");
  if (const Json* s = r.find(*j, "pressure")) problem.pressure = r.number(*s, "loads.pressure");
  if (const Json* p = r.find(*j, "point_loads")) {
    r.array(*p, "loads.point_loads");
    for (std::size_t i = 0; i < p->size(); ++i) {
      const std::string path = join_index("loads.point_loads", i);
      const Json& item = (*p)[i];
      r.check_object(item, path, {"at", "force"});
      const Eigen::Vector3d at = r.vec3(r.require(item, path, "at"), join_key(path, "at"));
      PointLoad load;
      load.force = r.vec3(r.require(item, path, "force"), join_key(path, "force"));
      load.vertex = nearest_vertex(problem.mesh.vertices, at);
      check_near_mesh(r, problem.mesh.vertices, load.vertex, at, join_key(path, "at"));
      log(path + ": " + describe_snap(problem.mesh.vertices, load.vertex, at));
      problem.point_loads.push_back(load);
    }
  }
}

TimeSettings read_time(const Reader& r, const Json* j) {
  TimeSettings t;
  if (j == nullptr) return t;
  r.check_object(*j, "time", {"dt", "end", "output_fps"});
  if (const Json* v = r.find(*j, "dt")) t.dt = r.positive(*v, "time.dt", "[s]");
  if (const Json* v = r.find(*j, "end")) t.end = r.positive(*v, "time.end", "[s]");
  if (t.end < t.dt)
    r.fail("time.end", "must be >= time.dt = " + format_number(t.dt) + " [s] (got " + format_number(t.end) + ")");
  if (const Json* v = r.find(*j, "output_fps")) t.output_fps = r.positive(*v, "time.output_fps", "[1/s]");
  if (const std::string problem = time_limit_problem(t); !problem.empty()) r.fail("time", problem);
  return t;
}

DampingSettings read_damping(const Reader& r, const Json* j) {
  DampingSettings d;
  if (j == nullptr) return d;
  r.check_object(*j, "damping", {"stiffness", "mass"});
  if (const Json* v = r.find(*j, "stiffness")) d.stiffness = r.non_negative(*v, "damping.stiffness", "[s]");
  if (const Json* v = r.find(*j, "mass")) d.mass = r.non_negative(*v, "damping.mass", "[1/s]");
  return d;
}

SolverSettings read_solver(const Reader& r, const Json* j) {
  SolverSettings s;
  if (j == nullptr) return s;
  r.check_object(*j, "solver",
                 {"type", "tolerance", "max_iterations", "newton_iterations", "rotation_tolerance_deg", "preconditioner",
                  "refresh_iterations", "tension_stiffening", "warm_start"});
  if (const Json* v = r.find(*j, "type")) {
    const std::string type = r.choice(*v, "solver.type", {"auto", "pcg", "cholmod"}, "solver type");
    s.type = type == "cholmod" ? LinearSolverType::cholmod
             : type == "pcg"   ? LinearSolverType::pcg
                               : LinearSolverType::automatic;
  }
  if (const Json* v = r.find(*j, "tolerance")) {
    s.tolerance = r.number(*v, "solver.tolerance");
    if (!(s.tolerance > 0 && s.tolerance < 1))
      r.fail("solver.tolerance", "must be > 0 and < 1 (got " + v->dump() + ")");
  }
  if (const Json* v = r.find(*j, "max_iterations")) s.max_iterations = r.integer_at_least(*v, "solver.max_iterations", 1);
  if (const Json* v = r.find(*j, "newton_iterations"))
    s.newton_iterations = r.integer_at_least(*v, "solver.newton_iterations", 1);
  if (const Json* v = r.find(*j, "rotation_tolerance_deg")) {
    s.rotation_tolerance_deg = r.number(*v, "solver.rotation_tolerance_deg");
    if (!(s.rotation_tolerance_deg > 0 && s.rotation_tolerance_deg <= 180))
      r.fail("solver.rotation_tolerance_deg", "must be > 0 and <= 180 [deg] (got " + v->dump() + ")");
  }
  if (const Json* v = r.find(*j, "preconditioner")) {
    const std::string p = r.choice(*v, "solver.preconditioner", {"auto", "block_jacobi", "cholesky"}, "preconditioner");
    s.preconditioner = p == "cholesky"       ? PreconditionerType::cholesky
                       : p == "block_jacobi" ? PreconditionerType::block_jacobi
                                             : PreconditionerType::automatic;
  }
  if (const Json* v = r.find(*j, "refresh_iterations"))
    s.refresh_iterations = r.integer_at_least(*v, "solver.refresh_iterations", 1);
  if (const Json* v = r.find(*j, "tension_stiffening")) s.tension_stiffening = r.boolean(*v, "solver.tension_stiffening");
  if (const Json* v = r.find(*j, "warm_start"))
    s.extrapolated_start =
        r.choice(*v, "solver.warm_start", {"extrapolated", "last_velocity"}, "warm start") == "extrapolated";
  return s;
}

InitialState read_initial(const Reader& r, const Json* j) {
  InitialState s;
  if (j == nullptr) return s;
  r.check_object(*j, "initial", {"velocity", "angular_velocity", "center"});
  if (const Json* v = r.find(*j, "velocity")) s.velocity = r.vec3(*v, "initial.velocity");
  if (const Json* v = r.find(*j, "angular_velocity")) s.angular_velocity = r.vec3(*v, "initial.angular_velocity");
  if (const Json* v = r.find(*j, "center")) s.center = r.vec3(*v, "initial.center");
  return s;
}

// "output": {"obj": bool, "obj_level": int, "checkpoint_every": int}: whether OBJ frames are
// wanted, the refinement level of the surface they hold, and how often (in frames) a checkpoint
// is written for --resume.
void read_output(const Reader& r, const Json* j, Scene& scene) {
  if (j == nullptr) return;
  r.check_object(*j, "output", {"obj", "obj_level", "checkpoint_every"});
  if (const Json* every = r.find(*j, "checkpoint_every"))
    scene.checkpoint_every = r.integer_at_least(*every, "output.checkpoint_every", 0);
  if (const Json* obj = r.find(*j, "obj")) scene.write_obj_frames = r.boolean(*obj, "output.obj");
  if (const Json* level = r.find(*j, "obj_level")) {
    scene.obj_level = r.integer_at_least(*level, "output.obj_level", 0);
    if (scene.obj_level > 4) r.fail("output.obj_level", "must be an integer from 0 to 4 (got " + level->dump() + ")");
  }
}

// "imperfection": {"amplitude": m, "seed": int >= 0, "wavelength": [min, max] m}.
Imperfection read_imperfection(const Reader& r, const Json* j) {
  Imperfection imp;
  if (j == nullptr) return imp;
  r.check_object(*j, "imperfection", {"amplitude", "seed", "wavelength"});
  imp.amplitude = r.non_negative(r.require(*j, "imperfection", "amplitude"), "imperfection.amplitude", "[m]");
  if (const Json* v = r.find(*j, "seed")) imp.seed = static_cast<std::uint64_t>(r.integer_at_least(*v, "imperfection.seed", 0));
  if (const Json* v = r.find(*j, "wavelength")) {
    const Json& w = r.sized_array(*v, "imperfection.wavelength", 2, "numbers [m] (shortest, longest)");
    imp.wavelength_min = r.positive(w[0], "imperfection.wavelength[0]", "[m]");
    imp.wavelength_max = r.positive(w[1], "imperfection.wavelength[1]", "[m]");
    if (imp.wavelength_min > imp.wavelength_max)
      r.fail("imperfection.wavelength", "the shortest wavelength (first) must not exceed the longest (got " + v->dump() + ")");
  }
  return imp;
}

// "collision": {"self": bool, "thickness": m, "friction": -, "tolerance": -, "surface_level": int,
//               "method": "barrier" | "constraints"}.
void read_collision(const Reader& r, const Json* j, Problem& problem, bool& level_given) {
  level_given = false;
  if (j == nullptr) return;
  r.check_object(*j, "collision", {"self", "thickness", "friction", "tolerance", "surface_level", "method"});
  CollisionSettings& c = problem.collision;
  if (const Json* v = r.find(*j, "self")) c.self = r.boolean(*v, "collision.self");
  if (const Json* v = r.find(*j, "thickness")) c.thickness = r.positive(*v, "collision.thickness", "[m]");
  if (const Json* v = r.find(*j, "friction")) c.friction = r.non_negative(*v, "collision.friction", "[-]");
  if (const Json* v = r.find(*j, "tolerance")) {
    c.tolerance = r.positive(*v, "collision.tolerance", "[-]");
    if (c.tolerance > 0.1) r.fail("collision.tolerance", "must be > 0 and at most 0.1 (got " + v->dump() + ")");
  }
  if (const Json* v = r.find(*j, "method")) {
    if (!v->is_string() || (*v != "barrier" && *v != "constraints"))
      r.fail("collision.method", "must be \"barrier\" or \"constraints\" (got " + v->dump() + ")");
    c.barrier = *v == "barrier";
  }
  if (const Json* v = r.find(*j, "surface_level")) {
    problem.collision_level = r.integer_at_least(*v, "collision.surface_level", 0);
    if (problem.collision_level > 4)
      r.fail("collision.surface_level", "must be an integer from 0 to 4 (got " + v->dump() + ")");
    level_given = true;
  }
}

// "obstacles": [{"name", "primitive" | "obj", shape parameters, "friction", "motion"}].
std::vector<Obstacle> read_obstacles(const Reader& r, const Json* j, double default_friction,
                                     const std::filesystem::path& folder, const LogFn& log, long long max_vertices) {
  std::vector<Obstacle> out;
  if (j == nullptr) return out;
  r.array(*j, "obstacles");
  std::set<std::string> names;
  for (std::size_t i = 0; i < j->size(); ++i) {
    const std::string path = join_index("obstacles", i);
    const Json& item = (*j)[i];
    if (!item.is_object()) r.fail(path, "expected an object (got " + describe(item) + ")");
    const bool has_obj = item.contains("obj"), has_primitive = item.contains("primitive");
    if (has_obj && has_primitive) r.fail(path, "give either \"obj\" or \"primitive\", not both");
    if (!has_obj && !has_primitive)
      r.fail(path, "needs \"primitive\" (allowed: \"plane\", \"sphere\", \"capsule\", \"box\", \"cylinder\") or \"obj\" (a file)");
    Obstacle o;
    o.name = "obstacle" + std::to_string(i);
    o.friction = default_friction;
    auto key = [&](const char* k) { return join_key(path, k); };
    std::vector<std::string> allowed = {"name", "friction", "motion"};
    if (has_obj) {
      o.shape = Obstacle::Shape::mesh;
      allowed.push_back("obj");
    } else {
      const std::string shape =
          r.choice(item["primitive"], key("primitive"), {"plane", "sphere", "capsule", "box", "cylinder"}, "primitive");
      allowed.push_back("primitive");
      if (shape == "plane") {
        o.shape = Obstacle::Shape::plane;
        allowed.insert(allowed.end(), {"point", "normal"});
      } else if (shape == "sphere") {
        o.shape = Obstacle::Shape::sphere;
        allowed.insert(allowed.end(), {"center", "radius"});
      } else if (shape == "box") {
        o.shape = Obstacle::Shape::box;
        allowed.insert(allowed.end(), {"center", "size"});
      } else {
        o.shape = shape == "capsule" ? Obstacle::Shape::capsule : Obstacle::Shape::cylinder;
        allowed.insert(allowed.end(), {"from", "to", "radius"});
      }
    }
    r.check_object(item, path, allowed);
    if (const Json* v = r.find(item, "name")) {
      o.name = r.string(*v, key("name"));
      if (o.name.empty()) r.fail(key("name"), "must not be empty");
    }
    if (!names.insert(o.name).second)
      r.fail(item.contains("name") ? key("name") : path, "duplicate obstacle name " + quote(o.name) +
                                                              (item.contains("name") ? "" : " (the default name of this unnamed obstacle)"));
    if (const Json* v = r.find(item, "friction")) o.friction = r.non_negative(*v, key("friction"), "[-]");
    if (const Json* motion = r.find(item, "motion")) {
      r.array(*motion, key("motion"));
      for (std::size_t m = 0; m < motion->size(); ++m)
        o.motion.push_back(read_motion(r, (*motion)[m], join_index(key("motion"), m)));
    }
    switch (o.shape) {
      case Obstacle::Shape::plane:
        o.point = r.vec3(r.require(item, path, "point"), key("point"));
        o.normal = r.vec3(r.require(item, path, "normal"), key("normal"));
        if (!(o.normal.norm() > 0)) r.fail(key("normal"), "must be a non-zero vector");
        o.normal.normalize();
        break;
      case Obstacle::Shape::sphere:
        o.center = r.vec3(r.require(item, path, "center"), key("center"));
        o.radius = r.positive(r.require(item, path, "radius"), key("radius"), "[m]");
        break;
      case Obstacle::Shape::box:
        o.center = r.vec3(r.require(item, path, "center"), key("center"));
        o.size = r.vec3(r.require(item, path, "size"), key("size"));
        if (!(o.size.minCoeff() > 0)) r.fail(key("size"), "every edge length must be > 0 [m] (got " + item["size"].dump() + ")");
        break;
      case Obstacle::Shape::capsule:
      case Obstacle::Shape::cylinder:
        o.from = r.vec3(r.require(item, path, "from"), key("from"));
        o.to = r.vec3(r.require(item, path, "to"), key("to"));
        o.radius = r.positive(r.require(item, path, "radius"), key("radius"), "[m]");
        if (!((o.to - o.from).norm() > 0)) r.fail(key("to"), "must differ from \"from\"");
        break;
      case Obstacle::Shape::mesh: {
        const std::string name = r.string(item["obj"], key("obj"));
        if (name.empty()) r.fail(key("obj"), "expected a non-empty file path");
        o.file = name;
        const std::filesystem::path obj = folder / name;
        try {
          o.mesh = read_obj(obj.string(), max_vertices);
          check_triangles(o.mesh);
        } catch (const MeshLimitError& e) {
          r.fail(key("obj"), std::string(e.what()) + " (mesh.max_vertices = " + std::to_string(max_vertices) +
                                 ", which limits obstacle meshes too; raise it to read larger ones)");
        } catch (const std::exception& e) {
          r.fail(key("obj"), e.what());
        }
        if (o.mesh.num_triangles() == 0) r.fail(key("obj"), obj.string() + ": no triangles");
        break;
      }
    }
    if (o.shape != Obstacle::Shape::plane && o.shape != Obstacle::Shape::mesh) o.mesh = tessellate(o);
    log("obstacle " + o.name + ": " + to_string(o.shape) +
        (o.shape == Obstacle::Shape::plane ? std::string()
                                           : ", " + std::to_string(o.mesh.num_triangles()) + " triangles") +
        (o.motion.empty() ? "" : ", moving"));
    out.push_back(std::move(o));
  }
  return out;
}

std::vector<Probe> read_probes(const Reader& r, const Json* j, const TriMesh& mesh, const LogFn& log) {
  std::vector<Probe> out;
  if (j == nullptr) return out;
  r.array(*j, "probes");
  std::set<std::string> names;
  for (std::size_t i = 0; i < j->size(); ++i) {
    const std::string path = join_index("probes", i);
    const Json& item = (*j)[i];
    r.check_object(item, path, {"name", "at"});
    Probe probe;
    probe.name = r.string(r.require(item, path, "name"), join_key(path, "name"));
    if (probe.name.empty()) r.fail(join_key(path, "name"), "must not be empty");
    if (!names.insert(probe.name).second)
      r.fail(join_key(path, "name"), "duplicate probe name " + quote(probe.name));
    probe.at = r.vec3(r.require(item, path, "at"), join_key(path, "at"));
    probe.vertex = nearest_vertex(mesh.vertices, probe.at);
    check_near_mesh(r, mesh.vertices, probe.vertex, probe.at, join_key(path, "at"));
    log("probe " + probe.name + ": " + describe_snap(mesh.vertices, probe.vertex, probe.at));
    out.push_back(std::move(probe));
  }
  return out;
}

}  // namespace

std::string time_limit_problem(const TimeSettings& t) {
  auto count = [](double n) {
    char buffer[48];
    std::snprintf(buffer, sizeof buffer, n < 1e15 ? "%.0f" : "%.3g", n);
    return std::string(buffer);
  };
  const double steps = std::ceil(t.end / t.dt - 1e-9);
  if (!(steps <= kMaxSteps))
    return "time.end / time.dt = " + format_number(t.end) + " / " + format_number(t.dt) + " needs " + count(steps) +
           " steps, more than the limit of " + count(kMaxSteps) + " (a larger time.dt or a shorter time.end)";
  const double frames = std::floor(t.end * t.output_fps + 1e-9) + 1.0;
  if (!(frames <= kMaxFrames))
    return "time.output_fps = " + format_number(t.output_fps) + " over time.end = " + format_number(t.end) +
           " s makes " + count(frames) + " frames, more than the limit of " + count(kMaxFrames);
  return "";
}

int nearest_vertex(const Eigen::MatrixX3d& vertices, const Eigen::Vector3d& point) {
  int best = -1;
  double best_d2 = std::numeric_limits<double>::infinity();
  for (Eigen::Index v = 0; v < vertices.rows(); ++v) {
    // The (overflow-safe) norm, not its square: a point 1e200 m away must not overflow to infinity.
    const double d2 = (vertices.row(v).transpose() - point).stableNorm();
    if (best < 0 || d2 < best_d2) {
      best_d2 = d2;
      best = static_cast<int>(v);
    }
  }
  return best;
}

std::vector<int> select_box(const Eigen::MatrixX3d& vertices, const Eigen::Vector3d& lo,
                            const Eigen::Vector3d& hi) {
  std::vector<int> out;
  for (Eigen::Index v = 0; v < vertices.rows(); ++v) {
    bool inside = true;
    for (Eigen::Index k = 0; k < 3; ++k) inside = inside && vertices(v, k) >= lo[k] && vertices(v, k) <= hi[k];
    if (inside) out.push_back(static_cast<int>(v));
  }
  return out;
}

RenderSettings read_render(const Reader& r, const Json* j) {
  RenderSettings s;
  if (j == nullptr) return s;
  r.check_object(*j, "render",
                 {"width", "height", "refine", "color", "back_color", "background", "wireframe", "ground", "camera",
                  "framing", "surface", "texture"});
  if (const Json* v = r.find(*j, "width")) s.width = r.integer_at_least(*v, "render.width", 16);
  if (const Json* v = r.find(*j, "height")) s.height = r.integer_at_least(*v, "render.height", 16);
  if (s.width > 8192 || s.height > 8192) r.fail("render", "images larger than 8192 px are not supported");
  if (const Json* v = r.find(*j, "refine")) {
    s.refine = r.integer_at_least(*v, "render.refine", 0);
    if (s.refine > 4) r.fail("render.refine", "must be an integer from 0 to 4 (got " + v->dump() + ")");
  }
  auto colour = [&](const char* key, Eigen::Vector3d& out) {
    if (const Json* v = r.find(*j, key)) {
      const std::string path = std::string("render.") + key;
      out = r.vec3(*v, path);
      if ((out.array() < 0).any() || (out.array() > 1).any())
        r.fail(path, "colour components must lie in [0, 1] (got " + v->dump() + ")");
    }
  };
  colour("color", s.color);
  colour("back_color", s.back_color);
  colour("background", s.background);
  if (const Json* v = r.find(*j, "wireframe")) s.wireframe = r.boolean(*v, "render.wireframe");
  if (const Json* v = r.find(*j, "texture")) s.texture = r.choice(*v, "render.texture", {"none", "grain"}, "texture");
  if (const Json* v = r.find(*j, "ground")) s.ground = r.boolean(*v, "render.ground");
  if (const Json* v = r.find(*j, "surface")) {
    const std::string surface = r.choice(*v, "render.surface", {"method", "loop_limit", "flat"}, "surface");
    s.surface = surface == "loop_limit" ? DrawnSurface::loop_limit
                : surface == "flat"     ? DrawnSurface::flat
                                        : DrawnSurface::method;
  }
  if (const Json* v = r.find(*j, "framing"))
    s.framing = r.choice(*v, "render.framing", {"motion", "sequence"}, "framing") == "sequence" ? Framing::sequence
                                                                                             : Framing::motion;
  if (const Json* cam = r.find(*j, "camera")) {
    r.check_object(*cam, "render.camera", {"eye", "target", "up", "fov_deg"});
    s.has_camera = true;
    s.eye = r.vec3(r.require(*cam, "render.camera", "eye"), "render.camera.eye");
    s.target = r.vec3(r.require(*cam, "render.camera", "target"), "render.camera.target");
    if (const Json* v = r.find(*cam, "up")) s.up = r.vec3(*v, "render.camera.up");
    if (const Json* v = r.find(*cam, "fov_deg")) {
      s.fov_deg = r.number(*v, "render.camera.fov_deg");
      if (!(s.fov_deg > 1 && s.fov_deg < 170)) r.fail("render.camera.fov_deg", "must lie in (1, 170) degrees (got " + v->dump() + ")");
    }
    if ((s.eye - s.target).norm() <= 0) r.fail("render.camera", "eye and target must differ");
    if (s.up.cross(s.eye - s.target).norm() <= 1e-12 * s.up.norm() * (s.eye - s.target).norm())
      r.fail("render.camera.up", "must not be parallel to the viewing direction");
  }
  return s;
}

RenderSettings render_settings_from_json(const Json& render, const std::string& where) {
  return read_render(Reader(where), &render);
}

namespace {
Scene load_scene_json(const Json& root, const Reader& r, const std::filesystem::path& file, const LogFn& log);

// Applies the --set overrides to the parsed scene in order, then reads it; errors at or around an
// overridden key name the override.
Scene load_overridden(Json root, Reader& r, const std::filesystem::path& file, const LogFn& log,
                      const std::vector<std::string>& overrides) {
  std::vector<std::pair<std::string, std::string>> written;
  for (const std::string& argument : overrides)
    written.emplace_back(apply_override(root, argument, log), shortened(argument));
  r.set_overrides(std::move(written));
  Scene scene = load_scene_json(root, r, file, log);
  scene.overrides = overrides;
  return scene;
}
}  // namespace

Scene load_scene(const std::filesystem::path& file, const LogFn& log, const std::vector<std::string>& overrides) {
  Reader r(file.string());
  return load_overridden(parse_file(r, file), r, file, log, overrides);
}

Scene load_scene_text(const std::string& text, const std::filesystem::path& file, const LogFn& log,
                      const std::vector<std::string>& overrides) {
  Reader r(file.string());
  return load_overridden(parse_text(r, text), r, file, log, overrides);
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
  auto lower = [](char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; };
  const std::size_t n = a.size(), m = b.size();
  // Rows i-2, i-1 and i of the (n+1) x (m+1) table.
  std::vector<std::size_t> before(m + 1), previous(m + 1), current(m + 1);
  for (std::size_t j = 0; j <= m; ++j) previous[j] = j;
  for (std::size_t i = 1; i <= n; ++i) {
    current[0] = i;
    for (std::size_t j = 1; j <= m; ++j) {
      const bool same = lower(a[i - 1]) == lower(b[j - 1]);
      current[j] = std::min({previous[j] + 1, current[j - 1] + 1, previous[j - 1] + (same ? 0 : 1)});
      if (i > 1 && j > 1 && lower(a[i - 1]) == lower(b[j - 2]) && lower(a[i - 2]) == lower(b[j - 1]))
        current[j] = std::min(current[j], before[j - 2] + 1);
    }
    std::swap(before, previous);
    std::swap(previous, current);
  }
  return previous[m];
}

std::string closest_name(const std::string& given, const std::vector<std::string>& allowed) {
  std::string best;
  std::size_t best_distance = std::numeric_limits<std::size_t>::max();
  for (const std::string& name : allowed) {
    if (name == given) return "";  // not a typo
    const std::size_t longer = std::max(name.size(), given.size());
    const std::size_t shorter = std::min(name.size(), given.size());
    if (3 * (longer - shorter) > longer) continue;  // too far apart in length alone (and cheap to skip)
    const std::size_t d = edit_distance(given, name);
    if (3 * d <= longer && d < best_distance) {
      best = name;
      best_distance = d;
    }
  }
  return best;
}

namespace {
// Logs a warning if the mesh has cracks (find_cracks): distinct border vertices at one position.
void warn_about_cracks(const TriMesh& mesh, bool from_obj, const LogFn& log) {
  const std::vector<std::pair<int, int>> cracks = find_cracks(mesh);
  if (cracks.empty()) return;
  std::string examples;
  const std::size_t shown = std::min<std::size_t>(cracks.size(), 3);
  for (std::size_t i = 0; i < shown; ++i) {
    const auto [a, b] = cracks[i];
    examples += (i > 0 ? "; " : "") + std::string("vertices ") + std::to_string(a) + " and " + std::to_string(b) +
                (from_obj ? " (OBJ indices " + std::to_string(a + 1) + " and " + std::to_string(b + 1) + ")" : "") +
                " at " + format_point(mesh.vertices.row(a).transpose());
  }
  log("warning: mesh: " + std::to_string(cracks.size()) +
      (cracks.size() == 1 ? " pair" : " pairs") + " of distinct border vertices at the same position (within " +
      format_number(kCrackTolerance) + " of the mesh's size): " + examples +
      (cracks.size() > shown ? "; ..." : "") +
      ". The surface is split there (a crack of border edges) and the cloth will come apart along it; "
      "merge the vertices in the mesh file if it should be connected (a cut made on purpose is fine)");
}

// A number for a message, to 3 significant digits ("1.41e+304", "0.25"); "inf" past the doubles.
std::string approx(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.3g", v);
  return buffer;
}

// Loads so large that no shell could carry them are errors naming the key. The estimate is the
// membrane strain they would cause if carried by stretching alone, the stiffest way a shell can
// carry a load: force per unit width over the stretch modulus E·t, with L the mesh's
// bounding-box diagonal — (|pressure|, |surface_load| or areal density·|gravity|)·L, |F|/L for a
// point load, |M|/L² for a couple, summed. Above kMaxLoadStrain it is an error, above 1 (100 %)
// a warning (far beyond the linear-elastic model). Gravity above 1e4 g is an error in any case.
constexpr double kMaxLoadStrain = 100.0;
constexpr double kMaxGravity = 1e4 * 9.80665;  // [m/s²]

void check_load_magnitudes(const Reader& r, const Problem& p, const LogFn& log) {
  if (const double g = p.gravity.stableNorm(); g > kMaxGravity)
    r.fail("loads.gravity", "|g| = " + approx(g) + " m/s² is more than 1e4 g (" + approx(kMaxGravity) +
                                " m/s²); check the value and its unit [m/s²]");
  const Eigen::MatrixX3d& v = p.mesh.vertices;
  if (v.rows() == 0) return;
  const Eigen::Vector3d half = (v.colwise().maxCoeff() / 2 - v.colwise().minCoeff() / 2).transpose();
  const double size = 2 * half.stableNorm();          // L [m]
  const double stretch = p.material.stretch_modulus;  // E·t [N/m]
  struct Term {
    std::string key, value, formula;  // "loads.pressure", "1e+308 N/m²", "|p|·L"
    double strain;
  };
  std::vector<Term> terms;
  auto add = [&](std::string key, std::string value, std::string formula, double strain) {
    terms.push_back({std::move(key), std::move(value), std::move(formula), std::isnan(strain) ? HUGE_VAL : strain});
  };
  if (const double w = p.material.areal_density * p.gravity.stableNorm(); w > 0)
    add("loads.gravity", approx(p.gravity.stableNorm()) + " m/s²", "areal density·|g|·L", w / stretch * size);
  if (const double s = p.surface_load.stableNorm(); s > 0)
    add("loads.surface_load", approx(s) + " N/m²", "|surface_load|·L", s / stretch * size);
  if (const double s = std::abs(p.pressure); s > 0)
    add("loads.pressure", approx(p.pressure) + " N/m²", "|p|·L", s / stretch * size);
  for (std::size_t i = 0; i < p.point_loads.size(); ++i)
    if (const double f = p.point_loads[i].force.stableNorm(); f > 0)
      add(join_key(join_index("loads.point_loads", i), "force"), "|F| = " + approx(f) + " N", "|F|/L",
          f / size / stretch);
  for (std::size_t i = 0; i < p.moments.size(); ++i)
    if (const double m = p.moments[i].moment.stableNorm(); m > 0)
      add(join_key(join_index("loads.moments", i), "moment"), "|M| = " + approx(m) + " N·m", "|M|/L²",
          m / size / size / stretch);
  if (terms.empty()) return;
  double total = 0;
  const Term* largest = &terms.front();
  for (const Term& t : terms) {
    total += t.strain;
    if (t.strain > largest->strain) largest = &t;
  }
  const std::string estimate =
      largest->value + ": even carried by stretching alone (the stiffest way a shell carries a load) the scene's "
      "loads would strain the sheet by about " + approx(total) + " (force per unit width, here " + largest->formula +
      ", over the stretch modulus E·t = " + approx(stretch) + " N/m; L = " + approx(size) +
      " m, the mesh's bounding-box diagonal)";
  if (!(total <= kMaxLoadStrain))
    r.fail(largest->key, estimate + ", more than " + approx(kMaxLoadStrain) +
                             " (10000 %): refused; check the value and its unit");
  if (total > 1)
    log("warning: " + largest->key + ": " + estimate +
        ", more than 1 (100 %): far beyond the range of the linear-elastic model");
}

Scene load_scene_json(const Json& root, const Reader& r, const std::filesystem::path& file, const LogFn& log) {
  const LogFn say = log ? log : LogFn([](const std::string&) {});
  r.check_object(root, "",
                 {"name", "description", "analysis", "method", "mesh", "material", "boundary", "loads", "probes",
                  "numerics", "time", "damping", "solver", "corotational", "initial", "output", "render",
                  "collision", "obstacles", "imperfection", "$schema"});
  // "$schema": the JSON Schema the file follows (scenes/scene.schema.json), for editors; ignored.
  if (const Json* schema = r.find(root, "$schema")) r.string(*schema, "$schema");

  Scene scene;
  scene.file = file;
  if (const Json* name = r.find(root, "name")) {
    scene.name = r.string(*name, "name");
    if (!is_safe_name(scene.name))
      r.fail("name", "must be a safe folder name: at most " + std::to_string(kMaxNameLength) +
                         " letters, digits, '_', '-', '.', not starting with '.' (got " +
                         (scene.name.size() > 60 ? quote(scene.name.substr(0, 40)) + "... (" +
                                                       std::to_string(scene.name.size()) + " characters)"
                                                 : quote(scene.name)) +
                         ")");
  } else {
    scene.name = file.stem().string();
    if (!is_safe_name(scene.name))
      r.fail("name", "not given, and the file name " + quote(scene.name) +
                         " is not a safe folder name; set \"name\" (letters, digits, '_', '-', '.', not "
                         "starting with '.')");
  }
  if (const Json* d = r.find(root, "description")) scene.description = r.string(*d, "description");
  scene.analysis = "static";
  if (const Json* a = r.find(root, "analysis")) scene.analysis = r.choice(*a, "analysis", {"static", "dynamic"});
  const bool dynamic = scene.analysis == "dynamic";
  if (!dynamic)
    for (const char* key : kDynamicOnlyKeys)
      if (r.find(root, key) != nullptr) r.fail(key, kNeedsDynamic);

  // The discretisation: it decides how the mesh is prepared, so it is read before the mesh.
  if (const Json* m = r.find(root, "method")) scene.problem.method = r.choice(*m, "method", discretization_methods(), "method");

  // Cheap checks first, the mesh (possibly large) after; nothing larger than this is read or made.
  const long long max_vertices = read_max_vertices(r, root);
  GrainSpec grain;
  scene.problem.material = read_material(r, r.find(root, "material"), grain);
  scene.problem.quadrature = read_numerics(r, r.find(root, "numerics"));
  Problem& dyn = scene.problem;
  if (dynamic) {
    if (const auto issue = find_issue(scene.problem, Analysis::dynamics); issue && issue->key == "material")
      r.fail(issue->key, issue->message);  // before the (possibly large) mesh is built
    dyn.time = read_time(r, r.find(root, "time"));
    dyn.damping = read_damping(r, r.find(root, "damping"));
    dyn.solver = read_solver(r, r.find(root, "solver"));
    if (const Json* c = r.find(root, "corotational")) dyn.corotational = r.boolean(*c, "corotational");
    dyn.initial = read_initial(r, r.find(root, "initial"));
    read_output(r, r.find(root, "output"), scene);
  }

  scene.render = read_render(r, r.find(root, "render"));
  const Imperfection imperfection = read_imperfection(r, r.find(root, "imperfection"));
  if (dynamic) {
    bool level_given = false;
    read_collision(r, r.find(root, "collision"), scene.problem, level_given);
    // Contact acts on the surface that is drawn, unless the scene says otherwise.
    if (!level_given) scene.problem.collision_level = scene.render.refine;
    scene.problem.obstacles =
        read_obstacles(r, r.find(root, "obstacles"), scene.problem.collision.friction, file.parent_path(), say,
                       max_vertices);
  }
  const Json& mesh_json = r.require(root, "", "mesh");
  const bool draw_grain = scene.render.texture == "grain";
  grain.needed_by = scene.problem.material.orthotropic() ? "material" : "render.texture";
  TriMesh mesh = build_mesh(r, mesh_json, file.parent_path(), say, max_vertices, grain,
                            grain.given || scene.problem.material.orthotropic() || draw_grain);
  warn_about_cracks(mesh, mesh_json.contains("obj"), say);
  // An obstacle's translations too are measured against the cloth (the scene's scale).
  for (std::size_t i = 0; i < scene.problem.obstacles.size(); ++i)
    for (std::size_t m = 0; m < scene.problem.obstacles[i].motion.size(); ++m)
      check_travel(r, scene.problem.obstacles[i].motion[m], join_index(join_key(join_index("obstacles", i), "motion"), m), mesh,
                   "the obstacle");
  try {
    scene.problem.mesh = prepare_mesh(scene.problem.method, mesh, say);
  } catch (const std::exception& e) {
    r.fail("mesh", e.what());
  }
  if (scene.problem.mesh.num_vertices() > max_vertices)
    r.fail("mesh", "prepared for the method (refined once by Loop subdivision) it has " +
                       std::to_string(scene.problem.mesh.num_vertices()) + " vertices, more than mesh.max_vertices = " +
                       std::to_string(max_vertices) + " (raise mesh.max_vertices to allow it)");

  scene.problem.boundary = read_boundary(r, r.find(root, "boundary"), scene.problem.mesh, dynamic, say);
  read_loads(r, r.find(root, "loads"), scene.problem, dynamic ? &dyn.ramp_time : nullptr, say);
  check_load_magnitudes(r, scene.problem, say);
  scene.probes = read_probes(r, r.find(root, "probes"), scene.problem.mesh, say);
  // The boundary and probes were selected on the mesh as placed; the imperfection then changes
  // its rest shape by at most the amplitude.
  if (imperfection.amplitude > 0) {
    try {
      apply_imperfection(scene.problem.mesh, imperfection);
    } catch (const std::exception& e) {
      r.fail("imperfection", e.what());
    }
    say("imperfection: amplitude " + format_number(imperfection.amplitude) + " m, seed " + std::to_string(imperfection.seed));
  }

  if (const auto issue = find_issue(scene.problem, dynamic ? Analysis::dynamics : Analysis::statics))
    r.fail(issue->key, issue->message);
  return scene;
}
}  // namespace

}  // namespace clothsim
