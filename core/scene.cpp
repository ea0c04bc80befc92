// Reading and writing a scene (core/scene.h): JSON in, with its types, ranges, unknown keys, --set overrides and
// the non-finite words scripts write; JSON out (scene.json and the stages' settings); and the key table of
// `surge keys`. Every one is a visitor over the keys as scene_fields.cpp declares them; the checks that need the
// whole scene are core/scene_validate.cpp's.
#include "core/scene.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "core/errors.h"
#include "core/expression.h"
#include "core/scene_fields.h"

namespace surge {
namespace {

using nlohmann::json;

std::string describe(const json& value) {
  // A scene's strings need not be UTF-8: replaced, not thrown on, when quoted back in a message.
  std::string text = value.dump(-1, ' ', false, json::error_handler_t::replace);
  if (text.size() > 40) text = text.substr(0, 37) + "...";
  return text;
}

std::string rangeText(const FieldInfo& info) {
  std::string text;
  if (std::isfinite(info.min)) text += (info.minExclusive ? "> " : ">= ") + formatNumber(info.min);
  if (std::isfinite(info.max) && info.max < 1e299) text += (text.empty() ? "<= " : ", <= ") + formatNumber(info.max);
  return text;
}

// JSON has no NaN or infinity, but Python's json module (and JavaScript's) writes them as the bare words NaN,
// Infinity and -Infinity, so scenes written by scripts hold them. A scene that does not parse is read again with
// each such word (outside strings) turned into a marked string, so that the reader names the key that holds it
// rather than a byte.
const char kNonFiniteMark = '\x01';  // written into the JSON text as the escape \u0001 (markNonFiniteWords)

constexpr const char* kNonFiniteWords[] = {"NaN", "Infinity", "-Infinity"};

std::string markNonFiniteWords(const std::string& text) {
  auto wordChar = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.'; };
  // The word that stands whole at i, or nullptr.
  auto wordAt = [&](size_t i) -> const char* {
    if (i > 0 && wordChar(text[i - 1])) return nullptr;
    for (const char* word : kNonFiniteWords) {
      const size_t n = std::char_traits<char>::length(word);
      if (text.compare(i, n, word) == 0 && !(i + n < text.size() && wordChar(text[i + n]))) return word;
    }
    return nullptr;
  };
  std::string marked;
  marked.reserve(text.size());
  bool inString = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (inString) {
      marked += c;
      if (c == '\\' && i + 1 < text.size()) marked += text[++i];
      else if (c == '"') inString = false;
    } else if (const char* word = wordAt(i)) {
      marked += std::string("\"\\u0001") + word + "\"";
      i += std::char_traits<char>::length(word) - 1;
    } else {
      marked += c;
      inString = c == '"';
    }
  }
  return marked;
}

// The word a marked string stands for (markNonFiniteWords), or nullptr for any other value.
const char* nonFiniteWord(const json& value) {
  if (!value.is_string()) return nullptr;
  const std::string& s = value.get_ref<const std::string&>();
  if (s.empty() || s[0] != kNonFiniteMark) return nullptr;
  for (const char* word : kNonFiniteWords)
    if (s.compare(1, std::string::npos, word) == 0) return word;
  return nullptr;
}

// Reads JSON into the scene, checking types, ranges, required and unknown keys.
class JsonReader : public SceneVisitor {
 public:
  JsonReader(const json& root, std::string where, Scene& scene, const std::set<std::string>& overridden)
      : where_(std::move(where)), scene_(scene), overridden_(overridden) {
    if (!root.is_object()) throw InputError(where_, "the top level must be a JSON object");
    stack_.push_back(Level{&root, "", {}});
  }

  void finish() { checkUnknown(stack_.back()); }

  void text(const char* key, std::string& value, const FieldInfo& info) override {
    if (const json* j = find(key, info)) {
      failIfNonFinite(key, *j);
      if (!j->is_string()) fail(key, "expected a string, got " + describe(*j));
      value = j->get<std::string>();
      if (info.required && value.empty()) fail(key, "must not be empty");
      // scene.json is written back as JSON, which holds UTF-8 only (found by fuzz/fuzz_scene).
      try {
        (void)j->dump();
      } catch (const json::type_error&) {
        fail(key, "is not valid UTF-8 text");
      }
    }
  }

