// libFuzzer target for the command-line number validators every program shares
// (src/base/finite_options.h): CLI11 parses the input, split at newlines into arguments, against
// options of each kind the programs use. Contract: every value accepted is finite and inside
// its range; anything else is a CLI::ParseError (exit 2 in the programs), never a crash.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "src/base/finite_options.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::string> args;
  std::string current;
  for (std::size_t i = 0; i < size && args.size() < 16; ++i) {
    const char c = static_cast<char>(data[i]);
    if (c == '\n') {
      args.push_back(current);
      current.clear();
    } else {
      current += c;
    }
  }
  args.push_back(current);

  CLI::App app{"fuzz"};
  double positive = 1.0, nonNegative = 0.0, ranged = 5.0, plain = 0.0;
  int count = 2;
  std::vector<double> list;
  app.add_option("--positive", positive)->check(jello::cli::positive());
  app.add_option("--non-negative", nonNegative)->check(jello::cli::nonNegative());
  app.add_option("--range", ranged)->check(jello::cli::range(1.0, 10.0));
  app.add_option("--plain", plain);
  app.add_option("--count", count)->check(CLI::Range(1, 256));
  app.add_option("--list", list);
  // CLI11 takes arguments last to first.
  std::vector<std::string> reversed(args.rbegin(), args.rend());
  try {
    app.parse(reversed);
    jello::refuseNonFiniteNumbers(app);
  } catch (const CLI::ParseError&) {
    return 0;
  }
  bool finite = std::isfinite(positive) && std::isfinite(nonNegative) && std::isfinite(ranged) &&
                std::isfinite(plain);
  for (const double v : list) finite = finite && std::isfinite(v);
  if (!finite || !(positive > 0.0) || !(nonNegative >= 0.0) || !(ranged >= 1.0) ||
      !(ranged <= 10.0) || count < 1 || count > 256) {
    std::abort();  // a value the validators should have refused
  }
  return 0;
}
