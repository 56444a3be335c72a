#include "experiments/studies/reference_file.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "src/base/atomic_file.h"
#include "src/world/world_reader.h"

namespace jello::experiments {

namespace {

std::string exact(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", v);
  return buffer;
}

// The file's lines, comments and blank lines skipped, read token by token with the line's
// number for the messages.
class Lines {
 public:
  explicit Lines(const std::filesystem::path& file) : file_(file), in_(file) {
    if (!in_) throw std::runtime_error(file.string() + ": cannot be read");
  }

  // The next line's tokens; false at the end of the file.
  bool next() {
    std::string line;
    while (std::getline(in_, line)) {
      ++number_;
      std::istringstream words(line);
      tokens_.clear();
      for (std::string t; words >> t;) tokens_.push_back(t);
      if (!tokens_.empty() && tokens_[0][0] != '#') return true;
    }
    if (in_.bad()) fail("a read error");
    return false;
  }

  // The next line, which must be `count` tokens, the first `name` when given.
  void expect(std::size_t count, const std::string& name = "") {
    if (!next()) fail("the file ends early" + (name.empty() ? "" : ", before '" + name + "'"));
    if (!name.empty() && tokens_[0] != name) {
      fail(quoted(0) + " where '" + name + "' was expected");
    }
    if (tokens_.size() != count) {
      fail(std::to_string(tokens_.size()) + " tokens where " + std::to_string(count) +
           " were expected");
    }
  }

  std::size_t size() const { return tokens_.size(); }
  const std::string& token(std::size_t i) const { return tokens_[i]; }
  // Token i as a message quotes it, 'TOKEN' (no terminal escapes: src/world/world_reader.h).
  std::string quoted(std::size_t i) const { return quote(tokens_[i]); }
  static std::string quote(const std::string& token) {
    std::string q(1, '\'');
    q.append(displayToken(token)).push_back('\'');
    return q;
  }

  double number(std::size_t i) const {
    const std::string& t = tokens_[i];
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(t.c_str(), &end);
    if (end == t.c_str() || *end != '\0' || errno == ERANGE || !std::isfinite(v)) {
      fail(quote(t) + " is not a finite number");
    }
    return v;
  }

  long count(std::size_t i, long most) const {
    const double v = number(i);
    if (v < 0.0 || v > double(most) || v != std::floor(v)) {
      fail(quoted(i) + " is not a count from 0 to " + std::to_string(most));
    }
    return long(v);
  }

  [[noreturn]] void fail(const std::string& what) const {
    throw std::runtime_error(displayToken(file_.string(), file_.string().size(), true) + ":" +
                             std::to_string(number_) + ": " + what);
  }