  void choice(const char* key, std::string& value, const std::vector<std::string>& options,
              const FieldInfo& info) override {
    if (const json* j = find(key, info)) {
      failIfNonFinite(key, *j);
      if (!j->is_string()) fail(key, "expected a string, got " + describe(*j));
      value = j->get<std::string>();
      for (const std::string& option : options)
        if (value == option) return;
      std::string list;
      for (const std::string& option : options) list += (list.empty() ? "" : ", ") + option;
      fail(key, "'" + value + "' is not one of: " + list);
    }
  }

  void choices(const char* key, std::vector<std::string>& values, const std::vector<std::string>& options,
               const FieldInfo& info) override {
    if (const json* j = find(key, info)) {
      if (!j->is_array()) fail(key, "expected an array of names, got " + describe(*j));
      values.clear();
      for (const json& item : *j) {
        failIfNonFinite(key, item);
        if (!item.is_string()) fail(key, "expected names, got " + describe(*j));
        const std::string name = item.get<std::string>();
        if (std::find(options.begin(), options.end(), name) == options.end()) {
          std::string list;
          for (const std::string& option : options) list += (list.empty() ? "" : ", ") + option;
          fail(key, "'" + name + "' is not one of: " + list);
        }
        if (std::find(values.begin(), values.end(), name) != values.end()) fail(key, "'" + name + "' is named twice");
        values.push_back(name);
      }
    }
  }

  void integer(const char* key, int& value, const FieldInfo& info) override {
    if (const json* j = find(key, info)) {
      failIfNonFinite(key, *j);
      if (!j->is_number_integer()) fail(key, "expected an integer, got " + describe(*j));
      const long long v = j->get<long long>();
      checkRange(key, double(v), info);
      value = static_cast<int>(v);
    }
  }

  void real(const char* key, double& value, const FieldInfo& info) override {
    if (const json* j = find(key, info)) {
      failIfNonFinite(key, *j);
      if (!j->is_number()) fail(key, "expected a number, got " + describe(*j));
      const double v = j->get<double>();
      checkRange(key, v, info);
      value = v;
    }
  }

  void vector(const char* key, Eigen::Vector3d& value, const FieldInfo& info, bool always3) override {
    if (const json* j = find(key, info)) {
      const size_t n = always3 ? 3 : static_cast<size_t>(scene_.dimensions);
      if (!j->is_array() || j->size() != n)
        fail(key, "expected an array of " + std::to_string(n) + " numbers, got " + describe(*j));
      Eigen::Vector3d v = Eigen::Vector3d::Zero();
      for (size_t k = 0; k < n; ++k) {
        failIfNonFinite(key, (*j)[k]);
        if (!(*j)[k].is_number()) fail(key, "expected numbers, got " + describe(*j));
        v[k] = (*j)[k].get<double>();
        if (!std::isfinite(v[k])) fail(key, "must be finite");
        checkRange(key, v[k], info);
      }
      value = v;
    }
  }

  void reals(const char* key, std::vector<double>& values, const FieldInfo& info) override {
    if (const json* j = find(key, info)) {
      if (!j->is_array() || j->empty() || j->size() > 3)
        fail(key, "expected an array of 1 to 3 numbers, got " + describe(*j));
      values.clear();
      for (const json& item : *j) {
        failIfNonFinite(key, item);
        if (!item.is_number()) fail(key, "expected numbers, got " + describe(*j));
        values.push_back(item.get<double>());
        checkRange(key, values.back(), info);
      }
    }
  }

