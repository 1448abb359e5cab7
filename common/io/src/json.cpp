#include "cvslam/io/json.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace cvslam {

Json Json::boolean(bool b) {
  Json j;
  j.type_ = Type::kBool;
  j.bool_ = b;
  return j;
}

Json Json::number(double x) {
  Json j;
  if (!std::isfinite(x)) return j;
  j.type_ = Type::kNumber;
  j.number_ = x;
  return j;
}

Json Json::string(std::string s) {
  Json j;
  j.type_ = Type::kString;
  j.string_ = std::move(s);
  return j;
}

Json Json::array() {
  Json j;
  j.type_ = Type::kArray;
  return j;
}

Json Json::object() {
  Json j;
  j.type_ = Type::kObject;
  return j;
}

Json Json::numbers(const std::vector<double>& xs) {
  Json j = array();
  for (double x : xs) j.push(number(x));
  return j;
}

const Json* Json::find(const std::string& key) const {
  for (const auto& [k, v] : members_)
    if (k == key) return &v;
  return nullptr;
}

Json& Json::push(Json value) {
  items_.push_back(std::move(value));
  return *this;
}

Json& Json::set(const std::string& key, Json value) {
  for (auto& [k, v] : members_) {
    if (k == key) {
      v = std::move(value);
      return *this;
    }
  }
  members_.emplace_back(key, std::move(value));
  return *this;
}

namespace {

void appendEscaped(std::string& out, const std::string& s) {
  out += '"';
  for (const char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      case '\b':
        out += "\\b";
        break;
      case '\f':
        out += "\\f";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof(buf), "\\u%04x", static_cast<unsigned>(c));
          out += buf;
        } else {
          out += c;
        }
    }
  }
  out += '"';
}

void newline(std::string& out, int indent, int depth) {
  if (indent < 0) return;
  out += '\n';
  out.append(static_cast<std::size_t>(indent * depth), ' ');
}

}  // namespace

void Json::dumpTo(std::string& out, int indent, int depth) const {
  switch (type_) {
    case Type::kNull:
      out += "null";
      break;
    case Type::kBool:
      out += bool_ ? "true" : "false";
      break;
    case Type::kNumber: {
      char buf[32];
      // Integers print without a fraction; 12 significant digits: far below any figure we report.
      if (number_ == std::floor(number_) && std::abs(number_) < 1e15)
        std::snprintf(buf, sizeof(buf), "%.0f", number_);
      else
        std::snprintf(buf, sizeof(buf), "%.12g", number_);
      out += buf;
      break;
    }
    case Type::kString:
      appendEscaped(out, string_);
      break;
    case Type::kArray: {
      // Arrays of plain values stay on one line (per-axis triples, time series).
      bool flat = true;
      for (const Json& j : items_) flat = flat && !j.isArray() && !j.isObject();
      out += '[';
      for (std::size_t i = 0; i < items_.size(); ++i) {
        if (i) out += flat || indent < 0 ? ", " : ",";
        if (!flat) newline(out, indent, depth + 1);
        items_[i].dumpTo(out, indent, depth + 1);
      }
      if (!flat && !items_.empty()) newline(out, indent, depth);
      out += ']';
      break;
    }
    case Type::kObject: {
      out += '{';
      for (std::size_t i = 0; i < members_.size(); ++i) {
        if (i) out += indent < 0 ? ", " : ",";
        newline(out, indent, depth + 1);
        appendEscaped(out, members_[i].first);
        out += ": ";
        members_[i].second.dumpTo(out, indent, depth + 1);
      }
      if (!members_.empty()) newline(out, indent, depth);
      out += '}';
      break;
    }
  }
}

std::string Json::dump(int indent) const {
  std::string out;
  dumpTo(out, indent, 0);
  if (indent >= 0) out += '\n';
  return out;
}

namespace {

/// Recursive-descent parser over the whole text; errors carry line and column.
class Parser {
 public:
  Parser(const std::string& text, const std::string& source) : s_(text), source_(source) {}

  Expected<Json> parseDocument() {
    Json v;
    if (!parseValue(v, 0)) return Status::Error(error_);
    skipSpace();
    if (pos_ != s_.size()) return fail("unexpected text after the JSON value");
    return v;
  }

 private:
  Status fail(const std::string& what) {
    int line = 1, col = 1;
    for (std::size_t i = 0; i < pos_ && i < s_.size(); ++i) {
      if (s_[i] == '\n') {
        ++line;
        col = 1;
      } else {
        ++col;
      }
    }
    error_ = source_ + ":" + std::to_string(line) + ":" + std::to_string(col) + ": " + what;
    return Status::Error(error_);
  }
  bool failed(const std::string& what) {
    fail(what);
    return false;
  }

  void skipSpace() {
    while (pos_ < s_.size() &&
           (s_[pos_] == ' ' || s_[pos_] == '\n' || s_[pos_] == '\t' || s_[pos_] == '\r'))
      ++pos_;
  }

