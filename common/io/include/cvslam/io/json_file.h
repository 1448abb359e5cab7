#pragma once
// JSON of the run records (run.json, stats.json), the evaluation summary and the LCM
// statistics, on nlohmann-json (Debian's nlohmann-json3-dev). `ordered_json` keeps members in
// insertion order, so written files read like docs/run_format.md. This file is the reading
// and writing boundary: nlohmann's exceptions become the project's Status errors here.
// Non-finite numbers are written as null (JSON has no NaN or infinity).

#include <nlohmann/json.hpp>
#include <string>

#include "cvslam/core/status.h"

namespace cvslam {

using Json = nlohmann::ordered_json;

/// Parses `text`; a malformed document gives one line "<source>:<line>:<column>: <what>".
Expected<Json> parseJson(const std::string& text, const std::string& source = "<json>");

/// Reads and parses the file at `path` ("<path>: cannot open" when it cannot be read).
Expected<Json> readJsonFile(const std::string& path);

/// The text of a JSON file: indented by 2 spaces, arrays of plain values on one line, final
/// newline. Every value is nlohmann's text (shortest round-trip numbers, non-finite → null).
std::string formatJson(const Json& json);

/// Writes formatJson(json) to `path`.
Status writeJsonFile(const std::string& path, const Json& json);

}  // namespace cvslam