  void formulas(const char* key, std::vector<std::string>& values, const FieldInfo& info) override {
    if (const json* j = find(key, info)) {
      const size_t n = static_cast<size_t>(scene_.dimensions);
      if (!j->is_array() || j->size() != n)
        fail(key, "expected an array of " + std::to_string(n) + " formulas (strings or numbers), got " + describe(*j));
      values.clear();
      for (size_t k = 0; k < n; ++k) {
        const json& item = (*j)[k];
        failIfNonFinite(key, item);
        if (!item.is_string() && !item.is_number()) fail(key, "expected formulas (strings or numbers), got " + describe(*j));
        values.push_back(item.is_string() ? item.get<std::string>() : item.dump());
        try {
          (void)Expression(values.back());
        } catch (const ExpressionError& e) {
          // Named as the component, from the file or --set as the array came (error() matches whole keys).
          throw InputError(overridden_.count(path(key)) ? "--set" : where_, path(key) + "[" + std::to_string(k) + "]",
                           "'" + values.back() + "': " + e.what());
        }
      }
    }
  }

  void group(const char* key, const FieldInfo& info, const std::function<void()>& body) override {
    const json* j = find(key, info);
    if (!j) return;
    if (!j->is_object()) fail(key, "expected an object, got " + describe(*j));
    stack_.push_back(Level{j, path(key), {}});
    body();
    checkUnknown(stack_.back());
    stack_.pop_back();
  }

  void list(const char* key, const FieldInfo& info, const std::function<size_t()>&,
            const std::function<void(size_t)>& resize, const std::function<void(size_t)>& visitItem) override {
    const json* j = find(key, info);
    if (!j) return;
    if (!j->is_array()) fail(key, "expected an array, got " + describe(*j));
    if (info.required && j->empty()) fail(key, "must not be empty");
    resize(j->size());
    for (size_t i = 0; i < j->size(); ++i) {
      const std::string itemPath = path(key) + "[" + std::to_string(i) + "]";
      if (!(*j)[i].is_object()) throw error(itemPath, "expected an object, got " + describe((*j)[i]));
      stack_.push_back(Level{&(*j)[i], itemPath, {}});
      visitItem(i);
      checkUnknown(stack_.back());
      stack_.pop_back();
    }
  }

 private:
  struct Level {
    const json* object;
    std::string path;
    std::set<std::string> seen;
  };

  std::string path(const std::string& key) const {
    const std::string& prefix = stack_.back().path;
    return prefix.empty() ? key : prefix + "." + key;
  }

  InputError error(const std::string& fullPath, const std::string& message) const {
    return InputError(overridden_.count(fullPath) ? "--set" : where_, fullPath, message);
  }

  [[noreturn]] void fail(const char* key, const std::string& message) const { throw error(path(key), message); }
  void failIfNonFinite(const char* key, const json& value) const {
    if (const char* word = nonFiniteWord(value)) fail(key, std::string("is ") + word + "; numbers must be finite");
  }

  const json* find(const char* key, const FieldInfo& info) {
    Level& level = stack_.back();
    level.seen.insert(key);
    auto it = level.object->find(key);
    if (it == level.object->end()) {
      if (info.required) fail(key, "missing required key");
      return nullptr;
    }
    return &*it;
  }

  void checkRange(const char* key, double v, const FieldInfo& info) const {
    if (!std::isfinite(v)) fail(key, "must be finite");
    if (v < info.min || (info.minExclusive && v <= info.min) || v > info.max)
      fail(key, formatNumber(v) + " is out of range (" + rangeText(info) + ")");
  }

  void checkUnknown(const Level& level) const {
    for (auto it = level.object->begin(); it != level.object->end(); ++it)
      if (!level.seen.count(it.key())) {
        const std::string full = level.path.empty() ? it.key() : level.path + "." + it.key();
        throw error(full, "unknown key");
      }
  }

  std::string where_;
  Scene& scene_;
  const std::set<std::string>& overridden_;
  std::vector<Level> stack_;
};

// Writes every key of the scene as JSON.
class JsonWriter : public SceneVisitor {
 public:
  explicit JsonWriter(const Scene& scene) : dimensions_(scene.dimensions) { stack_.push_back(&root_); }
  const json& root() const { return root_; }

