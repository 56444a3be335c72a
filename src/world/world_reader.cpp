#include "src/world/world_reader.h"

#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>
#include <system_error>
#include <tuple>
#include <vector>

#include "src/base/atomic_file.h"
#include "src/world/world_tokenizer.h"

namespace jello {
namespace {

using reader::StreamSource;
using reader::TextSource;
using reader::Token;
using reader::Tokenizer;
using reader::TokenLog;

std::string metres(double value) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", value);
  return buf;
}

bool looksNumeric(std::string_view s) {
  const char c = s.front();
  return (c >= '0' && c <= '9') || c == '-' || c == '+' || c == '.';
}

// True when `count` numbers are the positions and velocities of some N^3 cube, N >= 2: a word
// after them is trailing content, not a bad number.
bool completeCube(std::size_t count) {
  if (count == 0 || count % 6 != 0) return false;
  const std::size_t points = count / 6;
  const auto n = static_cast<std::size_t>(std::llround(std::cbrt(static_cast<double>(points))));
  return n >= 2 && n * n * n == points;
}

// The extension keywords (worlds/FORMAT.md), one row each: what follows the keyword is read by
// its function into the world. Each may appear once.
void readIntegratorExtension(Tokenizer& in, World& world, const ReaderLimits& limits) {
  const Token name = in.next();
  if (name.text.empty()) in.fail(name, "file ends where an integrator name was expected");
  if (const auto kind = parseIntegratorName(name.text)) {
    world.integrator = *kind;
    world.unknownIntegrator.clear();
  } else if (limits.acceptUnknownIntegrator) {
    world.unknownIntegrator = std::string(name.text);  // the caller overrides it
  } else {
    in.fail(name, "unknown integrator (known: " + integratorNameList() +
                      "; --integrator on the command line overrides it)");
  }
}

void readCubeExtension(Tokenizer& in, World& world, const ReaderLimits& limits) {
  const int n = in.integer("cube resolution");
  if (n < 2 || n > limits.maxCubeResolution) {
    in.fail(in.lastToken(),
            "cube resolution must be between 2 and " + std::to_string(limits.maxCubeResolution));
  }
  world.cubeResolution = n;
}

void readSphereExtension(Tokenizer& in, World& world, const ReaderLimits&) {
  Sphere s;
  s.center.x = in.number("sphere centre x");
  s.center.y = in.number("sphere centre y");
  s.center.z = in.number("sphere centre z");
  s.radius = in.positive("sphere radius");
  world.sphere = s;
}

void readConeExtension(Tokenizer& in, World& world, const ReaderLimits&) {
  Cone c;
  c.apex.x = in.number("cone apex x");
  c.apex.y = in.number("cone apex y");
  c.apex.z = in.number("cone apex z");
  c.axis.x = in.number("cone axis x");
  c.axis.y = in.number("cone axis y");
  c.axis.z = in.number("cone axis z");
  if (c.axis.x == 0.0 && c.axis.y == 0.0 && c.axis.z == 0.0) {
    in.fail(in.lastToken(), "the cone's axis must not be zero");
  }
  c.height = in.positive("cone height");
  c.radius = in.positive("cone base radius");
  world.cone = c;
}

void readSpiralExtension(Tokenizer& in, World& world, const ReaderLimits&) {
  Spiral s;
  s.cx = in.number("spiral axis x");
  s.cy = in.number("spiral axis y");
  s.zTop = in.number("spiral top height");
  s.rInner = in.number("spiral inner radius");
  if (s.rInner < 0.0) in.fail(in.lastToken(), "the spiral's inner radius must be >= 0");
  s.rOuter = in.positive("spiral outer radius");
  if (!(s.rOuter > s.rInner)) {
    in.fail(in.lastToken(), "the spiral's outer radius must exceed its inner radius");
  }
  s.pitch = in.positive("spiral pitch");
  s.turns = in.positive("spiral turns");
  if (s.turns > 100.0) in.fail(in.lastToken(), "the spiral has at most 100 turns");
  s.thickness = in.positive("spiral thickness");
  if (!(s.thickness < s.pitch)) {
    in.fail(in.lastToken(), "the spiral's thickness must be less than its pitch");
  }
  world.spiral = s;
}

// `contact MODEL [parameters]`: penalty takes none, smooth its layer (m, > 0), barrier its
// dhat (m, > 0) and kappa (N/m, > 0).
void readContactExtension(Tokenizer& in, World& world, const ReaderLimits&) {
  const Token name = in.next();
  if (name.text.empty()) in.fail(name, "file ends where a contact model was expected");
  const std::optional<ContactModel> model = contactModelFromName(name.text);
  if (!model) in.fail(name, "unknown contact model (known: " + contactModelNames() + ")");
  ContactLaw law;
  law.model = *model;
  law.mu = world.contact.mu;  // the friction extension may come first
  law.slipSpeed = world.contact.slipSpeed;
  if (law.model == ContactModel::Smooth) law.layer = in.positive("smooth contact layer");
  if (law.model == ContactModel::Barrier) {
    law.dhat = in.positive("barrier distance dhat");
    law.kappa = in.positive("barrier stiffness kappa");
  }
  world.contact = law;
}

// `friction MU SLIP`: Coulomb's coefficient (>= 0) and the slip speed eps_v (m/s, > 0).
void readFrictionExtension(Tokenizer& in, World& world, const ReaderLimits&) {
  world.contact.mu = in.nonNegative("friction coefficient mu");
  world.contact.slipSpeed = in.positive("friction slip speed");
}

struct Extension {
  std::string_view keyword;
  void (*read)(Tokenizer&, World&, const ReaderLimits&);
};
constexpr Extension kExtensions[] = {
    {"integrator", readIntegratorExtension}, {"cube", readCubeExtension},
    {"sphere", readSphereExtension},         {"cone", readConeExtension},
    {"spiral", readSpiralExtension},         {"contact", readContactExtension},
    {"friction", readFrictionExtension},
};

const Extension* extension(std::string_view keyword) {
  for (const Extension& e : kExtensions) {
    if (e.keyword == keyword) return &e;
  }
  return nullptr;
}

// "integrator, cube, sphere, cone, spiral": for the messages about unknown content.
std::string extensionKeywords() {
  std::string list;
  for (const Extension& e : kExtensions)
    list += (list.empty() ? "" : ", ") + std::string(e.keyword);
  return list;
}

// Reads the extension block from `keyword` on: one keyword per entry, each at most once.
void readExtensions(Tokenizer& in, Token keyword, World& world, const ReaderLimits& limits) {
  std::vector<std::string_view> seen;
  while (!keyword.text.empty()) {
    const Extension* e = extension(keyword.text);
    if (!e) {
      in.fail(keyword,
              "unknown trailing content (extension keywords: " + extensionKeywords() + ")");
    }
    if (std::find(seen.begin(), seen.end(), e->keyword) != seen.end()) {
      in.fail(keyword, "extension '" + std::string(e->keyword) + "' given twice");
    }
    seen.push_back(e->keyword);
    world.sources.push_back({std::string(e->keyword), keyword.line, std::string(keyword.text)});
    e->read(in, world, limits);
    keyword = in.next();
  }
}

}  // namespace

