#pragma once
// Command lines of every cvslam program, on CLI11 (Debian's libcli11-dev, header-only).
// One parse call keeps the house rules for all of them:
//   - `-h` / `--help` prints the program's own usage text (or CLI11's) and exits 0, before
//     any required option is checked;
//   - any error is one line on stderr, "<program>: <message> (try --help)", exit status 2;
//   - numbers are parsed strictly (the whole text, finite) with the validators below.
//
//   CLI::App app("…", "cvslam_eval");
//   app.add_option("--run", run_dir)->required();
//   app.add_option("--rate", rate)->check(cvslam::cli::kPositive);
//   if (auto exit_code = cvslam::cli::parse(app, argc, argv, kUsage)) return *exit_code;

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

namespace cvslam::cli {

/// Parses argv into `app`. Returns nullopt when the program should go on; otherwise the exit
/// status main should return (0 after --help, 2 after an error, whose line is printed).
/// `usage`: the program's hand-written help text; nullptr prints CLI11's generated help.
inline std::optional<int> parse(CLI::App& app, int argc, char** argv, const char* usage = nullptr) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    std::fputs(usage != nullptr ? usage : app.help().c_str(), stdout);
    return 0;
  } catch (const CLI::ParseError& e) {
    std::string message = e.what();
    for (char& c : message) {
      if (c == '\n') c = ' ';  // one line, whatever CLI11 composed
    }
    while (!message.empty() && message.back() == ' ') message.pop_back();
    std::fprintf(stderr, "%s: %s (try --help)\n", app.get_name().c_str(), message.c_str());
    return 2;
  }
  return std::nullopt;
}

/// A strict number validator: the whole text is a finite number that satisfies `ok`;
/// otherwise the error says `requirement`.
template <typename Predicate>
CLI::Validator numberValidator(const std::string& name, const std::string& requirement,
                               Predicate ok) {
  return CLI::Validator(
      [requirement, ok](std::string& text) -> std::string {
        char* end = nullptr;
        const double x = std::strtod(text.c_str(), &end);
        if (end == text.c_str() || *end != '\0' || !std::isfinite(x) || !ok(x)) {
          return "must be " + requirement + ", not '" + text + "'";
        }
        return {};
      },
      name);
}

/// Finite (CLI11 alone accepts "nan" and "inf" for doubles).
inline const CLI::Validator kFinite =
    numberValidator("FINITE", "a finite number", [](double) { return true; });
/// Finite and > 0.
inline const CLI::Validator kPositive =
    numberValidator("POSITIVE", "a number > 0", [](double x) { return x > 0.0; });
/// Finite and ≥ 0.
inline const CLI::Validator kNonNegative =
    numberValidator("NONNEGATIVE", "a number ≥ 0", [](double x) { return x >= 0.0; });
/// A whole number ≥ 0 (seeds, counts).
inline const CLI::Validator kCount = numberValidator(
    "COUNT", "a whole number ≥ 0", [](double x) { return x >= 0.0 && x == std::floor(x); });

}  // namespace cvslam::cli
