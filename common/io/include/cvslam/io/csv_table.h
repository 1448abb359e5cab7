#pragma once
// Numeric CSV files with a header line (run records, docs/run_format.md). Columns are found
// by name so that optional columns can be added without breaking readers.

#include <string>
#include <vector>

#include "cvslam/core/status.h"

namespace cvslam {

struct CsvTable {
  std::string source;                     ///< file name, for messages
  std::vector<std::string> header;        ///< column names (a leading '#' is dropped)
  std::vector<std::vector<double>> rows;  ///< every row has header.size() numbers
  std::vector<int> line_numbers;          ///< file line of each row (1-based)

  /// Index of column `name`, or −1.
  int column(const std::string& name) const;
  /// "file:line" of row i, for messages.
  std::string where(std::size_t row) const;
};

/// Reads a comma-separated numeric table. Blank lines and lines starting with '#' after the
/// header are skipped; `nan` is accepted (a missing value). Fails with "file:line: reason" on
/// a wrong field count or a non-numeric field, and when a `required` column is absent.
Expected<CsvTable> readCsvTable(const std::string& path,
                                const std::vector<std::string>& required = {});

}  // namespace cvslam