  bool literal(const char* word) {
    const std::string w(word);
    if (s_.compare(pos_, w.size(), w) != 0) return false;
    pos_ += w.size();
    return true;
  }

  bool parseValue(Json& out, int depth) {
    if (depth > 200) return failed("nesting too deep");
    skipSpace();
    if (pos_ >= s_.size()) return failed("unexpected end of input");
    const char c = s_[pos_];
    if (c == '{') return parseObject(out, depth);
    if (c == '[') return parseArray(out, depth);
    if (c == '"') {
      std::string str;
      if (!parseString(str)) return false;
      out = Json::string(std::move(str));
      return true;
    }
    if (literal("true")) return (out = Json::boolean(true), true);
    if (literal("false")) return (out = Json::boolean(false), true);
    if (literal("null")) return (out = Json(), true);
    if (c == '-' || (c >= '0' && c <= '9')) return parseNumber(out);
    return failed(std::string("unexpected character '") + c + "'");
  }

  bool parseNumber(Json& out) {
    const char* begin = s_.c_str() + pos_;
    char* end = nullptr;
    const double x = std::strtod(begin, &end);
    if (end == begin) return failed("malformed number");
    pos_ += static_cast<std::size_t>(end - begin);
    out = Json::number(x);
    return true;
  }

  bool parseString(std::string& out) {
    ++pos_;  // opening quote
    while (pos_ < s_.size()) {
      const char c = s_[pos_++];
      if (c == '"') return true;
      if (c != '\\') {
        out += c;
        continue;
      }
      if (pos_ >= s_.size()) break;
      const char e = s_[pos_++];
      switch (e) {
        case '"':
          out += '"';
          break;
        case '\\':
          out += '\\';
          break;
        case '/':
          out += '/';
          break;
        case 'b':
          out += '\b';
          break;
        case 'f':
          out += '\f';
          break;
        case 'n':
          out += '\n';
          break;
        case 'r':
          out += '\r';
          break;
        case 't':
          out += '\t';
          break;
        case 'u': {
          if (pos_ + 4 > s_.size()) return failed("truncated \\u escape");
          for (std::size_t i = pos_; i < pos_ + 4; ++i)
            if (!std::isxdigit(static_cast<unsigned char>(s_[i]))) return failed("bad \\u escape");
          const unsigned cp =
              static_cast<unsigned>(std::strtoul(s_.substr(pos_, 4).c_str(), nullptr, 16));
          pos_ += 4;
          // UTF-8 encode the basic multilingual plane (enough for our files).
          if (cp < 0x80) {
            out += static_cast<char>(cp);
          } else if (cp < 0x800) {
            out += static_cast<char>(0xC0 | (cp >> 6));
            out += static_cast<char>(0x80 | (cp & 0x3F));
          } else {
            out += static_cast<char>(0xE0 | (cp >> 12));
            out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
            out += static_cast<char>(0x80 | (cp & 0x3F));
          }
          break;
        }
        default:
          return failed(std::string("bad escape '\\") + e + "'");
      }
    }
    return failed("unterminated string");
  }

  bool parseArray(Json& out, int depth) {
    ++pos_;
    out = Json::array();
    skipSpace();
    if (pos_ < s_.size() && s_[pos_] == ']') return (++pos_, true);
    while (true) {
      Json item;
      if (!parseValue(item, depth + 1)) return false;
      out.push(std::move(item));
      skipSpace();
      if (pos_ < s_.size() && s_[pos_] == ',') {
        ++pos_;
        continue;
      }
      if (pos_ < s_.size() && s_[pos_] == ']') return (++pos_, true);
      return failed("expected ',' or ']' in array");
    }
  }

  bool parseObject(Json& out, int depth) {
    ++pos_;
    out = Json::object();
    skipSpace();
    if (pos_ < s_.size() && s_[pos_] == '}') return (++pos_, true);
    while (true) {
      skipSpace();
      if (pos_ >= s_.size() || s_[pos_] != '"') return failed("expected a quoted key");
      std::string key;
      if (!parseString(key)) return false;
      skipSpace();
      if (pos_ >= s_.size() || s_[pos_] != ':') return failed("expected ':' after key");
      ++pos_;
      Json value;
      if (!parseValue(value, depth + 1)) return false;
      out.set(key, std::move(value));
      skipSpace();
      if (pos_ < s_.size() && s_[pos_] == ',') {
        ++pos_;
        continue;
      }
      if (pos_ < s_.size() && s_[pos_] == '}') return (++pos_, true);
      return failed("expected ',' or '}' in object");
    }
  }

  const std::string& s_;
  const std::string& source_;
  std::size_t pos_ = 0;
  std::string error_;
};

}  // namespace

Expected<Json> Json::parse(const std::string& text, const std::string& source) {
  return Parser(text, source).parseDocument();
}

Expected<Json> Json::parseFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) return Status::Error(path + ": cannot open");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return parse(buffer.str(), path);
}

}  // namespace cvslam