  void text(const char* key, std::string& value, const FieldInfo&) override { (*stack_.back())[key] = value; }
  void choice(const char* key, std::string& value, const std::vector<std::string>&, const FieldInfo&) override {
    (*stack_.back())[key] = value;
  }
  void choices(const char* key, std::vector<std::string>& values, const std::vector<std::string>&,
               const FieldInfo&) override {
    (*stack_.back())[key] = values;
  }
  void integer(const char* key, int& value, const FieldInfo&) override { (*stack_.back())[key] = value; }
  // A value the reader would refuse is a key's "not given" (a fluid's colour 0): left out, as the file left it.
  void real(const char* key, double& value, const FieldInfo& info) override {
    if (!outOfRange(value, info)) (*stack_.back())[key] = value;
  }
  void vector(const char* key, Eigen::Vector3d& value, const FieldInfo& info, bool always3) override {
    if (value == Eigen::Vector3d::Zero() && outOfRange(0, info)) return;
    json array = json::array();
    for (int k = 0; k < (always3 ? 3 : dimensions_); ++k) array.push_back(value[k]);
    (*stack_.back())[key] = array;
  }
  void reals(const char* key, std::vector<double>& values, const FieldInfo&) override {
    if (!values.empty()) (*stack_.back())[key] = values;
  }
  void formulas(const char* key, std::vector<std::string>& values, const FieldInfo&) override {
    if (!values.empty()) (*stack_.back())[key] = values;
  }
  void group(const char* key, const FieldInfo&, const std::function<void()>& body) override {
    json& child = (*stack_.back())[key] = json::object();
    stack_.push_back(&child);
    body();
    stack_.pop_back();
  }
  void list(const char* key, const FieldInfo&, const std::function<size_t()>& size,
            const std::function<void(size_t)>&, const std::function<void(size_t)>& visitItem) override {
    json& array = (*stack_.back())[key] = json::array();
    for (size_t i = 0; i < size(); ++i) {
      array.push_back(json::object());
      stack_.push_back(&array.back());
      visitItem(i);
      stack_.pop_back();
    }
  }

 private:
  static bool outOfRange(double v, const FieldInfo& info) {
    return v < info.min || (info.minExclusive && v <= info.min) || v > info.max;
  }

  int dimensions_;
  json root_ = json::object();
  std::vector<json*> stack_;
};

// Lists every key as a markdown table row.
class KeyTable : public SceneVisitor {
 public:
  std::string rows;

  void text(const char* key, std::string& value, const FieldInfo& info) override {
    row(key, "string", value.empty() ? "" : "\"" + value + "\"", info);
  }
  void choice(const char* key, std::string& value, const std::vector<std::string>& options,
              const FieldInfo& info) override {
    std::string list;
    for (const std::string& option : options) list += (list.empty() ? "" : ", ") + ("`" + option + "`");
    row(key, "string", "\"" + value + "\"", info, "one of " + list);
  }
  void choices(const char* key, std::vector<std::string>&, const std::vector<std::string>& options,
               const FieldInfo& info) override {
    std::string list;
    for (const std::string& option : options) list += (list.empty() ? "" : ", ") + ("`" + option + "`");
    row(key, "array of strings", "[]", info, "each one of " + list);
  }
  void integer(const char* key, int& value, const FieldInfo& info) override {
    row(key, "integer", std::to_string(value), info);
  }
  void real(const char* key, double& value, const FieldInfo& info) override {
    row(key, "number", std::isnan(value) ? "" : formatNumber(value), info);  // NaN: resolved, as described
  }
  void vector(const char* key, Eigen::Vector3d& value, const FieldInfo& info, bool always3) override {
    std::string text = "[" + formatNumber(value[0]) + ", " + formatNumber(value[1]) + ", " + formatNumber(value[2]) + "]";
    row(key, always3 ? "3-vector" : "vector", info.required ? "" : text, info);
  }
  void reals(const char* key, std::vector<double>&, const FieldInfo& info) override {
    row(key, "numbers", "", info);
  }
  void formulas(const char* key, std::vector<std::string>&, const FieldInfo& info) override {
    row(key, "formulas", "", info);
  }
  void group(const char* key, const FieldInfo& info, const std::function<void()>& body) override {
    row(key, "object", "", info);
    prefix_.push_back(prefixed(key) + ".");
    body();
    prefix_.pop_back();
  }
  void list(const char* key, const FieldInfo& info, const std::function<size_t()>&,
            const std::function<void(size_t)>& resize, const std::function<void(size_t)>& visitItem) override {
    row(key, "array of objects", "", info);
    resize(1);
    prefix_.push_back(prefixed(key) + "[i].");
    visitItem(0);
    prefix_.pop_back();
  }

