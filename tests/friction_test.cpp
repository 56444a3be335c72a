// Coulomb friction (src/effects/friction.cpp, src/PHYSICS.md): the mollifier is C1 with its
// derivatives each other's; on every solid, under every contact law, the friction force is
// tangential, opposes the slip, is at most mu lambda and exactly mu lambda once sliding faster
// than eps_v; its velocity Jacobian matches finite differences at non-zero slip (static and
// kinetic) and is symmetric negative semidefinite; its power is f.v; the world file's
// `friction` extension round-trips and bad ones are refused naming the token.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

#include "solvers/system/jacobian.h"
#include "src/model.h"
#include "src/world/world_reader.h"
#include "src/world/world_writer.h"
#include "tests/test_support.h"

namespace jello {
namespace {

constexpr double kMu = 0.6, kSlip = 0.05;

TEST(SmoothedFriction, IsC1AtTheSlipSpeedAndItsDerivativesAreEachOthers) {
  for (double s : {1e-4, 0.01, 0.03, 0.0499, 0.07, 2.0}) {
    const FrictionValue v = smoothedFriction(s, kSlip);
    EXPECT_NEAR(v.g * s, v.f1, 1e-15);
    const double h = 1e-7;
    const double dg =
        (smoothedFriction(s + h, kSlip).g - smoothedFriction(s - h, kSlip).g) / (2 * h);
    EXPECT_NEAR(v.dg, dg, 1e-6 * std::abs(dg) + 1e-9) << s;
    EXPECT_GE(v.f1, 0.0);
    EXPECT_LE(v.f1, 1.0);
  }
  // f1 and its slope meet the kinetic 1 and 0 at eps_v; 0 at rest with slope 2/eps_v.
  const double e = kSlip, h = 1e-9;
  EXPECT_NEAR(smoothedFriction(e - h, e).f1, 1.0, 1e-12);
  for (double s : {e - h, e + h}) {  // f1' = g + s g'
    const FrictionValue v = smoothedFriction(s, e);
    EXPECT_NEAR(v.g + s * v.dg, 0.0, 1e-6 / e);
  }
  EXPECT_EQ(smoothedFriction(0.0, e).f1, 0.0);
  EXPECT_NEAR(smoothedFriction(0.0, e).g, 2.0 / e, 1e-12);
}

// test::onePoint with friction mu = kMu, eps = kSlip.
ModelSpec onePoint(ContactConstants k) {
  k.mu = kMu;
  k.slipSpeed = kSlip;
  return test::onePoint(k);
}

// A model per solid and law: the walls, the plane, the sphere and the cone (the spiral's
// friction runs the cone's code path; its exterior distance is checked in contact_laws_test).
std::vector<ModelSpec> everySolidAndLaw() {
  const ContactConstants laws[] = {{1000.0, 0.3},
                                   {1000.0, 0.3, ContactModel::Smooth, 0.05},
                                   {1000.0, 0.0, ContactModel::Barrier, 0.0, 0.05, 1000.0}};
  std::vector<ModelSpec> specs;
  for (const ContactConstants& k : laws) {
    ModelSpec walls = onePoint(k), plane = onePoint(k), sphere = onePoint(k), cone = onePoint(k);
    walls.walls = true;
    plane.plane = Plane{-1, 1, 2, 2};
    sphere.sphere = Sphere{{0.1, -0.2, 0.3}, 0.9};
    cone.cone = Cone{{0.2, -0.1, 0.0}, {0.1, 0.2, -1.0}, 1.8, 1.1};
    specs.insert(specs.end(), {walls, plane, sphere, cone});
  }
  return specs;
}

State at(const Vec3& x, const Vec3& v) {
  return test::pointAt(x, v);
}

// Points where the model's one solid pushes with a normal force (in it, or within the
// barrier's reach outside), each with its one contact.
std::vector<std::pair<Vec3, Penetration>> pushedPoints(const Model& model, int count) {
  const Obstacle& o = *model.obstacles().front();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-2.1, 2.1);
  std::vector<std::pair<Vec3, Penetration>> points;
  Penetration touch[kMaxPenetrations];
  const bool barrier = o.constants().model == ContactModel::Barrier;
  for (long tries = 0; int(points.size()) < count && tries < 10000000; ++tries) {
    const Vec3 x{u(rng), u(rng), u(rng)};
    if (o.penetrations(x, o.reach(), touch) != 1) continue;
    const double q = touch[0].depth;
    if (barrier ? !(q < -1e-3 && q > -0.04) : !(q > 1e-3 && q < 0.2)) continue;
    points.emplace_back(x, touch[0]);
  }
  EXPECT_EQ(int(points.size()), count);
  return points;
}

// The friction force alone: the forces with mu minus those without.
Eigen::Vector3d frictionForce(const ModelSpec& spec, const State& s) {
  ModelSpec without = spec;
  without.contact.mu = 0.0;
  Eigen::VectorXd f, f0;
  Model(spec).forces(s.x, s.v, f);
  Model(without).forces(s.x, s.v, f0);
  return f - f0;
}

TEST(Friction, IsTangentialBoundedAndOpposesTheSlipOnEverySolidUnderEveryLaw) {
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0.0, 1.0);
  for (const ModelSpec& spec : everySolidAndLaw()) {
    const Model model(spec);
    const Obstacle& o = *model.obstacles().front();
    SCOPED_TRACE(std::string(obstacleName(o.kind())) + " " +
                 std::string(contactModelName(o.constants().model)));
    for (const auto& [x, touch] : pushedPoints(model, 20)) {
      const Vec3 n = unitVector(touch.gradient * -1.0);
      ModelSpec frictionless = spec;
      frictionless.contact.mu = 0.0;
      Eigen::VectorXd normal;
      Model(frictionless).forces(at(x, {0, 0, 0}).x, at(x, {0, 0, 0}).v, normal);
      const double lambda = normal.norm();  // at rest: the elastic normal force alone
      for (double speed : {0.3 * kSlip, 0.9 * kSlip, 3.0 * kSlip}) {
        Vec3 u{g(rng), g(rng), g(rng)};
        u = u - n * dot(u, n);
        u = unitVector(u) * speed;
        const Vec3 v = u + n * (0.5 * g(rng));  // and some normal velocity
        const Eigen::Vector3d f = frictionForce(spec, at(x, v));
        const Eigen::Vector3d nn(n.x, n.y, n.z), uu(u.x, u.y, u.z);
        EXPECT_LT(std::abs(f.dot(nn)), 1e-12 * lambda);
        EXPECT_LT(f.dot(uu), 0.0);
        EXPECT_LT((f + f.norm() * uu / speed).norm(), 1e-9 * lambda);  // along -u
        const double expected = kMu * lambda * smoothedFriction(speed, kSlip).f1;
        EXPECT_NEAR(f.norm(), expected, 1e-9 * lambda);
        if (speed > kSlip) {
          EXPECT_NEAR(f.norm(), kMu * lambda, 1e-9 * lambda);
        }
        EXPECT_NEAR(o.frictionPower(at(x, v).x.data(), at(x, v).v.data(), 1),
                    f.dot(Eigen::Vector3d(v.x, v.y, v.z)), 1e-12 * lambda);
      }
    }
  }
}

