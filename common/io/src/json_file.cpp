#include "cvslam/io/json_file.h"

#include <algorithm>
#include <fstream>
#include <sstream>

namespace cvslam {
namespace {

/// nlohmann's message without its "[json.exception…] parse error at line L, column C: " prefix
/// (the line and column are put back in the project's "<source>:<line>:<column>:" form).
std::string parseErrorDetail(const std::string& what) {
  const std::size_t column = what.find("column ");
  const std::size_t colon = what.find(": ", column == std::string::npos ? 0 : column);
  return colon == std::string::npos ? what : what.substr(colon + 2);
}

/// One value as nlohmann writes it on one line; invalid UTF-8 in a string is replaced rather
/// than thrown, so that a record is never lost to it.
std::string oneLine(const Json& j) {
  return j.dump(-1, ' ', false, Json::error_handler_t::replace);
}

/// Indents by 2 like nlohmann's dump(2), except that an array of plain values stays on one
/// line: dump(2) would give a stats.json time series one line per frame, where
/// docs/run_format.md shows one line per series.
void appendIndented(std::string& out, const Json& j, int depth) {
  if (!j.is_structured() || j.empty()) {
    out += oneLine(j);
    return;
  }
  const auto structured = [](const Json& e) { return e.is_structured(); };
  if (j.is_array() && std::none_of(j.begin(), j.end(), structured)) {
    out += '[';
    for (std::size_t i = 0; i < j.size(); ++i) out += (i ? ", " : "") + oneLine(j[i]);
    out += ']';
    return;
  }
  const auto newline = [&out](int d) {
    out += '\n';
    out.append(static_cast<std::size_t>(2 * d), ' ');
  };
  out += j.is_object() ? '{' : '[';
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (it != j.begin()) out += ',';
    newline(depth + 1);
    if (j.is_object()) out += oneLine(Json(it.key())) + ": ";
    appendIndented(out, it.value(), depth + 1);
  }
  newline(depth);
  out += j.is_object() ? '}' : ']';
}

}  // namespace

std::string formatJson(const Json& json) {
  std::string out;
  appendIndented(out, json, 0);
  out += '\n';
  return out;
}

Expected<Json> parseJson(const std::string& text, const std::string& source) {
  try {
    return Json::parse(text);
  } catch (const Json::parse_error& e) {
    // e.byte is the 1-based position of the offending character; count lines up to it.
    const std::size_t end = std::min<std::size_t>(e.byte > 0 ? e.byte - 1 : 0, text.size());
    std::size_t line = 1, line_start = 0;
    for (std::size_t i = 0; i < end; ++i) {
      if (text[i] == '\n') {
        ++line;
        line_start = i + 1;
      }
    }
    return Status::Error(source + ":" + std::to_string(line) + ":" +
                         std::to_string(end - line_start + 1) + ": " + parseErrorDetail(e.what()));
  } catch (const Json::exception& e) {
    return Status::Error(source + ": " + e.what());
  }
}

Expected<Json> readJsonFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::Error(path + ": cannot open");
  std::ostringstream text;
  text << in.rdbuf();
  return parseJson(text.str(), path);
}

Status writeJsonFile(const std::string& path, const Json& json) {
  std::ofstream out(path, std::ios::trunc);
  if (!out) return Status::Error(path + ": cannot write");
  out << formatJson(json);
  return out ? Status::Ok() : Status::Error(path + ": write failed");
}

}  // namespace cvslam