 private:
  std::string prefixed(const char* key) const { return (prefix_.empty() ? "" : prefix_.back()) + key; }
  void row(const char* key, const std::string& type, const std::string& value, const FieldInfo& info,
           std::string allowed = "") {
    if (allowed.empty()) allowed = rangeText(info);
    std::string units = *info.units ? std::string(" (") + info.units + ")" : "";
    rows += "| `" + prefixed(key) + "` | " + type + " | " + (info.required ? "required" : value) + " | " +
            allowed + " | " + info.description + units + " |\n";
  }
  std::vector<std::string> prefix_;
};

// Splits "solver.iterations" or "fluids[0].box.min" / "fluids.0.box.min" into JSON pointer parts.
std::vector<std::string> splitKeyPath(const std::string& path) {
  std::vector<std::string> parts;
  std::string current;
  for (char c : path) {
    if (c == '.' || c == '[') {
      if (!current.empty()) parts.push_back(current);
      current.clear();
    } else if (c != ']') {
      current += c;
    }
  }
  if (!current.empty()) parts.push_back(current);
  return parts;
}

std::string normalisedPath(const std::vector<std::string>& parts) {
  std::string path;
  for (const std::string& part : parts) {
    const bool index = !part.empty() && std::all_of(part.begin(), part.end(), ::isdigit);
    path += index ? "[" + part + "]" : (path.empty() ? "" : ".") + part;
  }
  return path;
}

void applyOverride(json& root, const std::string& assignment, std::set<std::string>& overridden) {
  const auto equals = assignment.find('=');
  if (equals == std::string::npos || equals == 0)
    throw InputError("--set", assignment, "expected key.path=value");
  const std::string keyPath = assignment.substr(0, equals);
  const std::string valueText = assignment.substr(equals + 1);
  const std::vector<std::string> parts = splitKeyPath(keyPath);
  if (parts.empty()) throw InputError("--set", assignment, "expected key.path=value");
  json value = json::parse(valueText, nullptr, false);
  if (value.is_discarded()) value = valueText;  // a bare word is a string
  json* node = &root;
  for (size_t i = 0; i < parts.size(); ++i) {
    const std::string& part = parts[i];
    const bool last = i + 1 == parts.size();
    if (node->is_array()) {
      if (!std::all_of(part.begin(), part.end(), ::isdigit) || std::stoul(part) >= node->size())
        throw InputError("--set", normalisedPath(parts), "no such list item");
      node = &(*node)[std::stoul(part)];
    } else {
      if (!node->is_object()) throw InputError("--set", normalisedPath(parts), "is not inside an object");
      node = last ? &(*node)[part] : &(*node)[part];
      if (!last && node->is_null()) *node = json::object();
    }
  }
  *node = value;
  overridden.insert(normalisedPath(parts));
}

}  // namespace