// File names keep their length and their UTF-8; only control bytes are escaped.
std::string displayToken(std::string_view token, std::size_t limit, bool keepUtf8,
                         std::size_t bytes) {
  bytes = std::max(bytes, token.size());
  std::string out;
  for (std::size_t i = 0; i < token.size() && i < limit; ++i) {
    const auto c = static_cast<unsigned char>(token[i]);
    if ((c >= 0x20 && c < 0x7f) || (keepUtf8 && c >= 0x80)) {
      out += static_cast<char>(c);
    } else {
      static constexpr char hex[] = "0123456789abcdef";
      out += "\\x";
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  if (bytes > limit) {
    out += "... (" + std::to_string(bytes) + " bytes)";
  }
  return out;
}

WorldFileError::WorldFileError(std::string file, int line, std::string token,
                               const std::string& message, std::size_t tokenBytes)
    // Line 0 is the file as a whole (it cannot be opened, it is too large): no ":0".
    : std::runtime_error(displayToken(file, file.size(), true) +
                         (line > 0 ? ":" + std::to_string(line) : std::string()) + ": " + message +
                         " (at '" + displayToken(token, kShownTokenBytes, false, tokenBytes) +
                         "')"),
      file_(std::move(file)),
      line_(line),
      token_(displayToken(token, kShownTokenBytes, false, tokenBytes)) {}

namespace {

// The integrator, the time step, the constants, the mass and the plane.
void readHeader(Tokenizer& in, const ReaderLimits& limits, World& w) {
  const Token integrator = in.next();
  if (integrator.text.empty()) in.fail(integrator, "empty file: no integrator name");
  const auto kind = parseIntegratorName(integrator.text);
  if (kind) {
    w.integrator = *kind;
  } else if (limits.acceptUnknownIntegrator) {
    w.unknownIntegrator = std::string(integrator.text);  // the caller overrides it
  } else {
    in.fail(integrator, "unknown integrator (known: " + integratorNameList() +
                            "; --integrator on the command line overrides it)");
  }

  w.dt = in.positive("the time step dt");
  w.stepsPerFrame = in.integer("n (steps per frame)");
  if (w.stepsPerFrame < 1) in.fail(in.lastToken(), "n (steps per frame) must be at least 1");
  // The line of each constant: a line that holds fewer than four (a repeated "dt n" line) is
  // where a failure further on started.
  std::array<Token, 4> constants;
  w.kElastic = in.nonNegative("kElastic");
  constants[0] = in.lastToken();
  w.dElastic = in.nonNegative("dElastic");
  constants[1] = in.lastToken();
  w.kCollision = in.nonNegative("kCollision");
  constants[2] = in.lastToken();
  w.dCollision = in.nonNegative("dCollision");
  constants[3] = in.lastToken();
  const int constantsLine = in.lastToken().line;
  w.sources.push_back({"kElastic", constants[0].line, constants[0].text});
  w.sources.push_back({"kCollision", constants[2].line, constants[2].text});
  w.mass = in.positive("the point mass");
  // Line breaks carry no meaning, but a mass on the constants' line usually means that line has
  // too many numbers, which is what to say when the plane flag then fails.
  const std::string flagHint =
      in.lastToken().line == constantsLine
          ? " (line " + std::to_string(constantsLine) +
                " holds more numbers than the four constants kElastic dElastic kCollision "
                "dCollision: the extra ones were read as the mass and the plane flag)"
          : std::string();

  int planeFlag = 0;
  try {
    planeFlag = in.integer("the plane flag", flagHint);
  } catch (const WorldFileError& e) {
    const int first = constants[0].line;
    const auto onFirst = std::count_if(constants.begin(), constants.end(),
                                       [first](const Token& t) { return t.line == first; });
    if (onFirst == 4) throw;
    // The constants began on a line too short for them: that line is the mistake.
    in.fail(constants[0], "line " + std::to_string(first) + " holds " + std::to_string(onFirst) +
                              " of the four constants kElastic dElastic kCollision dCollision "
                              "(a repeated 'dt n' line?), so every number after it was read one "
                              "place off: line " +
                              std::to_string(e.line()) + " then failed");
  }
  if (planeFlag == 1) {
    const Token first = in.next();
    Plane p;
    p.a = in.toNumber(first, "plane a");
    p.b = in.number("plane b");
    p.c = in.number("plane c");
    p.d = in.number("plane d");
    if (p.a == 0.0 && p.b == 0.0 && p.c == 0.0) in.fail(first, "the plane normal (a,b,c) is zero");
    w.plane = p;
    w.sources.push_back({"plane", first.line, first.text});
  }
}

void readField(Tokenizer& in, const ReaderLimits& limits, World& w) {
  const int res = in.integer("the force-field resolution");
  const Token resToken = in.lastToken();
  if (res < 0 || res == 1 || res > limits.maxFieldResolution) {
    in.fail(resToken, "force-field resolution must be 0 (none) or between 2 and " +
                          std::to_string(limits.maxFieldResolution));
  }
  if (res == 0) return;
  const std::size_t nodes = static_cast<std::size_t>(res) * res * res;
  // Each of the 3*nodes numbers needs at least a digit and a separator: refuse before
  // allocating when the file cannot hold them.
  if (in.remainingBytes() < nodes * 3 * 2 - 1) {
    in.fail(resToken, "file is too short for a force field of resolution " + std::to_string(res) +
                          " (" + std::to_string(nodes) + " nodes)");
  }
  w.field.resolution = res;
  // Allocated as the numbers arrive: from a pipe, whose size is unknown, a resolution of 1024
  // allocated 25 GB before the first number was read.
  w.field.forces.reserve(std::min<std::size_t>(nodes, std::size_t{1} << 16));
  for (std::size_t i = 0; i < nodes; ++i) {
    Vec3 f;
    f.x = in.number("force-field x");
    f.y = in.number("force-field y");
    f.z = in.number("force-field z");
    w.field.forces.push_back(f);
  }
}

// Positions and velocities: their count depends on the cube resolution, which an extension
// given after them may set, so the numbers are collected up to the first keyword, returned.
Token readCubeNumbers(Tokenizer& in, const ReaderLimits& limits, std::vector<double>& values,
                      TokenLog& tokens) {
  values.reserve(6 * 512);
  tokens.reserve(6 * 512);
  // The largest cube the limits allow bounds how many numbers can follow: refused at the first
  // number beyond it, so a file of a billion numbers costs no more memory than that cube.
  const std::size_t largest = static_cast<std::size_t>(limits.maxCubeResolution);
  const std::size_t maxValues = 6 * largest * largest * largest;
  Token t = in.next();
  while (!t.text.empty() && !extension(t.text)) {
    if (values.size() == maxValues) {
      in.fail(t, "more numbers than the positions and velocities of the largest cube allowed (" +
                     std::to_string(largest) + "^3 points: " + std::to_string(maxValues) +
                     " numbers)");
    }
    if (completeCube(values.size()) && !looksNumeric(t.text)) {
      in.fail(t, "unknown trailing content after the velocities (extension keywords: " +
                     extensionKeywords() + ")");
    }
    values.push_back(in.toNumber(t, "a position or velocity"));
    tokens.add(t);
    t = in.next();
  }
  return t;
}

// The cube's positions and velocities from the numbers read, once its resolution is known: as
// many as it has points, each start one the simulation would not call diverged at once.
void assignCube(Tokenizer& in, const std::vector<double>& values, const TokenLog& tokens,
                int lastLine, World& w) {
  const std::size_t points = static_cast<std::size_t>(w.numPoints());
  const std::size_t expected = 6 * points;
  if (values.size() < expected) {
    const bool inPositions = values.size() < 3 * points;
    const std::string block = inPositions ? "positions" : "velocities";
    const std::size_t got = inPositions ? values.size() : values.size() - 3 * points;
    const Token where{{}, 0, tokens.empty() ? lastLine : tokens.back().line};
    in.fail(where, "truncated: " + std::to_string(got / 3) + " of " + std::to_string(points) + " " +
                       block + " (cube resolution " + std::to_string(w.cubeResolution) + ")");
  }
  if (values.size() > expected) {
    in.fail(tokens[expected], "unknown trailing content after the " + std::to_string(points) +
                                  " velocities (cube resolution " +
                                  std::to_string(w.cubeResolution) + ")");
  }
  w.positions.resize(points);
  w.velocities.resize(points);
  for (std::size_t p = 0; p < points; ++p) {
    w.positions[p] = {values[3 * p], values[3 * p + 1], values[3 * p + 2]};
    const std::size_t q = 3 * (points + p);
    w.velocities[p] = {values[q], values[q + 1], values[q + 2]};
  }
  if (const std::optional<PointProblem> bad = positionsProblem(w.positions)) {
    const std::string first = bad->other != bad->point
                                  ? " (point " + std::to_string(bad->other) + " on line " +
                                        std::to_string(tokens[3 * bad->other].line) + ")"
                                  : std::string();
    in.fail(tokens[3 * bad->point], bad->message + first);
  }
  if (const std::optional<PointProblem> bad = velocitiesProblem(w.velocities, w.mass)) {
    in.fail(tokens[3 * (points + bad->point)], bad->message);
  }
}

}  // namespace

std::optional<PointProblem> positionsProblem(const std::vector<Vec3>& positions) {
  const std::size_t points = positions.size();
  for (std::size_t p = 0; p < points; ++p) {
    const Vec3& x = positions[p];
    const double r = std::hypot(x.x, x.y, x.z);
    if (!(r <= kStartBound)) {
      return PointProblem{p, p,
                          "point " + std::to_string(p) + " starts " + metres(r) +
                              " m from the origin (at most " + metres(kStartBound) +
                              " m: the box is [-2,2]^3)"};
    }
  }
  std::vector<std::size_t> order(points);
  for (std::size_t p = 0; p < points; ++p) order[p] = p;
  const auto key = [&](std::size_t p) {
    const Vec3& x = positions[p];
    return std::tuple(x.x, x.y, x.z);
  };
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return key(a) < key(b) || (key(a) == key(b) && a < b);
  });
  for (std::size_t i = 1; i < points; ++i) {
    const std::size_t a = order[i - 1], b = order[i];
    if (key(a) == key(b)) {
      return PointProblem{b, a,
                          "points " + std::to_string(a) + " and " + std::to_string(b) +
                              " start at the same position: the springs between them would "
                              "have no direction"};
    }
  }
  return std::nullopt;
}

