// Spring counts and geometry of the lattice.
#include <gtest/gtest.h>

#include <set>
#include <utility>

#include "src/effects/spring_forces.h"

namespace jello {
namespace {

class LatticeOfSize : public ::testing::TestWithParam<int> {};

TEST_P(LatticeOfSize, SpringCountsMatchTheFormulas) {
  const int n = GetParam();
  const Lattice lat{n};
  const SpringForces springs(latticeSpringGroups(lat, 1.0, 0.0), lat.numPoints());
  std::array<long, kSpringKinds> counted{};
  for (const Spring& s : springs.springs()) ++counted[static_cast<int>(s.kind)];
  EXPECT_EQ(counted, springCountFormula(n));
  long total = 0;
  for (long c : springCountFormula(n)) total += c;
  EXPECT_EQ(springs.numSprings(), total);
}

TEST_P(LatticeOfSize, EachPairIsOneSpringOfTheRightKindAndRestLength) {
  const int n = GetParam();
  const Lattice lat{n};
  const SpringForces springs(latticeSpringGroups(lat, 1.0, 0.0), lat.numPoints());
  std::set<std::pair<int, int>> pairs;
  for (const Spring& s : springs.springs()) {
    const int ia = s.a / (n * n), ja = s.a / n % n, ka = s.a % n;
    const int ib = s.b / (n * n), jb = s.b / n % n, kb = s.b % n;
    const int di = std::abs(ib - ia), dj = std::abs(jb - ja), dk = std::abs(kb - ka);
    const int sq = di * di + dj * dj + dk * dk;
    const SpringKind expected = sq == 1   ? SpringKind::Structural
                                : sq == 2 ? SpringKind::FaceShear
                                : sq == 3 ? SpringKind::BodyShear
                                          : SpringKind::Bend;
    EXPECT_TRUE(sq <= 3 || (sq == 4 && (di == 2 || dj == 2 || dk == 2))) << s.a << "-" << s.b;
    EXPECT_EQ(s.kind, expected);
    EXPECT_DOUBLE_EQ(s.rest, std::sqrt(double(sq)) / (n - 1));
    EXPECT_TRUE(pairs.insert({std::min(s.a, s.b), std::max(s.a, s.b)}).second) << "twice";
  }
}

INSTANTIATE_TEST_SUITE_P(N, LatticeOfSize, ::testing::Values(2, 3, 8, 16));

TEST(Lattice, EightCubedHasThe6220SpringsOfTheAssignment) {
  EXPECT_EQ(springCountFormula(8), (std::array<long, 4>{1344, 2352, 1372, 1152}));
}

}  // namespace
}  // namespace jello
