// The writer: exact round trips, the original creator's format, extensions, atomic replace.
#include "src/world_writer.h"

#include <gtest/gtest.h>

#include <cstring>
#include <limits>
#include <random>

#include "src/atomic_file.h"
#include "src/scene_builder.h"
#include "src/world_reader.h"
#include "tests/test_support.h"

namespace jello {
namespace {

bool sameBits(double a, double b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

void expectSameBits(const Vec3& a, const Vec3& b) {
  EXPECT_TRUE(sameBits(a.x, b.x) && sameBits(a.y, b.y) && sameBits(a.z, b.z));
}

TEST(WorldWriter, RoundTripsEveryDoubleBitExactly) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> any(-2.0, 2.0);
  SceneSpec spec;
  spec.fieldResolution = 3;
  spec.sphere = Sphere{{0.1, 0.2, 0.3}, 0.4};
  World w = buildWorld(spec);
  w.dt = std::nextafter(1e-3, 1.0);
  w.mass = 1.0 / 3.0;
  w.kElastic = std::numeric_limits<double>::denorm_min();
  w.dCollision = std::numeric_limits<double>::max();
  for (Vec3& x : w.positions) x = {any(rng), any(rng) * 1e-300, any(rng) * 1e300};
  for (Vec3& v : w.velocities) v = {any(rng) / 3, any(rng) / 7, -0.0};
  for (Vec3& f : w.field.forces) f = {any(rng), any(rng), any(rng)};

  const World r = parseWorld(formatWorld(w), "roundtrip");
  EXPECT_TRUE(sameBits(r.dt, w.dt));
  EXPECT_TRUE(sameBits(r.mass, w.mass));
  EXPECT_TRUE(sameBits(r.kElastic, w.kElastic));
  EXPECT_TRUE(sameBits(r.dCollision, w.dCollision));
  ASSERT_EQ(r.positions.size(), w.positions.size());
  for (std::size_t p = 0; p < w.positions.size(); ++p) {
    expectSameBits(r.positions[p], w.positions[p]);
    expectSameBits(r.velocities[p], w.velocities[p]);
  }
  for (std::size_t i = 0; i < w.field.forces.size(); ++i) {
    expectSameBits(r.field.forces[i], w.field.forces[i]);
  }
  ASSERT_TRUE(r.sphere.has_value());
  expectSameBits(r.sphere->center, w.sphere->center);
  EXPECT_EQ(formatWorld(r), formatWorld(w));
}

TEST(WorldWriter, LegacyFormatOfTheDefaultSceneIsTheOriginalCreatorsFile) {
  const std::string expected = test::readFile(test::worldsDir() / "createWorld-default.w");
  EXPECT_EQ(formatWorld(buildWorld(SceneSpec{}), NumberFormat::Legacy), expected);
}

TEST(WorldWriter, ReproducesAReferenceWorldOnEveryLineButTheHandEditedOne) {
  // rotate.w is printed exactly as the original %lf writer would print it.
  const World w = test::loadWorld("rotate.w");
  EXPECT_EQ(formatWorld(w, NumberFormat::Legacy), test::readFile(test::worldsDir() / "rotate.w"));
}

TEST(WorldWriter, WritesNoExtensionBlockForAnOriginalScene) {
  const std::string text = formatWorld(test::loadWorld("jello.w"));
  EXPECT_EQ(text.find("cube"), std::string::npos);
  EXPECT_EQ(text.find("sphere"), std::string::npos);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 7 + 27000 + 1024);
}

TEST(WorldWriter, ExtensionsRoundTrip) {
  SceneSpec spec;
  spec.cubeResolution = 5;
  spec.sphere = Sphere{{0.0, 0.0, -1.0}, 0.5};
  spec.plane.reset();
  spec.fieldResolution = 0;
  const World w = buildWorld(spec);
  const World r = parseWorld(formatWorld(w), "ext");
  EXPECT_EQ(r.cubeResolution, 5);
  EXPECT_EQ(r.positions.size(), 125u);
  ASSERT_TRUE(r.sphere.has_value());
  EXPECT_EQ(r.sphere->radius, 0.5);
  EXPECT_FALSE(r.plane.has_value());
  EXPECT_TRUE(r.field.empty());
}

TEST(AtomicFile, ReplacesTheFileAndLeavesNoTemporary) {
  test::TempDir dir;
  const auto path = dir.path() / "w.w";
  writeFileAtomically(path, "old");
  writeFileAtomically(path, "new");
  EXPECT_EQ(test::readFile(path), "new");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()),
                          std::filesystem::directory_iterator{}),
            1);
}

TEST(AtomicFile, FailsWithThePathWhenTheDirectoryIsMissing) {
  test::TempDir dir;
  const auto path = dir.path() / "missing" / "w.w";
  try {
    writeFileAtomically(path, "x");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
}

TEST(AtomicFile, KeepsThePreviousFileWhenTheTargetCannotBeReplaced) {
  test::TempDir dir;
  const auto path = dir.path() / "w.w";
  writeFileAtomically(path, "previous");
  // A directory in the way of the rename: the write fails after the temporary was written.
  const auto blocked = dir.path() / "blocked";
  std::filesystem::create_directories(blocked / "inner");
  EXPECT_THROW(writeFileAtomically(blocked, "new"), std::runtime_error);
  EXPECT_EQ(test::readFile(path), "previous");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()),
                          std::filesystem::directory_iterator{}),
            2);  // w.w and blocked/, no temporary left behind
}

}  // namespace
}  // namespace jello