std::optional<PointProblem> velocitiesProblem(const std::vector<Vec3>& velocities, double mass) {
  for (std::size_t p = 0; p < velocities.size(); ++p) {
    const Vec3& v = velocities[p];
    if (!std::isfinite(0.5 * mass * (v.x * v.x + v.y * v.y + v.z * v.z))) {
      return PointProblem{
          p, p, "point " + std::to_string(p) + "'s velocity gives it an infinite kinetic energy"};
    }
  }
  return std::nullopt;
}

namespace {

World parseTokens(Tokenizer& in, const ReaderLimits& limits) {
  World w;
  readHeader(in, limits, w);
  readField(in, limits, w);
  std::vector<double> values;
  TokenLog tokens;
  const Token keyword = readCubeNumbers(in, limits, values, tokens);
  readExtensions(in, keyword, w, limits);
  assignCube(in, values, tokens, keyword.line, w);
  return w;
}

}  // namespace

World parseWorld(std::string_view text, const std::string& name, const ReaderLimits& limits) {
  TextSource source(text);
  Tokenizer in(source, name, std::max<std::uintmax_t>(text.size(), 1),
               std::numeric_limits<std::uintmax_t>::max());
  return parseTokens(in, limits);
}

World readWorld(const std::filesystem::path& path, const ReaderLimits& limits) {
  const std::string name = path.string();
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec || !fs::exists(status)) {
    throw WorldFileError(name, 0, name,
                         "cannot open: " + (ec ? ec.message() : std::string("no such file")));
  }
  if (fs::is_directory(status))
    throw WorldFileError(name, 0, name, "is a directory, not a world file");
  if (fs::is_character_file(status) || fs::is_block_file(status) || fs::is_socket(status)) {
    throw WorldFileError(name, 0, name,
                         std::string("is a ") + (fs::is_socket(status) ? "socket" : "device") +
                             ", not a world file (read from a regular file or a pipe)");
  }
  // A regular file too large is refused before anything is read. Pipes, and files such as
  // /proc's whose size reads 0, are read to their end, refused as soon as they pass the limit.
  // Either is read in chunks and never held whole: a file of endless numbers is refused at the
  // first number no allowed cube could hold, in a few megabytes.
  std::uintmax_t size = 0;
  if (fs::is_regular_file(status)) {
    size = fs::file_size(path, ec);
    if (ec) size = 0;
    if (size > limits.maxFileBytes) {
      throw reader::fileTooLarge(name, limits.maxFileBytes);
    }
  }
  // A FIFO no process writes would block the open below forever.
  const FifoReadHold hold(path);
  if (!hold.problem().empty()) throw WorldFileError(name, 0, name, hold.problem());
  std::ifstream file(path, std::ios::binary);
  if (!file) throw WorldFileError(name, 0, name, "cannot open for reading");
  StreamSource source(file, name);
  Tokenizer in(source, name, size, limits.maxFileBytes);
  return parseTokens(in, limits);
}

}  // namespace jello
