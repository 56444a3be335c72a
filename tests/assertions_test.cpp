// The project's checks: JELLO_ASSERT and JELLO_VALIDATE abort with the condition where they are
// on (debug and asan builds), evaluate nothing where they are off (release), and the checks
// placed in the code fire on the errors they guard against.
#include "src/base/assertions.h"

#include <gtest/gtest.h>

#include <limits>
#include <stdexcept>

#include "solvers/simulation.h"
#include "src/base/out_of_memory.h"
#include "src/world/scene_builder.h"
#include "tests/test_support.h"

namespace jello {
namespace {

TEST(Assertions, AbortNamingTheConditionWhenOn) {
  if (!kJelloAssertions) GTEST_SKIP() << "assertions are off in this build";
  EXPECT_DEATH(JELLO_ASSERT(1 + 1 == 3, "arithmetic"),
               "assertion failed: 1 \\+ 1 == 3 \\(arithmetic\\)");
}

// An exception nobody caught (a library's, where no main expected one) is named and ends with
// exit 1, not a silent SIGABRT (jello-work-precision --drift-k 1e308 aborted with 134 and
// printed nothing).
TEST(Assertions, AnUncaughtExceptionIsNamedAndExitsOne) {
  EXPECT_EXIT(
      {
        exitCleanlyWhenOutOfMemory("jello-test");
        try {
          throw std::runtime_error("TridiagEigen: eigen decomposition failed");
        } catch (...) {
          std::terminate();  // what an exception escaping main does
        }
      },
      ::testing::ExitedWithCode(1),
      "jello-test: error: unexpected failure: TridiagEigen: eigen decomposition failed");
}

TEST(Assertions, EvaluateNothingWhenOff) {
  if (kJelloAssertions) GTEST_SKIP() << "assertions are on in this build";
  int calls = 0;
  JELLO_ASSERT(++calls == 1, "never evaluated");
  EXPECT_EQ(calls, 0);
}

TEST(Assertions, AModelWithoutMassIsAProgrammingError) {
  if (!kJelloAssertions) GTEST_SKIP() << "assertions are off in this build";
  ModelSpec spec = test::singleSpring(1.0, 0.0, 1.0, 1.0);
  spec.mass = 0.0;
  EXPECT_DEATH(Model{spec}, "positive mass");
}

// A state that is not finite never reaches an integrator: Simulation keeps the last sane
// state. Handing it one anyway (a world built in code with a NaN) trips the validation where it
// is on, and where it is off the step is refused as a start no step can begin from (its
// energy is not finite: Model::startProblem), the simulation left at step 0.
TEST(Validations, ANonFiniteStateHandedToAStepIsCaught) {
  World w = test::loadWorld("jello.w");
  w.positions[3].x = std::numeric_limits<double>::quiet_NaN();
  Simulation sim(w);
  if (kJelloValidate) {
    EXPECT_DEATH((void)sim.step(), "validation failed.*finite");
  } else {
    const StepResult r = sim.step();
    EXPECT_FALSE(r.ok);
    EXPECT_NE(r.message.find("every term of the energy must be finite"), std::string::npos)
        << r.message;
    EXPECT_EQ(sim.steps(), 0);
  }
}

}  // namespace
}  // namespace jello
