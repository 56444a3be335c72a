// What every program's command line shares: numeric options must be finite, and their range
// errors must be short. CLI11's range validators (PositiveNumber, Range, ...) compare, and every
// comparison with NaN is false, so "nan" passed them all; their messages print the largest
// double in full (309 digits). Header-only, for the programs' mains (which link CLI11); the
// model itself does not depend on CLI11.
#pragma once

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>

namespace jello::cli {

// "1e+06", "0.5": a number as a person writes it.
inline std::string shortNumber(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

// The value as a finite number, or an error message.
inline std::string finiteCheck(const std::string& text, double& value) {
  char* end = nullptr;
  value = std::strtod(text.c_str(), &end);
  if (end == text.c_str()) return "'" + text + "' is not a number";
  if (!std::isfinite(value)) return "must be a finite number, not '" + text + "'";
  return {};
}

// A finite number in [lo, hi] (either bound may be infinite), or (lo, hi] when lo is open.
inline CLI::Validator numberIn(double lo, double hi, bool openBelow, const std::string& name) {
  return CLI::Validator(
      [=](std::string& text) {
        double v = 0.0;
        if (std::string e = finiteCheck(text, v); !e.empty()) return e;
        if (openBelow ? !(v > lo) : !(v >= lo)) {
          return "must be " + std::string(openBelow ? "greater than " : "at least ") +
                 shortNumber(lo) + ", not " + text;
        }
        if (!(v <= hi)) return "must be at most " + shortNumber(hi) + ", not " + text;
        return std::string();
      },
      name);
}

inline CLI::Validator positive() {
  return numberIn(0.0, std::numeric_limits<double>::infinity(), true, "POSITIVE");
}
inline CLI::Validator nonNegative() {
  return numberIn(0.0, std::numeric_limits<double>::infinity(), false, "NONNEGATIVE");
}
inline CLI::Validator range(double lo, double hi) {
  return numberIn(lo, hi, false, "in [" + shortNumber(lo) + " - " + shortNumber(hi) + "]");
}

}  // namespace jello::cli

namespace jello {

// Throws CLI::ValidationError (a ParseError: exit code 2 in every program) naming the first
// option given a NaN or an infinity. Covers every option whose type is a number (FLOAT, INT,
// and vectors of them), those without a range check included, so a new option is covered
// without being listed. Call right after app.parse, inside the same try.
inline void refuseNonFiniteNumbers(const CLI::App& app) {
  for (const CLI::Option* option : app.get_options()) {
    const std::string type = option->get_type_name();
    if (type.rfind("FLOAT", 0) != 0 && type.rfind("INT", 0) != 0 && type.rfind("UINT", 0) != 0) {
      continue;
    }
    for (const std::string& text : option->results()) {
      char* end = nullptr;
      const double value = std::strtod(text.c_str(), &end);
      if (end != text.c_str() && !std::isfinite(value)) {
        throw CLI::ValidationError(option->get_name(),
                                   "must be a finite number, not '" + text + "'");
      }
    }
  }
}

}  // namespace jello
