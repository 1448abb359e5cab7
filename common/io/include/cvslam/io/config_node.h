#pragma once
// YAML configuration access for module options structs.
//
// Every module has an options struct with in-class defaults. Its `load(const ConfigNode&)`
// reads the keys it knows with `get` (absent key: the default stays), validates with
// `check`, and returns `node.status()`. Errors accumulate across the whole file and name
// the file, the key path and the reason, e.g.
//   "config/agent.yaml: filter.gamma: must be > 0 (got -2)".
// Keys nobody read are reported by `ConfigNode::finish()` as unknown (catches typos).
// Every key a load reads is recorded with the value it holds afterwards (read or default):
// `values()`, which options_description.h turns into a struct's printout and equality.

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <cmath>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/io/number_format.h"

namespace cvslam {

class ConfigNode {
 public:
  /// Parses a YAML file. The error names the file and the parser's reason.
  static Expected<ConfigNode> loadFile(const std::string& path);
  /// Parses YAML text; `source` names it in error messages.
  static Expected<ConfigNode> fromString(const std::string& yaml,
                                         const std::string& source = "<string>");
  /// An empty map: every option keeps its default.
  static ConfigNode empty(const std::string& source = "<defaults>");

  /// The sub-map at `key`. A missing key gives an empty section (defaults apply); a key that is
  /// not a map is an error.
  ConfigNode child(const std::string& key) const;
  /// Marks `key` as read without looking inside: a section another program reads (e.g.
  /// cvslam_run skips cvslam_agent's `agent:`), so finish() does not call it unknown.
  void skip(const std::string& key) const { markRead(key); }
  /// The section at `key` as YAML text ("" when absent), marked read: a section that a module
  /// this one does not link parses later (a scenario's `render:`, read by the renderer's
  /// drivers only). A key that is not a map is an error.
  std::string sectionText(const std::string& key) const;
  bool has(const std::string& key) const;
  /// Keys present in this map, in file order.
  std::vector<std::string> keys() const;
  /// Elements of a sequence at `key`, each as a node (for lists of agents, waypoints, ...).
  std::vector<ConfigNode> sequence(const std::string& key) const;

  /// Reads `key` into `value` if present; otherwise leaves the default. Type errors are recorded.
  template <typename T>
  void get(const std::string& key, T& value) const;
  /// Like get, but a missing key is an error.
  template <typename T>
  void require(const std::string& key, T& value) const;
  /// Reads a string key and maps it through `choices` (e.g. {"ekf", Filter::kEkf}).
  template <typename E>
  void getEnum(const std::string& key, E& value,
               const std::vector<std::pair<std::string, E>>& choices) const;

  /// Records `reason` against `key` when `condition` is false. Returns `condition`.
  bool check(bool condition, const std::string& key, const std::string& reason) const;

  /// First error recorded anywhere in this file so far (ok if none).
  Status status() const;
  /// status(), plus an error for every key of a visited section that nobody read.
  Status finish() const;

  /// One option read by a load, with its value after the read, as YAML text.
  struct Value {
    std::string path;  ///< "a.b.key" (a list element: "a.list[2].key")
    std::string text;  ///< "0.25", "true", "ekf", "[1, 0, 0]"
  };
  /// Every key read with get/require/getEnum anywhere in this file, in the order read (a key
  /// read twice: its last value).
  std::vector<Value> values() const;

  /// "file: a.b.key" — the location used in messages.
  std::string where(const std::string& key) const;
  const std::string& source() const { return shared_->source; }
  const std::string& path() const { return path_; }

 private:
  struct Shared {
    std::string source;
    std::vector<std::string> errors;
    std::map<std::string, std::set<std::string>> read_keys;  // section path -> keys read
    std::map<std::string, YAML::Node> sections;              // visited sections
    std::vector<Value> values;                               // every option read, in order
    std::map<std::string, std::size_t> value_index;          // path -> its entry in values
  };
  ConfigNode(YAML::Node node, std::shared_ptr<Shared> shared, std::string path);
  std::string keyPath(const std::string& key) const;
  void markRead(const std::string& key) const;
  void recordError(const std::string& key, const std::string& reason) const;
  YAML::Node lookup(const std::string& key) const;

  template <typename T>
  bool convert(const YAML::Node& n, const std::string& key, T& value) const;
  template <typename T>
  static std::string text(const T& value);
  void recordValue(const std::string& key, std::string text) const;

