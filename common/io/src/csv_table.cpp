#include "cvslam/io/csv_table.h"

#include <cstdlib>
#include <fstream>

namespace cvslam {
namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const auto comma = line.find(',', start);
    out.push_back(trim(line.substr(start, comma - start)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

}  // namespace

int CsvTable::column(const std::string& name) const {
  for (std::size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) return static_cast<int>(i);
  return -1;
}

std::string CsvTable::where(std::size_t row) const {
  return source + ":" + std::to_string(row < line_numbers.size() ? line_numbers[row] : 0);
}

Expected<CsvTable> readCsvTable(const std::string& path, const std::vector<std::string>& required) {
  std::ifstream in(path);
  if (!in) return Status::Error(path + ": cannot open");
  CsvTable t;
  t.source = path;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string text = trim(line);
    if (text.empty()) continue;
    if (t.header.empty()) {
      t.header = split(text[0] == '#' ? text.substr(1) : text);
      continue;
    }
    if (text[0] == '#') continue;
    const std::vector<std::string> fields = split(text);
    const std::string at = path + ":" + std::to_string(line_no) + ": ";
    if (fields.size() != t.header.size()) {
      return Status::Error(at + "expected " + std::to_string(t.header.size()) + " fields, got " +
                           std::to_string(fields.size()));
    }
    std::vector<double> row(fields.size());
    for (std::size_t i = 0; i < fields.size(); ++i) {
      const char* begin = fields[i].c_str();
      char* end = nullptr;
      row[i] = std::strtod(begin, &end);
      if (fields[i].empty() || *end != '\0')
        return Status::Error(at + "column '" + t.header[i] + "': not a number: '" + fields[i] +
                             "'");
    }
    t.rows.push_back(std::move(row));
    t.line_numbers.push_back(line_no);
  }
  if (t.header.empty()) return Status::Error(path + ": empty file (no header line)");
  for (const std::string& name : required)
    if (t.column(name) < 0) return Status::Error(path + ": missing column '" + name + "'");
  return t;
}

}  // namespace cvslam
