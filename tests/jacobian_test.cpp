// Assembled Jacobians against central differences of the forces, effect by effect.
#include "solvers/system/jacobian.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <random>
#include <utility>

#include "solvers/system/implicit_system.h"
#include "solvers/system/system_operator.h"
#include "src/base/parallel.h"
#include "src/world/scene_builder.h"
#include "tests/test_support.h"

namespace jello {
namespace {

// Central differences of the model's total force with respect to x (wrtV = false) or v.
Eigen::MatrixXd finiteDifferences(const Model& model, const State& s, bool wrtV) {
  const Eigen::Index n3 = s.x.size();
  Eigen::MatrixXd J(n3, n3);
  Eigen::VectorXd fp, fm;
  const double h = 1e-6;
  for (Eigen::Index j = 0; j < n3; ++j) {
    State plus = s, minus = s;
    (wrtV ? plus.v : plus.x)[j] += h;
    (wrtV ? minus.v : minus.x)[j] -= h;
    model.forces(plus.x, plus.v, fp);
    model.forces(minus.x, minus.v, fm);
    J.col(j) = (fp - fm) / (2 * h);
  }
  return J;
}

double relativeError(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff();
}

struct Assembled {
  Eigen::MatrixXd K, D;
  long clamps;
};

Assembled assemble(const Model& model, const State& s, JacobianOptions options) {
  JacobianAssembler jac(model);
  jac.assemble(s.x.data(), options);
  return {Eigen::MatrixXd(jac.K()), Eigen::MatrixXd(jac.D()), jac.lastClampCount()};
}

// Two points on one spring of rest length 0.3, at the given length, moving apart and sideways.
State twoPoints(double length) {
  State s;
  s.x.setZero(6);
  s.v.setZero(6);
  State::set(s.x, 0, {0.1, -0.2, 0.05});
  State::set(s.x, 1,
             Vec3{0.1, -0.2, 0.05} + Vec3{0.6, 0.3, -0.2} * (length / norm({0.6, 0.3, -0.2})));
  State::set(s.v, 0, {1.0, 0.0, 0.5});
  State::set(s.v, 1, {-0.5, 2.0, 0.0});
  return s;
}

TEST(SpringJacobian, MatchesFiniteDifferencesWhenStretched) {
  const Model model(test::singleSpring(200.0, 0.0, 0.3, 0.01));
  const State s = twoPoints(0.45);
  const Assembled a = assemble(model, s, {});
  EXPECT_EQ(a.clamps, 0);
  EXPECT_LT(relativeError(a.K, finiteDifferences(model, s, false)), 1e-6);
}

TEST(SpringJacobian, MatchesFiniteDifferencesWhenCompressedWithoutTheClamp) {
  const Model model(test::singleSpring(200.0, 0.0, 0.3, 0.01));
  const State s = twoPoints(0.2);
  const Assembled a = assemble(model, s, {.clampCompression = false});
  EXPECT_LT(relativeError(a.K, finiteDifferences(model, s, false)), 1e-6);
  // Unclamped, the element Hessian -K has a negative direction (across the spring).
  EXPECT_LT(test::symmetricEigenvalues(-a.K).minCoeff(), -1.0);
}

TEST(SpringJacobian, ClampedUnderCompressionIsSemidefiniteAndCounted) {
  const Model model(test::singleSpring(200.0, 0.0, 0.3, 0.01));
  const State s = twoPoints(0.2);
  const Assembled a = assemble(model, s, {});
  EXPECT_EQ(a.clamps, 1);
  const Eigen::VectorXd eig = test::symmetricEigenvalues(-a.K);
  EXPECT_GT(eig.minCoeff(), -1e-12);
  EXPECT_NEAR(eig.maxCoeff(), 2 * 200.0, 1e-9);  // along the spring: 2k for the pair
}

TEST(SpringDampingJacobian, MatchesFiniteDifferencesInVelocity) {
  const Model model(test::singleSpring(200.0, 0.7, 0.3, 0.01));
  const State s = twoPoints(0.4);
  EXPECT_LT(relativeError(assemble(model, s, {}).D, finiteDifferences(model, s, true)), 1e-6);
}

// One point, no springs, with the given effects.
ModelSpec onePoint(bool walls) {
  ModelSpec spec;
  spec.numPoints = 1;
  spec.mass = 0.01;
  spec.walls = walls;
  spec.contact = {1000.0, 0.3};
  return spec;
}

State at(const Vec3& x, const Vec3& v = {0.3, -0.2, 0.1}) {
  return test::pointAt(x, v);
}

TEST(ContactJacobian, MatchesFiniteDifferencesAtEachWall) {
  const Model model(onePoint(true));
  for (int axis = 0; axis < 3; ++axis) {
    for (double side : {-1.0, 1.0}) {
      double c[3] = {0.3, -0.4, 0.5};
      c[axis] = side * 2.05;
      const State s = at({c[0], c[1], c[2]});
      const Assembled a = assemble(model, s, {});
      EXPECT_LT(relativeError(a.K, finiteDifferences(model, s, false)), 1e-6);
      EXPECT_LT(relativeError(a.D, finiteDifferences(model, s, true)), 1e-6);
    }
  }
  const State corner = at({2.1, -2.05, 2.2});
  EXPECT_LT(relativeError(assemble(model, corner, {}).K, finiteDifferences(model, corner, false)),
            1e-6);
}

TEST(ContactJacobian, MatchesFiniteDifferencesBelowThePlane) {
  ModelSpec spec = onePoint(false);
  spec.plane = Plane{-1, 1, 2, 6};  // gravity.w's
  const Model model(spec);
  const State s = at({0.5, -1.0, -2.4});  // -0.5 - 1 - 4.8 + 6 < 0
  const Assembled a = assemble(model, s, {});
  EXPECT_LT(relativeError(a.K, finiteDifferences(model, s, false)), 1e-6);
  EXPECT_LT(relativeError(a.D, finiteDifferences(model, s, true)), 1e-6);
}

TEST(ContactJacobian, MatchesFiniteDifferencesInsideTheSphere) {
  ModelSpec spec = onePoint(false);
  spec.sphere = Sphere{{0.0, 0.0, -1.0}, 0.6};
  const Model model(spec);
  const State s = at({0.2, -0.1, -0.6}, {0, 0, 0});  // the damping's x-term is omitted
  const Assembled exact = assemble(model, s, {.clampCompression = false});
  EXPECT_LT(relativeError(exact.K, finiteDifferences(model, s, false)), 1e-6);
  // Clamped, the curvature term is dropped and -K is semidefinite.
  const Assembled clamped = assemble(model, s, {});
  EXPECT_GT(test::symmetricEigenvalues(-clamped.K).minCoeff(), -1e-12);
  // The damping's v-derivative -dc n n^T, moving obliquely into the sphere.
  const State moving = at({0.2, -0.1, -0.6}, {0.7, -0.4, -1.1});
  EXPECT_LT(relativeError(assemble(model, moving, {}).D, finiteDifferences(model, moving, true)),
            1e-6);
}

TEST(FieldJacobian, MatchesFiniteDifferencesInsideACell) {
  ModelSpec spec = onePoint(false);
  SceneSpec scene;
  scene.fieldResolution = 5;
  World bumpy = buildWorld(scene);
  for (int i = 0; i < 125; ++i) {
    bumpy.field.forces[i] = {std::sin(i * 0.7), std::cos(i * 1.3), 0.1 * i};
  }
  spec.field = bumpy.field;
  const Model model(spec);
  const State s = at({0.3, -0.7, 1.2});
  const Assembled a = assemble(model, s, {.includeField = true});
  EXPECT_LT(relativeError(a.K, finiteDifferences(model, s, false)), 1e-6);
  EXPECT_EQ(assemble(model, s, {}).K.cwiseAbs().maxCoeff(), 0.0);  // off by default
}

// jello.w deformed at random, some points through the walls and the plane, moving.
State deformedJello(const World& w) {
  State s = initialState(w);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.04, 0.04);
  for (Eigen::Index i = 0; i < s.x.size(); ++i) s.x[i] += u(rng);
  for (Eigen::Index i = 0; i < s.v.size(); ++i) s.v[i] = 50 * u(rng);
  const int n = s.numPoints();
  s.x[0] = -2.1;          // point 0 through the x = -2 wall
  s.x[2 * n + 7] = 2.15;  // point 7 through the top
  s.x[n + 300] = -1.0;    // point 300 (x near 0.7, z near 0.4) below the plane -x+y+z+2=0
  s.x[2 * n + 300] = -1.5;
  return s;
}

TEST(AssembledJacobian, MatchesFiniteDifferencesOnADeformedMovingJello) {
  World w = test::loadWorld("jello.w");
  const State s = deformedJello(w);
  // D against the full model (forces are linear in v).
  const Model damped(w);
  EXPECT_LT(relativeError(assemble(damped, s, {}).D, finiteDifferences(damped, s, true)), 1e-6);
  // K against a model without damping: the damping's x-derivative is omitted by design.
  w.dElastic = w.dCollision = 0.0;
  const Model model(w);
  const Assembled a = assemble(model, s, {.clampCompression = false});
  EXPECT_LT(relativeError(a.K, finiteDifferences(model, s, false)), 1e-6);
  // K is symmetric without the field.
  EXPECT_LT((a.K - a.K.transpose()).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(AssembledJacobian, ClampedSystemIsPositiveDefiniteForAnyStep) {
  World w = test::loadWorld("jello.w");
  w.kElastic = 1e5;
  State s = deformedJello(w);
  s.x *= 0.6;  // compress every spring
  const Model model(w);
  JacobianAssembler jac(model);
  jac.assemble(s.x.data(), {});
  EXPECT_GT(jac.lastClampCount(), 1000);
  SparseMatrix A = jac.pattern();
  jac.combine(0.05, 0.05 * 0.05, A);
  EXPECT_TRUE(test::choleskySucceeds(Eigen::MatrixXd(A)));
}

// One system of the test below: A against K and D, a solve, v^T D v, and bind's answers.
void solvesTheScaledJacobians(ImplicitSystem& system, const Model& model, const Model& other,
                              const State& s) {
  EXPECT_TRUE(system.bind(model));
  EXPECT_FALSE(system.bind(model));
  system.assemble(s.x.data(), s.v.data());
  const double a = 0.02, b = 4e-4;
  ASSERT_TRUE(system.factorize(a, b).ok);
  const double quadratic = system.dampingQuadratic(s.v);  // before D is formed
  const Eigen::Index n3 = s.x.size();
  const Eigen::MatrixXd A = model.mass() * Eigen::MatrixXd::Identity(n3, n3) -
                            a * Eigen::MatrixXd(system.D()) - b * Eigen::MatrixXd(system.K());
  EXPECT_LT((Eigen::MatrixXd(system.A()) - A).cwiseAbs().maxCoeff(), 1e-12 * A.norm());
  const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(n3, -1.0, 2.0);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n3);
  ASSERT_TRUE(system.solve(rhs, x).ok);
  EXPECT_LT((A * x - rhs).norm(), 1e-10 * rhs.norm());
  const Eigen::VectorXd Dv = system.D() * s.v;
  EXPECT_NEAR(quadratic, s.v.dot(Dv), 1e-12 * std::abs(s.v.dot(Dv)));
  EXPECT_TRUE(system.bind(other));  // another model, even one built from the same world
}

// The shared implicit system solves M - a D - b K (M = m I) at the assembled state: the solution
// checked against a dense matrix built from K and D by the test, and binding reports a new
// model once.
TEST(ImplicitSystem, SolvesTheMassMinusScaledJacobiansAtTheAssembledState) {
  World w = test::loadWorld("jello.w");
  w.kElastic = 1e4;
  const State s = deformedJello(w);
  const Model model(w), other(w);
  std::vector<LinearSolverOptions> solvers = {{LinearSolverKind::Cholmod, 1e-10},
                                              {LinearSolverKind::Ldlt, 1e-10}};
  // CG with every preconditioner, matrix-free and through the sparse matrix: the same solution.
  for (PreconditionerKind pre : {PreconditionerKind::Jacobi, PreconditionerKind::BlockJacobi,
                                 PreconditionerKind::IncompleteCholesky, PreconditionerKind::Factor,
                                 PreconditionerKind::Projective}) {
    for (bool matrixFree : {true, false}) {
      solvers.push_back({LinearSolverKind::Cg, 1e-11, pre, matrixFree});
    }
  }
  // Each also with the operator filled straight from the springs (where it applies: matrix-free
  // CG, jacobi, block-jacobi, projective), K, D and A then formed only when asked for below.
  for (const LinearSolverOptions& options : solvers) {
    for (bool direct : {false, true}) {
      SCOPED_TRACE(std::string(linearSolverName(options.kind)) + " " +
                   std::string(preconditionerName(options.preconditioner)) +
                   (options.matrixFree ? " matrix-free" : " csr") + (direct ? ", direct" : ""));
      ImplicitSystem system(options, true, direct);
      EXPECT_EQ(system.fillsDirectly(), direct && options.kind == LinearSolverKind::Cg &&
                                            options.matrixFree &&
                                            !preconditionerNeedsMatrix(options.preconditioner));
      solvesTheScaledJacobians(system, model, other, s);
    }
  }
}

// Filled straight from the springs, the operator holds the assembled matrix's values: its
// product, diagonal blocks and clamp count on the sinking jello (springs compressed and stretched,
// contact on the diagonal), with the clamp and without.
TEST(SystemOperator, FilledFromTheSpringsEqualsTheAssembledMatrix) {
  World w = test::loadWorld("jello.w");
  State s = deformedJello(w);
  s.x.tail(s.numPoints()).array() -= 2.3;
  s.x.head(2 * s.numPoints()) *= 0.8;  // some springs compressed
  const Model model(w);
  for (bool clamp : {true, false}) {
    SCOPED_TRACE(clamp ? "clamped" : "unclamped");
    JacobianAssembler full(model), others(model);
    full.assemble(s.x.data(), {.clampCompression = clamp, .velocities = s.v.data()});
    others.assemble(s.x.data(),
                    {.clampCompression = clamp, .velocities = s.v.data(), .includeSprings = false});
    SparseMatrix A = full.pattern();
    const double a = 0.01, b = 1e-4;
    full.combine(a, b, A);
    SystemOperator gathered(model.springs(), model.numPoints()),
        filled(model.springs(), model.numPoints());
    gathered.gather(A, full.diagonalSlots(), full.springSlots());
    const long clamps = filled.fill(s.x.data(), model.mass(), a, b, clamp,
                                    others.diagonalK().data(), others.diagonalD().data());
    EXPECT_EQ(clamps, full.lastClampCount());
    if (clamp) {
      EXPECT_GT(clamps, 100);
    }
    const Eigen::VectorXd p = Eigen::VectorXd::Random(s.x.size());
    Eigen::VectorXd y(p.size());
    filled.apply(p.data(), y.data());
    const Eigen::VectorXd expected = A * p;
    EXPECT_LT((y - expected).cwiseAbs().maxCoeff(), 1e-12 * expected.cwiseAbs().maxCoeff());
    for (int e = 0; e < 6; ++e) {
      for (int q = 0; q < model.numPoints(); ++q) {
        EXPECT_NEAR(filled.diagonalBlocks()[e][q], gathered.diagonalBlocks()[e][q],
                    1e-12 * model.mass() * 1e3);
      }
    }
    // The springs' part of v^T D v, with the other effects' diagonal blocks added by the caller.
    const Eigen::VectorXd Dv = full.D() * s.v;
    double quadratic = filled.springDampingQuadratic(s.x.data(), s.v.data());
    const std::ptrdiff_t n = model.numPoints();
    for (std::ptrdiff_t q = 0; q < n; ++q)
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
          quadratic += s.v[r * n + q] * others.diagonalD()[9 * q + 3 * r + c] * s.v[c * n + q];
    EXPECT_NEAR(quadratic, s.v.dot(Dv), 1e-12 * std::abs(s.v.dot(Dv)));
  }
}

// Without the clamp the matrix of a compressed stiff jello is indefinite: CG meets a negative
// curvature, and the directly filled system falls back to LDLT of A, formed then, as the
// gathered one does inside its solver.
TEST(ImplicitSystem, DirectlyFilledFallsBackToLdltWhereTheMatrixIsIndefinite) {
  World w = test::loadWorld("jello.w");
  w.kElastic = 1e5;
  State s = deformedJello(w);
  s.x *= 0.9;
  const Model model(w);
  ImplicitSystem system({LinearSolverKind::Cg, 1e-10, PreconditionerKind::Projective}, false, true);
  ASSERT_TRUE(system.fillsDirectly());
  system.bind(model);
  system.assemble(s.x.data(), s.v.data());
  const double a = 0.01, b = 0.01 * 0.01;
  ASSERT_TRUE(system.factorize(a, b).ok);
  const Eigen::Index n3 = s.x.size();
  const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(n3, -1.0, 2.0);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n3);
  const StepResult solved = system.solve(rhs, x);
  ASSERT_TRUE(solved.ok) << solved.message;
  EXPECT_EQ(system.solver().stats().fallbacks, 1);
  const SparseMatrix& A = system.A();
  EXPECT_FALSE(test::choleskySucceeds(Eigen::MatrixXd(A)));
  EXPECT_LT((A * x - rhs).norm(), 1e-8 * rhs.norm());
}

// A deformed world whose lower layers sink into the floor (springs under every orientation,
// contact blocks on the diagonal): backward Euler's matrix (a = 0.01, b = 1e-4) assembled, and
// gathered into the matrix-free product.
struct SinkingProduct {
  explicit SinkingProduct(World w)
      : world(std::move(w)),
        state(deformedJello(world)),
        model(world),
        op(model.springs(), model.numPoints()) {
    state.x.tail(state.numPoints()).array() -= 2.3;
    JacobianAssembler jac(model);
    jac.assemble(state.x.data(), {});
    A = jac.pattern();
    jac.combine(0.01, 1e-4, A);
    op.gather(A, jac.diagonalSlots(), jac.springSlots());
  }
  World world;
  State state;
  Model model;
  SparseMatrix A;
  SystemOperator op;
};

// The matrix-free product through the spring groups equals the sparse matrix's.
TEST(SystemOperator, ProductEqualsTheSparseMatrix) {
  const SinkingProduct scene(test::loadWorld("jello.w"));
  const State& s = scene.state;
  const Eigen::VectorXd p = Eigen::VectorXd::Random(s.x.size());
  Eigen::VectorXd y(p.size());
  scene.op.apply(p.data(), y.data());
  const Eigen::VectorXd expected = scene.A * p;
  EXPECT_LT((y - expected).cwiseAbs().maxCoeff(), 1e-13 * expected.cwiseAbs().maxCoeff());
  ASSERT_LT(s.x.tail(s.numPoints()).minCoeff(), -2.0);  // some points below the floor
}

// From 16^3 the product is split over threads (runs of base points, then the gaps between them):
// on 1, 2 and 3 threads it equals the sparse matrix's, and the threaded products the serial one,
// to round-off; below it stays serial, bit for bit.
TEST(SystemOperator, ThreadedProductEqualsTheSerialOne) {
  for (int n : {8, 16}) {
    const SinkingProduct scene(resampleCube(test::loadWorld("jello.w"), n));
    const SystemOperator& op = scene.op;
    const Eigen::VectorXd p = Eigen::VectorXd::Random(scene.state.x.size());
    const Eigen::VectorXd expected = scene.A * p;
    const double scale = expected.cwiseAbs().maxCoeff();
    setParallelThreads(1);
    Eigen::VectorXd serial(p.size());
    op.apply(p.data(), serial.data());
    EXPECT_LT((serial - expected).cwiseAbs().maxCoeff(), 1e-13 * scale);
    for (int threads : {2, 3}) {
      SCOPED_TRACE(std::to_string(n) + "^3, " + std::to_string(threads) + " threads");
      setParallelThreads(threads);
      Eigen::VectorXd threaded = Eigen::VectorXd::Constant(p.size(), 1e300);  // all overwritten
      op.apply(p.data(), threaded.data());
      EXPECT_LT((threaded - expected).cwiseAbs().maxCoeff(), 1e-13 * scale);
      EXPECT_LT((threaded - serial).cwiseAbs().maxCoeff(), 1e-13 * scale);
      if (n * n * n < kParallelMinPoints) {
        EXPECT_EQ(threaded, serial);
      } else {
        EXPECT_NE(threaded, serial);  // split: some sums in another order
      }
    }
    setParallelThreads(1);
  }
}

}  // namespace
}  // namespace jello
