// The extreme values of every numeric option of every program never end in a signal (issue 41,
// item 1: jello-work-precision --drift-k 1e308 died of SIGABRT, printing nothing). The options
// come from each program's own --help, so a new one is swept without being listed here. Each
// run is short (two steps, --quick, one frame) and cut at 3 s: a value that makes the run long
// is not a failure, dying by a signal is. Minutes of runs: label `sweep`, out of CI (scripts/
// test.sh without arguments runs it).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "tests/test_support.h"

namespace jello {
namespace {

struct Program {
  std::string name;
  std::string arguments;  // what makes a run short (and a world file where one is needed)
};

struct Case {
  std::string program, option, command;
};

// Every numeric option of `program` from its --help: "  --plane FLOAT x 4 ...", "  -n,--steps-
// per-frame INT:INT in [1 - 1000000]=1"; each run with each extreme value (repeated for options
// taking several numbers).
std::vector<Case> casesOf(const std::filesystem::path& path, const Program& program) {
  const test::Outcome help = test::run(path.string() + " --help");
  EXPECT_EQ(help.code, 0) << program.name;
  const std::regex numeric(R"(^\s+(?:-\w,)?(--[\w-]+) ((?:FLOAT|INT|UINT)\S*)(?: x (\d+))?)");
  static const char* const kFloats[] = {"1e308",     "-1e308", "1e-300", "4.9e-324",
                                        "-4.9e-324", "0",      "-1",     "1e19"};
  static const char* const kInts[] = {"2147483647",          "2147483648", "-2147483649",
                                      "9223372036854775807", "0",          "-1"};
  std::vector<Case> cases;
  std::istringstream lines(help.output);
  for (std::string line; std::getline(lines, line);) {
    std::smatch m;
    if (!std::regex_search(line, m, numeric)) continue;
    const bool floating = m[2].str().rfind("FLOAT", 0) == 0;
    const int count = m[3].matched ? std::stoi(m[3]) : 1;
    const auto add = [&](const char* value) {
      std::string values;
      for (int i = 0; i < count; ++i) values.append(" ").append(value);
      std::string command = "timeout 3 ";
      command.append(path.string()).append(" ").append(program.arguments).append(" ");
      command.append(m[1].str()).append(values).append(" >/dev/null 2>&1");
      cases.push_back({program.name, m[1].str() + values, command});
    };
    if (floating) {
      for (const char* v : kFloats) add(v);
    } else {
      for (const char* v : kInts) add(v);
    }
  }
  return cases;
}

TEST(EveryProgram, TheExtremeValuesOfEveryNumericOptionNeverEndInASignal) {
  const std::filesystem::path bin = std::filesystem::path(JELLO_SIM).parent_path();
  test::TempDir dir;
  const std::string out = dir.path().string();
  const std::string world = (test::worldsDir() / "jello.w").string();
  const Program programs[] = {
      {"jello-sim", world + " --steps 2 --quiet"},
      {"jello-create-world", "-o " + out + "/w.w"},
      {"jello-stability", "--quick --quiet --out-dir " + out + "/s"},
      {"jello-work-precision", "--quick --quiet --out-dir " + out + "/wp"},
      {"jello-scaling", "--quick --quiet --no-atlas --out-dir " + out + "/sc"},
      {"jello", world + " --record " + out + "/frames --frames 1"}};
  std::vector<Case> cases;
  for (const Program& program : programs) {
    const std::filesystem::path path = bin / program.name;
    if (!std::filesystem::exists(path)) {
      std::printf("%s is not built here: not swept\n", program.name.c_str());
      continue;
    }
    for (Case& c : casesOf(path, program)) cases.push_back(std::move(c));
  }
  EXPECT_GE(cases.size(), 300u);  // over 40 numeric options, 6 or 8 values each
  // Two at a time: the runs are processes, mostly refused in milliseconds.
  std::vector<int> codes(cases.size(), 0);
  std::atomic<std::size_t> next{0};
  const auto work = [&] {
    for (std::size_t i = next++; i < cases.size(); i = next++)
      codes[i] = test::run(cases[i].command).code;
  };
  std::thread other(work);
  work();
  other.join();
  int refused = 0, ran = 0, cut = 0;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const int code = codes[i];
    // timeout: 124 when it cut the run; 128 + N when the program died of signal N.
    EXPECT_TRUE(code < 128 || code == 124)
        << cases[i].program << " " << cases[i].option << ": exit " << code << "\n"
        << cases[i].command;
    refused += code == 2;
    ran += code == 0;
    cut += code == 124;
  }
  std::printf(
      "%zu runs: %d refused (exit 2), %d ran (exit 0), %d cut at 3 s, %zu other exits "
      "(asserted: none died of a signal)\n",
      cases.size(), refused, ran, cut, cases.size() - refused - ran - cut);
}

}  // namespace
}  // namespace jello