  YAML::Node node_;
  std::shared_ptr<Shared> shared_;
  std::string path_;
};

// ---- implementation of the templates -------------------------------------------------

template <typename T>
bool ConfigNode::convert(const YAML::Node& n, const std::string& key, T& value) const {
  if constexpr (std::is_base_of_v<Eigen::MatrixBase<T>, T>) {
    constexpr int kSize = T::SizeAtCompileTime;
    static_assert(kSize > 0, "only fixed-size Eigen types can be read from config");
    if (!n.IsSequence() || static_cast<int>(n.size()) != kSize) {
      recordError(key, "expected a list of " + std::to_string(kSize) + " numbers");
      return false;
    }
    T out;
    // Row-major listing in the file, as a person writes a matrix.
    for (int i = 0; i < kSize; ++i) {
      double x = 0.0;
      if (!convert(n[static_cast<std::size_t>(i)], key, x)) return false;
      out(i / T::ColsAtCompileTime, i % T::ColsAtCompileTime) = x;
    }
    value = out;
    return true;
  } else if constexpr (std::is_same_v<T, std::vector<double>> ||
                       std::is_same_v<T, std::vector<int>> ||
                       std::is_same_v<T, std::vector<std::string>>) {
    if (!n.IsSequence()) {
      recordError(key, "expected a list");
      return false;
    }
    T out;
    for (std::size_t i = 0; i < n.size(); ++i) {
      typename T::value_type x{};
      if (!convert(n[i], key, x)) return false;
      out.push_back(x);
    }
    value = std::move(out);
    return true;
  } else {
    if (!n.IsScalar()) {
      recordError(key, "expected a single value");
      return false;
    }
    try {
      T out = n.as<T>();
      if constexpr (std::is_floating_point_v<T>) {
        if (!std::isfinite(out)) {
          recordError(key, "must be a finite number (got " + n.Scalar() + ")");
          return false;
        }
      }
      value = out;
      return true;
    } catch (const YAML::Exception&) {
      std::string expected = std::is_same_v<T, bool>       ? "true or false"
                             : std::is_floating_point_v<T> ? "a number"
                             : std::is_integral_v<T>       ? "an integer"
                                                           : "a string";
      recordError(key, "expected " + expected + " (got '" + n.Scalar() + "')");
      return false;
    }
  }
}

template <typename T>
std::string ConfigNode::text(const T& value) {
  if constexpr (std::is_base_of_v<Eigen::MatrixBase<T>, T>) {
    std::string out = "[";
    for (int i = 0; i < T::SizeAtCompileTime; ++i)  // row-major, as convert() reads it
      out += (i > 0 ? ", " : "") +
             formatShortest(value(i / T::ColsAtCompileTime, i % T::ColsAtCompileTime));
    return out + "]";
  } else if constexpr (std::is_same_v<T, std::vector<double>> ||
                       std::is_same_v<T, std::vector<int>> ||
                       std::is_same_v<T, std::vector<std::string>>) {
    std::string out = "[";
    for (std::size_t i = 0; i < value.size(); ++i) out += (i > 0 ? ", " : "") + text(value[i]);
    return out + "]";
  } else if constexpr (std::is_same_v<T, bool>) {
    return value ? "true" : "false";
  } else if constexpr (std::is_floating_point_v<T>) {
    return formatShortest(static_cast<double>(value));
  } else if constexpr (std::is_integral_v<T>) {
    return std::to_string(value);
  } else {
    YAML::Emitter e;  // quoted when YAML needs it
    e << value;
    return e.c_str();
  }
}

template <typename T>
void ConfigNode::get(const std::string& key, T& value) const {
  markRead(key);
  YAML::Node n = lookup(key);
  if (n && !n.IsNull()) convert(n, key, value);
  recordValue(key, text(value));
}

template <typename T>
void ConfigNode::require(const std::string& key, T& value) const {
  markRead(key);
  YAML::Node n = lookup(key);
  if (!n || n.IsNull()) {
    recordError(key, "required key is missing");
    return;
  }
  convert(n, key, value);
  recordValue(key, text(value));
}

template <typename E>
void ConfigNode::getEnum(const std::string& key, E& value,
                         const std::vector<std::pair<std::string, E>>& choices) const {
  std::string name;
  for (const auto& [n, v] : choices)
    if (v == value) name = n;
  get(key, name);
  for (const auto& [n, v] : choices) {
    if (n == name) {
      value = v;
      return;
    }
  }
  std::string list;
  for (const auto& c : choices) list += (list.empty() ? "" : ", ") + c.first;
  recordError(key, "must be one of " + list + " (got '" + name + "')");
}

}  // namespace cvslam
