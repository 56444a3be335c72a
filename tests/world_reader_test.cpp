// The reader against the six reference worlds and every class of bad input.
#include "src/world/world_reader.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <csignal>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "src/world/scene_builder.h"
#include "src/world/world_writer.h"
#include "tests/test_support.h"

namespace jello {
namespace {

struct Header {
  friend void PrintTo(const Header& h, std::ostream* os) { *os << h.file; }
  std::string file;
  double dt;
  double kElastic, kCollision;
  std::optional<Plane> plane;
  Vec3 firstFieldNode;
  Vec3 velocity;      // of every point
  bool skewedCorner;  // p[7][7][7] = (8/7, 8/7, 8/7)
};

class ReferenceWorld : public ::testing::TestWithParam<Header> {};

TEST_P(ReferenceWorld, LoadsWithItsHeaderValues) {
  const Header& h = GetParam();
  const World w = test::loadWorld(h.file);
  EXPECT_EQ(w.integrator, IntegratorKind::RK4);
  EXPECT_EQ(w.dt, h.dt);
  EXPECT_EQ(w.stepsPerFrame, 1);
  EXPECT_EQ(w.kElastic, h.kElastic);
  EXPECT_EQ(w.dElastic, 0.25);
  EXPECT_EQ(w.kCollision, h.kCollision);
  EXPECT_EQ(w.dCollision, 0.25);
  EXPECT_EQ(w.mass, 0.001953);  // 1/512 printed with six decimals
  ASSERT_EQ(w.plane.has_value(), h.plane.has_value());
  if (h.plane) {
    EXPECT_EQ(w.plane->a, h.plane->a);
    EXPECT_EQ(w.plane->b, h.plane->b);
    EXPECT_EQ(w.plane->c, h.plane->c);
    EXPECT_EQ(w.plane->d, h.plane->d);
  }
  ASSERT_EQ(w.field.resolution, 30);
  ASSERT_EQ(w.field.forces.size(), 27000u);
  EXPECT_EQ(w.field.forces.front(), h.firstFieldNode);
  EXPECT_EQ(w.cubeResolution, 8);
  ASSERT_EQ(w.positions.size(), 512u);
  ASSERT_EQ(w.velocities.size(), 512u);
  const Lattice lat{8};
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 8; ++j)
      for (int k = 0; k < 8; ++k) {
        const int p = lat.index(i, j, k);
        const double scale = (h.skewedCorner && p == 511) ? 8.0 / 7.0 : 1.0;
        const Vec3 expected = p == 511 ? Vec3{scale, scale, scale} : lat.restPosition(i, j, k);
        EXPECT_NEAR(w.positions[p].x, expected.x, 5e-7) << p;
        EXPECT_NEAR(w.positions[p].y, expected.y, 5e-7) << p;
        EXPECT_NEAR(w.positions[p].z, expected.z, 5e-7) << p;
        EXPECT_EQ(w.velocities[p], h.velocity) << p;
      }
  EXPECT_FALSE(w.sphere.has_value());
}

INSTANTIATE_TEST_SUITE_P(
    AllSix, ReferenceWorld,
    ::testing::Values(
        Header{"jello.w", 0.0005, 200, 400, Plane{-1, 1, 1, 2}, {}, {10, -10, 20}, true},
        Header{
            "createWorld-default.w", 0.0005, 200, 400, Plane{-1, 1, 1, 2}, {}, {10, -10, 20}, true},
        Header{"moveLeft.w", 0.0005, 500, 1000, std::nullopt, {}, {-50, 0, 0}, false},
        Header{"rotate.w",
               0.001,
               500,
               1000,
               Plane{1, -1, -1, 4},
               {0.019531, -0.019531, 0},
               {0, 0, 0},
               false},
        Header{"skewedCorner.w", 0.00001, 500, 1000, std::nullopt, {}, {0, 0, 0}, true},
        Header{"gravity.w",
               0.0001,
               500,
               1000,
               Plane{-1, 1, 2, 6},
               {0, 0, -0.06},
               {10, -10, 0},
               false}),
    [](const auto& param_info) {
      std::string name = param_info.param.file.substr(0, param_info.param.file.find('.'));
      name.erase(std::remove(name.begin(), name.end(), '-'), name.end());
      return name;
    });

TEST(ReferenceWorlds, RotateFieldIsTheVortexAtEveryNode) {
  const World w = test::loadWorld("rotate.w");
  const int r = w.field.resolution;
  for (int i = 0; i < r; ++i)
    for (int j = 0; j < r; ++j)
      for (int k = 0; k < r; ++k) {
        const double x = -2.0 + 4.0 * i / (r - 1), y = -2.0 + 4.0 * j / (r - 1);
        const Vec3& f = w.field.forces[(i * r + j) * r + k];
        EXPECT_NEAR(f.x, 5.0 / 512 * -y, 5e-7);
        EXPECT_NEAR(f.y, 5.0 / 512 * x, 5e-7);
        EXPECT_EQ(f.z, 0.0);
      }
}

TEST(ReferenceWorlds, CrlfLineEndingsReadLikeLf) {
  const std::string lf = test::readFile(test::worldsDir() / "rotate.w");
  std::string crlf;
  for (char c : lf) {
    if (c == '\n') crlf += '\r';
    crlf += c;
  }
  const World a = parseWorld(lf, "lf"), b = parseWorld(crlf, "crlf");
  EXPECT_EQ(formatWorld(a), formatWorld(b));
}

TEST(ReferenceWorlds, IntegratorNamesAreCaseInsensitive) {
  const std::string text = test::readFile(test::worldsDir() / "moveLeft.w");
  for (const char* name : {"EULER", "euler", "Euler", "rk4", "Symplectic"}) {
    const World w = parseWorld(name + text.substr(3), "named");
    EXPECT_EQ(w.integrator, *parseIntegratorName(name));
  }
}

// A valid world small enough to edit by line: plane on line 6, a 2^3 field on lines 8-15,
// positions from line 16, velocities from line 528.
std::vector<std::string> validLines() {
  SceneSpec spec;
  spec.fieldResolution = 2;
  std::istringstream in(formatWorld(buildWorld(spec)));
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::string join(const std::vector<std::string>& lines) {
  std::string text;
  for (const std::string& l : lines) text += l + "\n";
  return text;
}

struct BadInput {
  friend void PrintTo(const BadInput& b, std::ostream* os) { *os << b.name; }
  std::string name;
  int line;             // 1-based line to replace; 0: use `text` as the whole file
  std::string replace;  // its new text ("" with drop > 0: remove lines)
  int drop = 0;         // lines to remove from the end
  std::string append;   // text added at the end
  int expectedLine;
  std::string expectedToken;
  std::string expectedMessage;
};

class BadWorld : public ::testing::TestWithParam<BadInput> {};

TEST_P(BadWorld, IsRefusedNamingFileLineAndToken) {
  const BadInput& b = GetParam();
  std::vector<std::string> lines = validLines();
  if (b.line > 0) lines[b.line - 1] = b.replace;
  lines.resize(lines.size() - b.drop);
  std::string text = b.line == 0 && b.drop == 0 && b.append.empty() ? b.replace : join(lines);
  text += b.append;
  try {
    (void)parseWorld(text, "bad.w");
    FAIL() << "accepted";
  } catch (const WorldFileError& e) {
    EXPECT_EQ(e.file(), "bad.w");
    EXPECT_EQ(e.line(), b.expectedLine) << e.what();
    EXPECT_EQ(e.token(), b.expectedToken) << e.what();
    EXPECT_NE(std::string(e.what()).find(b.expectedMessage), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).rfind("bad.w:" + std::to_string(b.expectedLine) + ": ", 0), 0u)
        << e.what();
  }
}

INSTANTIATE_TEST_SUITE_P(
    EveryErrorClass, BadWorld,
    ::testing::Values(
        BadInput{"EmptyFile", 0, "", 0, "", 1, "<end of file>", "empty file"},
        BadInput{"UnknownIntegrator", 1, "Verlet", 0, "", 1, "Verlet", "unknown integrator"},
        BadInput{"ZeroDt", 2, "0 1", 0, "", 2, "0", "must be positive"},
        BadInput{"NegativeDt", 2, "-0.001 1", 0, "", 2, "-0.001", "must be positive"},
        BadInput{"NanDt", 2, "nan 1", 0, "", 2, "nan", "must be finite"},
        BadInput{"NonNumericDt", 2, "fast 1", 0, "", 2, "fast", "expected a number"},
        BadInput{"ZeroStepsPerFrame", 2, "0.001 0", 0, "", 2, "0", "at least 1"},
        BadInput{"FractionalStepsPerFrame", 2, "0.001 1.5", 0, "", 2, "1.5", "expected an integer"},
        BadInput{"NegativeConstant", 3, "200 -0.25 400 0.25", 0, "", 3, "-0.25",
                 "must not be negative"},
        BadInput{"ZeroMass", 4, "0", 0, "", 4, "0", "must be positive"},
        BadInput{"InfiniteMass", 4, "inf", 0, "", 4, "inf", "must be finite"},
        BadInput{"OverflowingMass", 4, "1e999", 0, "", 4, "1e999", "out of range"},
        BadInput{"ZeroPlaneNormal", 6, "0 0 0 2", 0, "", 6, "0", "normal (a,b,c) is zero"},
        BadInput{"FieldResolutionOne", 7, "1", 0, "", 7, "1", "force-field resolution"},
        BadInput{"NegativeFieldResolution", 7, "-3", 0, "", 7, "-3", "force-field resolution"},
        BadInput{"HugeFieldResolution", 7, "100000", 0, "", 7, "100000", "force-field resolution"},
        BadInput{"FieldLargerThanTheFile", 7, "100", 0, "", 7, "100", "too short"},
        BadInput{"NonNumericPosition", 16, "0 abc 0", 0, "", 16, "abc", "expected a number"},
        BadInput{"InfinitePosition", 20, "0 0 -inf", 0, "", 20, "-inf", "must be finite"},
        BadInput{"TruncatedVelocities", 0, "", 10, "", 1029, "<end of file>",
                 "truncated: 502 of 512 velocities"},
        BadInput{"TruncatedPositions", 0, "", 600, "", 439, "<end of file>",
                 "truncated: 424 of 512 positions"},
        BadInput{"TrailingNumbers", 0, "", 0, "1 2 3\n", 1040, "1", "unknown trailing content"},
        BadInput{"UnknownKeyword", 0, "", 0, "wobble 3\n", 1040, "wobble",
                 "unknown trailing content"},
        BadInput{"CubeResolutionOne", 0, "", 0, "cube 1\n", 1040, "1", "cube resolution"},
        BadInput{"CubeResolutionMismatch", 0, "", 0, "cube 3\n", 70, "0",
                 "unknown trailing content"},
        BadInput{"NegativeSphereRadius", 0, "", 0, "sphere 0 0 0 -1\n", 1040, "-1",
                 "must be positive"},
        BadInput{"CubeTwice", 0, "", 0, "cube 8\ncube 8\n", 1041, "cube", "given twice"},
        BadInput{"SixConstants", 3, "200 0.25 400 0.25 0.25 0.25", 0, "", 3, "0.25",
                 "holds more numbers than the four constants"},
        // The "dt n" line twice: the numbers after it read one place off, the plane flag
        // failing on line 5; the line to blame is the repeated one, 3.
        BadInput{"RepeatedDtLine", 3, "0.0005 1\n200 0.25 400 0.25", 0, "", 3, "0.0005",
                 "holds 2 of the four constants"},
        BadInput{"IntegratorTwice", 0, "", 0, "integrator implicit\nintegrator bdf2\n", 1041,
                 "integrator", "given twice"},
        BadInput{"UnknownIntegratorExtension", 0, "", 0, "integrator Verlet\n", 1040, "Verlet",
                 "unknown integrator"},
        BadInput{"IntegratorExtensionWithoutName", 0, "", 0, "integrator\n", 1041, "<end of file>",
                 "integrator name was expected"},
        BadInput{"StartsFarAway", 20, "150 0 0", 0, "", 20, "150", "m from the origin"},
        BadInput{"InfiniteKineticEnergy", 530, "1e200 0 0", 0, "", 530, "1e200",
                 "infinite kinetic energy"},
        BadInput{"CoincidentPoints", 17, "0 0 0", 0, "", 17, "0", "start at the same position"},
        BadInput{"ConeWithZeroAxis", 0, "", 0, "cone 0 0 0 0 0 0 1 1\n", 1040, "0",
                 "axis must not be zero"},
        BadInput{"SpiralThickerThanItsPitch", 0, "", 0, "spiral 0 0 1 0.5 1.5 0.2 1 0.3\n", 1040,
                 "0.3", "less than its pitch"}),
    [](const auto& param_info) { return param_info.param.name; });

TEST(WorldReader, RefusesAHugeCubeBeforeAllocating) {
  ReaderLimits limits;
  limits.maxCubeResolution = 16;
  std::vector<std::string> lines = validLines();
  lines.push_back("cube 17");
  EXPECT_THROW((void)parseWorld(join(lines), "big.w", limits), WorldFileError);
}

TEST(WorldReader, RefusesEndlessNumbersAtTheFirstOneNoCubeCouldHold) {
  // A valid 2^3 world followed by a million numbers: with the cube limit at 16 (6 * 16^3 =
  // 24,576 numbers), the reader stops at the first number past that bound, naming its line,
  // instead of collecting all of them.
  ReaderLimits limits;
  limits.maxCubeResolution = 16;
  World w = buildWorld(SceneSpec{});
  std::string text = formatWorld(w);
  for (int i = 0; i < 1000000; ++i) text += "1\n";
  try {
    (void)parseWorld(text, "endless.w", limits);
    FAIL() << "accepted";
  } catch (const WorldFileError& e) {
    EXPECT_NE(std::string(e.what()).find("more numbers than the positions and velocities"),
              std::string::npos)
        << e.what();
    // The world's own 6 * 512 numbers and then one per line: the line of number 24,577.
    const auto worldLines =
        std::count(text.begin(), text.begin() + long(formatWorld(w).size()), '\n');
    EXPECT_EQ(e.line(), worldLines + (6 * 16 * 16 * 16 - 6 * 512) + 1);
  }
}

TEST(WorldReader, ReportsAMissingFile) {
  try {
    (void)readWorld("/nonexistent/dir/world.w");
    FAIL();
  } catch (const WorldFileError& e) {
    EXPECT_EQ(e.line(), 0);
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/world.w"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("cannot open"), std::string::npos);
    // The file as a whole has no line: no "world.w:0:" (issue 41, low).
    EXPECT_EQ(std::string(e.what()).rfind("/nonexistent/dir/world.w: cannot open", 0), 0u)
        << e.what();
  }
}

// Some editors start a file with a UTF-8 byte-order mark: it is not part of the integrator.
TEST(WorldReader, AcceptsAByteOrderMark) {
  const std::string text = join(validLines());
  const World plain = parseWorld(text, "plain.w");
  const World marked = parseWorld("\xEF\xBB\xBF" + text, "bom.w");
  EXPECT_EQ(marked.integrator, plain.integrator);
  EXPECT_EQ(marked.positions.size(), plain.positions.size());
}

// A bad token is shown at most 40 bytes long, control and non-ASCII bytes escaped: a 1 MB
// "number" or a terminal escape sequence never reaches the message whole.
TEST(WorldReader, ShowsBadTokensShortAndEscaped) {
  std::vector<std::string> lines = validLines();
  lines[1] = std::string(1 << 20, '7') + "x 1";
  try {
    (void)parseWorld(join(lines), "long.w");
    FAIL() << "accepted";
  } catch (const WorldFileError& e) {
    EXPECT_LT(std::string(e.what()).size(), 300u);
    EXPECT_NE(std::string(e.what()).find("(1048577 bytes)"), std::string::npos) << e.what();
  }
  lines = validLines();
  lines[1] = "\x1b[31mred 1";
  try {
    (void)parseWorld(join(lines), "escape.w");
    FAIL() << "accepted";
  } catch (const WorldFileError& e) {
    EXPECT_EQ(std::string(e.what()).find('\x1b'), std::string::npos) << e.what();
    EXPECT_EQ(e.token(), "\\x1b[31mred");
  }
}

TEST(WorldReader, ReportsADirectory) {
  EXPECT_THROW((void)readWorld(test::worldsDir()), WorldFileError);
}

// Special inputs: a pipe is read to its end like a file (here written by a thread); a file of
// /proc, whose size reads 0, is read too and refused for what it holds (not as "empty"); a
// device is refused by name before anything is read.
TEST(WorldReader, ReadsPipesAndProcFilesAndRefusesDevices) {
  test::TempDir dir;
  const auto fifo = dir.path() / "world.fifo";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const std::string text = test::readFile(test::worldsDir() / "jello.w");
  std::thread writer([&] {
    std::ofstream out(fifo, std::ios::binary);
    out << text;
  });
  const World fromPipe = readWorld(fifo);
  writer.join();
  EXPECT_EQ(fromPipe.positions, readWorld(test::worldsDir() / "jello.w").positions);
  try {
    (void)readWorld("/proc/self/status");
    FAIL() << "accepted";
  } catch (const WorldFileError& e) {
    EXPECT_EQ(e.line(), 1);
    EXPECT_EQ(std::string(e.what()).find("empty file"), std::string::npos) << e.what();
  }
  try {
    (void)readWorld("/dev/null");
    FAIL() << "accepted";
  } catch (const WorldFileError& e) {
    EXPECT_NE(std::string(e.what()).find("is a device"), std::string::npos) << e.what();
  }
}

// Peak resident memory of this process (kB), after resetting it when `reset` (Linux's clear_refs).
long peakResidentKb(bool reset) {
  if (reset) std::ofstream("/proc/self/clear_refs") << "5";
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stol(line.substr(6));
  }
  return -1;
}

