#pragma once
// Minimal JSON value, writer and parser for run records (stats.json, run.json) and the
// evaluation summary (docs/run_format.md). No JSON library ships with the build machine; the
// subset here is the whole of RFC 8259 except that numbers are always doubles.
// Object members keep insertion order so written files read like the documentation.

#include <string>
#include <utility>
#include <vector>

#include "cvslam/core/status.h"

namespace cvslam {

class Json {
 public:
  enum class Type { kNull, kBool, kNumber, kString, kArray, kObject };

  Json() = default;  ///< null
  static Json boolean(bool b);
  /// A number; non-finite values are written as null (JSON has no NaN or infinity).
  static Json number(double x);
  static Json string(std::string s);
  static Json array();
  static Json object();
  /// Array of numbers.
  static Json numbers(const std::vector<double>& xs);

  Type type() const { return type_; }
  bool isNull() const { return type_ == Type::kNull; }
  bool isNumber() const { return type_ == Type::kNumber; }
  bool isString() const { return type_ == Type::kString; }
  bool isArray() const { return type_ == Type::kArray; }
  bool isObject() const { return type_ == Type::kObject; }

  bool asBool() const { return bool_; }
  double asNumber() const { return number_; }
  const std::string& asString() const { return string_; }
  const std::vector<Json>& items() const { return items_; }
  const std::vector<std::pair<std::string, Json>>& members() const { return members_; }

  /// Member `key` of an object, or nullptr.
  const Json* find(const std::string& key) const;
  /// Appends to an array.
  Json& push(Json value);
  /// Sets (replaces or appends) member `key` of an object.
  Json& set(const std::string& key, Json value);

  /// Serialises; indent < 0 gives one line.
  std::string dump(int indent = 2) const;

  /// Parses text; errors name `source`, line and column.
  static Expected<Json> parse(const std::string& text, const std::string& source = "<json>");
  static Expected<Json> parseFile(const std::string& path);

 private:
  void dumpTo(std::string& out, int indent, int depth) const;

  Type type_ = Type::kNull;
  bool bool_ = false;
  double number_ = 0.0;
  std::string string_;
  std::vector<Json> items_;
  std::vector<std::pair<std::string, Json>> members_;
};

}  // namespace cvslam
