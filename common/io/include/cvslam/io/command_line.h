#pragma once
// The two pieces every cvslam program's hand-written argv loop needs: the value after an
// option, and a strict number (the whole text, finite). Errors are one line, naming the option.

#include <cmath>
#include <cstdlib>
#include <string>

namespace cvslam {

/// The argument after argv[*i] (advancing *i), or false with "<option> needs a value".
inline bool nextArgValue(int argc, char** argv, int* i, std::string* out, std::string* error) {
  const std::string option = argv[*i];
  if (*i + 1 >= argc) {
    *error = option + " needs a value";
    return false;
  }
  *out = argv[++*i];
  return true;
}

/// `text` as a finite number, or false with "<option>: not a number: '<text>'".
inline bool parseNumberArg(const std::string& option, const std::string& text, double* x,
                           std::string* error) {
  char* end = nullptr;
  *x = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0' || !std::isfinite(*x)) {
    *error = option + ": not a number: '" + text + "'";
    return false;
  }
  return true;
}

}  // namespace cvslam