// Huge inputs are read in chunks and refused early, in bounded memory: a 200 MB file whose
// velocities are followed by one giant token (a sparse file of NUL bytes), and a pipe of endless
// numbers, refused at the first number no allowed cube could hold. The whole-text reader used
// about 22x (later 1x) the file in memory and read every byte first.
TEST(WorldReader, RefusesHugeInputsEarlyInBoundedMemory) {
#if defined(__SANITIZE_ADDRESS__)
  constexpr long kBoundScale = 3;  // AddressSanitizer's shadow and quarantine (measured 110 MB)
#else
  constexpr long kBoundScale = 1;
#endif
  test::TempDir dir;
  const std::string text = test::readFile(test::worldsDir() / "jello.w");
  const auto big = dir.path() / "big.w";
  std::ofstream(big, std::ios::binary) << text;
  std::filesystem::resize_file(big, 200u << 20);
  const long before = peakResidentKb(true);
  ASSERT_GT(before, 0);
  try {
    (void)readWorld(big);
    FAIL() << "accepted";
  } catch (const WorldFileError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown trailing content"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("bytes)"), std::string::npos) << e.what();
    EXPECT_LT(std::string(e.what()).size(), 400u);
  }
  EXPECT_LT(peakResidentKb(false) - before, kBoundScale * 32 * 1024)
      << "kB above the peak before reading";

  const auto fifo = dir.path() / "endless.fifo";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  std::signal(SIGPIPE, SIG_IGN);  // the writer sees EPIPE when the reader stops
  long written = 0;
  std::thread writer([&] {
    const int fd = ::open(fifo.c_str(), O_WRONLY);
    if (fd < 0) return;
    std::string chunk = text;
    for (int i = 0; i < 4096; ++i) chunk += "1.25 ";
    while (written < (1L << 30)) {
      const ssize_t n = ::write(fd, chunk.data(), chunk.size());
      if (n <= 0) break;
      written += n;
      chunk = chunk.substr(chunk.size() - 4096 * 5);  // numbers only after the first world
    }
    ::close(fd);
  });
  const long beforePipe = peakResidentKb(true);
  try {
    (void)readWorld(fifo);
    FAIL() << "accepted";
  } catch (const WorldFileError& e) {
    EXPECT_NE(std::string(e.what()).find("more numbers than the positions and velocities"),
              std::string::npos)
        << e.what();
  }
  const long peak = peakResidentKb(false) - beforePipe;
  writer.join();
  std::signal(SIGPIPE, SIG_DFL);
  EXPECT_LT(peak, kBoundScale * 96 * 1024) << "kB above the peak before reading";
  // 6 * 64^3 numbers of 5 bytes are about 8 MB: the rest of the pipe was never read.
  EXPECT_LT(written, 64L << 20);
}

TEST(WorldReader, ReadsPlaneFlagsOtherThanOneAsNoPlane) {
  std::vector<std::string> lines = validLines();
  lines[4] = "7";
  lines.erase(lines.begin() + 5);  // the plane's coefficients
  EXPECT_FALSE(parseWorld(join(lines), "flag.w").plane.has_value());
}

}  // namespace
}  // namespace jello
