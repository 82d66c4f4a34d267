// The scene files' JSON reader: see json_reader.hpp.
#include "sim/scene/json_reader.hpp"

#include <algorithm>
#include <fstream>
#include <set>
#include <sstream>
#include <system_error>

namespace clothsim {
namespace scene_io {
namespace {

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

// Whether key path `a` is `b` or contains it or lies inside it ("time" and "time.end";
// "boundary[0]" and "boundary[0].fix[1]"; not "time" and "timestep").
bool paths_related(const std::string& a, const std::string& b) {
  const std::string& shorter = a.size() <= b.size() ? a : b;
  const std::string& longer = a.size() <= b.size() ? b : a;
  if (shorter.empty() || longer.compare(0, shorter.size(), shorter) != 0) return false;
  return longer.size() == shorter.size() || longer[shorter.size()] == '.' || longer[shorter.size()] == '[';
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

}  // namespace

std::string join_key(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

std::string join_index(const std::string& path, std::size_t index) {
  return path + "[" + std::to_string(index) + "]";
}

std::string quote(const std::string& s) { return Json(s).dump(-1, ' ', false, Json::error_handler_t::replace); }

std::string format_number(double v) { return Json(v).dump(); }

std::string format_point(const Eigen::Vector3d& p) {
  std::string out = "[";
  for (int k = 0; k < 3; ++k) out.append(k > 0 ? ", " : "").append(format_number(p[k]));
  return out.append("]");
}

std::string format_list(const std::vector<std::string>& items, bool quoted) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (i > 0) out += ", ";
    out += quoted ? quote(items[i]) : items[i];
  }
  return out;
}

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

bool is_safe_name(const std::string& name) {
  if (name.empty() || name.front() == '.' || name.size() > kMaxNameLength) return false;
  for (char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-' || c == '.';
    if (!ok) return false;
  }
  return true;
}

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

std::string override_note(const std::string& path, const std::vector<std::pair<std::string, std::string>>& overrides) {
  std::string note;
  for (const auto& [key, argument] : overrides)
    if (paths_related(path, key)) note += (note.empty() ? " (set by --set " : ", --set ") + argument;
  return note.empty() ? note : note + ")";
}

std::string did_you_mean(const std::string& given, const std::vector<std::string>& allowed) {
  const std::string best = closest_name(given, allowed);
  return best.empty() ? best : "; did you mean " + quote(best) + "?";
}

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

std::string shortened(const std::string& text) {
  return text.size() > 80 ? text.substr(0, 77) + "..." : text;
}

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

}  // namespace scene_io

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

}  // namespace clothsim
