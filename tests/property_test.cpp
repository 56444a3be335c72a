// Properties over randomly generated worlds. Ranges of the generated valid worlds:
//   cube resolution 2..5, integrator any, dt 1e-5..1e-2 s, n 1..10, spring and contact
//   constants 0..1e4, mass 1e-4..1 kg, plane (half of them) with a random non-zero normal and
//   d in -3..3, field (half) of resolution 2..5 with forces in -1..1 N, sphere (a third) with
//   centre in the box and radius 0.1..1 m, positions in -2..2 m, velocities in -50..50 m/s.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <sstream>

#include "solvers/simulation.h"
#include "src/world/scene_builder.h"
#include "src/world/world_reader.h"
#include "src/world/world_writer.h"
#include "tests/test_support.h"

namespace jello {
namespace {

class RandomWorlds {
 public:
  explicit RandomWorlds(unsigned seed) : rng_(seed) {}

  double uniform(double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng_);
  }
  double logUniform(double lo, double hi) { return std::exp(uniform(std::log(lo), std::log(hi))); }
  int integer(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }
  Vec3 vec(double lo, double hi) { return {uniform(lo, hi), uniform(lo, hi), uniform(lo, hi)}; }

  World next() {
    World w;
    const auto kinds = allIntegrators();
    w.integrator = kinds[static_cast<std::size_t>(integer(0, int(kinds.size()) - 1))];
    w.dt = logUniform(1e-5, 1e-2);
    w.stepsPerFrame = integer(1, 10);
    w.kElastic = uniform(0, 1e4);
    w.dElastic = uniform(0, 1e4);
    w.kCollision = uniform(0, 1e4);
    w.dCollision = uniform(0, 1e4);
    w.mass = logUniform(1e-4, 1.0);
    if (integer(0, 1)) {
      Vec3 normal;
      do normal = vec(-1, 1);
      while (normal == Vec3{});
      w.plane = Plane{normal.x, normal.y, normal.z, uniform(-3, 3)};
    }
    if (integer(0, 1)) {
      w.field.resolution = integer(2, 5);
      const int r = w.field.resolution;
      for (int i = 0; i < r * r * r; ++i) w.field.forces.push_back(vec(-1, 1));
    }
    if (integer(0, 2) == 0) w.sphere = Sphere{vec(-2, 2), uniform(0.1, 1.0)};
    w.cubeResolution = integer(2, 5);
    for (int p = 0; p < w.numPoints(); ++p) {
      w.positions.push_back(vec(-2, 2));
      w.velocities.push_back(vec(-50, 50));
    }
    return w;
  }

 private:
  std::mt19937_64 rng_;
};

TEST(RandomWorlds, WriteAndReadBackBitExactly) {
  RandomWorlds gen(2026);
  for (int i = 0; i < 300; ++i) {
    const World w = gen.next();
    const std::string text = formatWorld(w);
    const World r = parseWorld(text, "random");
    // %.17g is one-to-one on doubles (it keeps -0), so equal text means equal bits.
    ASSERT_EQ(formatWorld(r), text) << "world " << i;
    EXPECT_EQ(r.integrator, w.integrator);
    EXPECT_EQ(r.cubeResolution, w.cubeResolution);
    EXPECT_EQ(r.sphere.has_value(), w.sphere.has_value());
  }
}

TEST(RandomWorlds, AnyNonFiniteNumberIsRefused) {
  RandomWorlds gen(7);
  const char* bad[] = {"nan", "-nan", "NaN", "inf", "-inf", "INF", "infinity", "1e400", "-1e999"};
  for (int i = 0; i < 200; ++i) {
    const std::string text = formatWorld(gen.next());
    // Replace one numeric token, chosen at random, after the integrator name.
    std::istringstream in(text);
    std::vector<std::string> tokens;
    for (std::string t; in >> t;) tokens.push_back(t);
    std::size_t at;
    // A real-valued field: digits and a point or exponent (integer fields such as n, the
    // plane flag and resolutions are written without either).
    auto isReal = [](const std::string& t) {
      return t.find_first_of("0123456789") != std::string::npos &&
             t.find_first_of(".e") != std::string::npos;
    };
    do at = static_cast<std::size_t>(gen.integer(1, int(tokens.size()) - 1));
    while (!isReal(tokens[at]));
    const std::string replacement = bad[gen.integer(0, 8)];
    tokens[at] = replacement;
    std::string mutated;
    for (const std::string& t : tokens) mutated += t + "\n";
    try {
      (void)parseWorld(mutated, "mutated");
      FAIL() << "accepted " << replacement << " at token " << at;
    } catch (const WorldFileError& e) {
      EXPECT_EQ(e.token(), replacement) << e.what();
    }
  }
}

TEST(RandomWorlds, ASimulationNeverLeavesANonFiniteStateUnreported) {
  RandomWorlds gen(99);
  int diverged = 0, runs = 0;
  const int worlds = test::kSanitized ? 24 : 60;  // 100 s under the sanitizers for 60
  for (int i = 0; i < worlds; ++i) {
    World w = gen.next();
    w.cubeResolution = 3;
    w.positions.resize(27);
    w.velocities.resize(27);
    const IntegratorKind kinds[] = {IntegratorKind::Euler, IntegratorKind::Symplectic,
                                    IntegratorKind::RK4, IntegratorKind::Implicit};
    Simulation sim(w, kinds[i % 4], gen.logUniform(1e-5, 5e-2));
    ++runs;
    for (int step = 0; step < 40; ++step) {
      const StepResult r = sim.step();
      ASSERT_TRUE(sim.state().x.allFinite() && sim.state().v.allFinite()) << "world " << i;
      if (!r.ok) {
        ASSERT_TRUE(sim.divergence().has_value());
        ++diverged;
        break;
      }
    }
  }
  // Wild random worlds: many blow up, and every one of those was reported.
  EXPECT_GT(diverged, 0);
  EXPECT_LT(diverged, runs);
}

}  // namespace
}  // namespace jello