namespace {

// Scene files name their meshes and images relative to themselves; the resolved scene (scene.json) holds them
// absolute. Resolved before the scene is checked, since the simulator's defaults may read them (a fluid shape's
// volume).
void resolveFiles(Scene& scene, const fs::path& folder) {
  auto resolve = [&](ColliderSettings& c) {
    if (!c.file.empty() && fs::path(c.file).is_relative())
      c.file = fs::absolute(folder / c.file).lexically_normal().string();
  };
  for (ColliderSettings& c : scene.colliders) resolve(c);
  for (BodySettings& b : scene.bodies) resolve(b.solid);
  for (FluidBlock& f : scene.fluids) resolve(f.solid);
  for (ColliderSettings& c : scene.sinks) resolve(c);
}

Scene parseSceneIn(const std::string& text, const std::string& where, const std::vector<std::string>& overrides,
                   const fs::path* folder) {
  json root = json::parse(text, nullptr, false);
  if (root.is_discarded()) {
    const std::string marked = markNonFiniteWords(text);
    if (marked != text) root = json::parse(marked, nullptr, false);
  }
  if (root.is_discarded()) {
    // Re-parse with exceptions to learn where the syntax error is.
    try {
      json unused = json::parse(text);
      (void)unused;
    } catch (const json::parse_error& e) {
      std::string message = e.what();
      const auto colon = message.find("] ");
      throw InputError(where, "byte " + std::to_string(e.byte),
                       "invalid JSON" + (colon == std::string::npos ? "" : " (" + message.substr(colon + 2) + ")"));
    } catch (const json::exception& e) {
      // For example a number too large for a double (1e400): the library names no key, only the number.
      std::string message = e.what();
      const auto colon = message.find("] ");
      throw InputError(where, "invalid JSON" + (colon == std::string::npos ? "" : " (" + message.substr(colon + 2) + ")"));
    }
    throw InputError(where, "invalid JSON");
  }
  std::set<std::string> overridden;
  if (root.is_object())
    for (const std::string& assignment : overrides) applyOverride(root, assignment, overridden);
  Scene scene;
  JsonReader reader(root, where, scene, overridden);
  visitScene(scene, reader);
  reader.finish();
  if (folder) resolveFiles(scene, *folder);
  scene.source = where;
  validateScene(scene, where);
  return scene;
}

}  // namespace

Scene parseScene(const std::string& text, const std::string& where, const std::vector<std::string>& overrides) {
  return parseSceneIn(text, where, overrides, nullptr);
}

Scene loadScene(const fs::path& path, const std::vector<std::string>& overrides) {
  const fs::path folder = path.parent_path();
  return parseSceneIn(readTextFile(path), path.string(), overrides, &folder);
}

std::string sceneToJson(const Scene& scene) {
  Scene copy = scene;
  JsonWriter writer(copy);
  visitScene(copy, writer);
  return writer.root().dump(2) + "\n";
}

fs::path writeStageSettings(const fs::path& dir, const std::string& stage, const Scene& scene,
                            const std::string& extra) {
  if (stage != "surface" && stage != "render" && stage != "whitewater")
    throw std::logic_error("writeStageSettings: no stage '" + stage + "'");
  // The keys the stages read, and the stage's own section; the later stages read the whitewater where there is.
  std::vector<std::string> keys = {"dimensions", "domain", "particle_spacing", "colliders", "bodies", stage};
  if (stage == "render") keys.push_back("fluids");  // their colours and absorption distances
  if (stage == "whitewater") keys = {"dimensions", "domain", "particle_spacing", "gravity", "solver", stage};
  else if (scene.whitewater.enabled) keys.push_back("whitewater");
  Scene copy = scene;
  JsonWriter writer(copy);
  visitScene(copy, writer);
  json settings = json::object();
  for (const std::string& key : keys)
    if (writer.root().contains(key)) settings[key] = writer.root()[key];
  settings["options"] = json::parse(extra);
  const std::string text = settings.dump(2) + "\n";
  const fs::path path = dir / (stage + "_settings.json");
  std::error_code error;
  if (!fs::exists(path, error) || readTextFile(path) != text)
    writeFileAtomically(path, [&](std::ostream& out) { out << text; });
  return path;
}

std::string sceneKeysMarkdown() {
  Scene defaults;
  KeyTable table;
  visitScene(defaults, table);
  return "| key | type | default | allowed | meaning |\n|---|---|---|---|---|\n" + table.rows;
}

}  // namespace surge