 private:
  std::filesystem::path file_;
  std::ifstream in_;
  int number_ = 0;
  std::vector<std::string> tokens_;
};

}  // namespace

std::string TrajectoryKey::fileName() const {
  char buffer[128];
  std::snprintf(buffer, sizeof buffer, "reference_%s_n%d_k%g_dt%.6g.txt", scene.c_str(), n, k, dt);
  return buffer;
}

std::optional<StoredTrajectory> readTrajectory(const std::filesystem::path& file,
                                               const TrajectoryKey& key) {
  std::error_code error;
  if (!std::filesystem::exists(file, error)) {
    if (error) throw std::runtime_error(file.string() + ": " + error.message());
    return std::nullopt;
  }
  // A FIFO (or device) in its place would block the read, or never end: a reference is a file.
  if (!std::filesystem::is_regular_file(file, error)) {
    throw std::runtime_error(file.string() +
                             ": not a regular file (a reference trajectory is "
                             "one that jello-scaling wrote)");
  }
  Lines lines(file);
  lines.expect(2, "scene");
  if (lines.token(1) != key.scene) {
    lines.fail("made for the scene " + lines.quoted(1) + ", not '" + key.scene + "'");
  }
  const auto same = [&](const char* name, double wanted) {
    lines.expect(2, name);
    if (lines.number(1) != wanted) {
      lines.fail(std::string("made for ") + name + " = " + displayToken(lines.token(1)) + ", not " +
                 exact(wanted));
    }
  };
  same("k_N_per_m", key.k);
  same("n", key.n);
  same("dt_s", key.dt);
  same("interval_s", key.interval);
  same("time_s", key.time);
  const long samples = std::lround(key.time / key.interval) + 1;
  lines.expect(2, "fits");
  StoredTrajectory stored;
  stored.fits.resize(std::size_t(lines.count(1, samples)));
  if (stored.fits.empty()) lines.fail("no fits (the one at t = 0 comes first)");
  for (AffineFit& f : stored.fits) {
    lines.expect(12);
    for (int i = 0; i < 12; ++i) f(i % 3, i / 3) = lines.number(std::size_t(i));
  }
  if (!lines.next()) lines.fail("the file ends early, before 'end'");
  if (lines.token(0) == "state") {
    const long points = long(key.n) * key.n * key.n;
    if (lines.size() != 3) lines.fail("'state' takes the time and the number of points");
    if (lines.number(2) != double(points)) {
      lines.fail("a state of " + displayToken(lines.token(2)) + " points, not " +
                 std::to_string(points));
    }
    State s;
    s.t = lines.number(1);
    s.x.resize(3 * points);
    s.v.resize(3 * points);
    for (long p = 0; p < points; ++p) {
      lines.expect(6);
      State::set(s.x, int(p), {lines.number(0), lines.number(1), lines.number(2)});
      State::set(s.v, int(p), {lines.number(3), lines.number(4), lines.number(5)});
    }
    const double expected = double(stored.fits.size() - 1) * key.interval;
    if (std::abs(s.t - expected) > 0.5 * key.dt) {
      lines.fail("the state at t = " + exact(s.t) +
                 " s is not that of the last fit (t = " + exact(expected) + " s)");
    }
    stored.resume = std::move(s);
    if (!lines.next()) lines.fail("the file ends early, before 'end'");
  } else if (long(stored.fits.size()) != samples) {
    lines.fail("unfinished (" + std::to_string(stored.fits.size()) + " of " +
               std::to_string(samples) + " fits) and without the state to resume from");
  }
  if (lines.token(0) != "end") lines.fail(lines.quoted(0) + " where 'end' was expected");
  if (lines.next()) lines.fail(lines.quoted(0) + " after 'end'");
  return stored;
}

void writeTrajectory(const std::filesystem::path& file, const TrajectoryKey& key,
                     const std::vector<AffineFit>& fits, const State* resume) {
  std::string text =
      "# jello-scaling's atlas: the visible motion of an RK4 reference (" +
      std::string(resume ? "unfinished, with the state it resumes from" : "finished") + ")\n";
  text += "scene " + key.scene + "\nk_N_per_m " + exact(key.k) + "\nn " + std::to_string(key.n) +
          "\ndt_s " + exact(key.dt) + "\ninterval_s " + exact(key.interval) + "\ntime_s " +
          exact(key.time) + "\nfits " + std::to_string(fits.size()) + "\n";
  for (const AffineFit& f : fits) {
    for (int i = 0; i < 12; ++i) text += exact(f(i % 3, i / 3)) + (i == 11 ? "\n" : " ");
  }
  if (resume) {
    const int points = resume->numPoints();
    text += "state " + exact(resume->t) + " " + std::to_string(points) + "\n";
    for (int p = 0; p < points; ++p) {
      const Vec3 x = resume->position(p), v = resume->velocity(p);
      for (double value : {x.x, x.y, x.z, v.x, v.y, v.z}) text += exact(value) + " ";
      text.back() = '\n';
    }
  }
  text += "end\n";
  writeFileAtomically(file, text);
}

}  // namespace jello::experiments