TEST(Friction, ItsVelocityJacobianMatchesFiniteDifferencesAtNonZeroSlip) {
  std::mt19937 rng(4);
  std::normal_distribution<double> g(0.0, 1.0);
  for (const ModelSpec& spec : everySolidAndLaw()) {
    const Model model(spec);
    SCOPED_TRACE(std::string(obstacleName(model.obstacles().front()->kind())) + " " +
                 std::string(contactModelName(spec.contact.model)));
    for (const auto& [x, touch] : pushedPoints(model, 10)) {
      const Vec3 n = unitVector(touch.gradient * -1.0);
      for (double speed : {0.2 * kSlip, 0.7 * kSlip, 4.0 * kSlip}) {
        Vec3 u{g(rng), g(rng), g(rng)};
        u = unitVector(u - n * dot(u, n)) * speed;
        const State s = at(x, u + n * 0.1);
        Eigen::Matrix3d D;
        const double h = 1e-7 * kSlip;
        for (int j = 0; j < 3; ++j) {
          State p = s, m = s;
          p.v[j] += h;
          m.v[j] -= h;
          Eigen::VectorXd fp, fm;
          model.forces(p.x, p.v, fp);
          model.forces(m.x, m.v, fm);
          D.col(j) = (fp - fm) / (2 * h);
        }
        JacobianAssembler jac(model);
        jac.assemble(s.x.data(), {.velocities = s.v.data()});
        const Eigen::Matrix3d assembled = Eigen::MatrixXd(jac.D());
        EXPECT_LT((assembled - D).cwiseAbs().maxCoeff(), 1e-6 * D.cwiseAbs().maxCoeff())
            << "speed " << speed << "\n"
            << assembled << "\n"
            << D;
        EXPECT_LT((assembled - assembled.transpose()).cwiseAbs().maxCoeff(),
                  1e-12 * assembled.cwiseAbs().maxCoeff());
        EXPECT_LE(
            Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(assembled).eigenvalues().maxCoeff(),
            1e-12 * assembled.cwiseAbs().maxCoeff());
        // Without the velocities, friction is left out of D.
        jac.assemble(s.x.data(), {});
        ModelSpec frictionless = spec;
        frictionless.contact.mu = 0.0;
        const Model frictionlessModel(frictionless);
        JacobianAssembler plain(frictionlessModel);
        plain.assemble(s.x.data(), {});
        EXPECT_EQ(Eigen::MatrixXd(jac.D()), Eigen::MatrixXd(plain.D()));
      }
    }
  }
}

TEST(FrictionWorlds, TheExtensionRoundTripsAndBadOnesAreRefused) {
  World w = test::loadWorld("jello.w");
  EXPECT_TRUE(w.contact.frictionIsDefault());  // no extension: no friction
  w.contact.mu = 0.4;
  w.contact.slipSpeed = 0.002;
  const std::string text = formatWorld(w);
  const std::size_t at = text.find("\nfriction 0.4");
  ASSERT_NE(at, std::string::npos) << text;
  const std::string line = text.substr(at + 1, text.find('\n', at + 1) - at - 1);
  EXPECT_EQ(parseWorld(text, "t.w").contact, w.contact);
  w.contact.model = ContactModel::Smooth;  // with a contact line, in either order
  w.contact.layer = 0.01;
  EXPECT_EQ(parseWorld(formatWorld(w), "t.w").contact, w.contact);
  const auto refused = [&](const std::string& badLine, const std::string& token) {
    std::string bad = text;
    bad.replace(at + 1, line.size(), badLine);
    try {
      parseWorld(bad, "bad.w");
      ADD_FAILURE() << badLine << " was read";
    } catch (const WorldFileError& e) {
      EXPECT_NE(std::string(e.what()).find("bad.w"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(token), std::string::npos) << e.what();
    }
  };
  refused("friction -0.1 0.002", "-0.1");
  refused("friction 0.4 0", "slip speed");
  refused("friction 0.4", "slip speed");
  refused("friction nan 0.002", "nan");
  refused("friction 0.4 0.002 friction 0.4 0.002", "given twice");
}

}  // namespace
}  // namespace jello
