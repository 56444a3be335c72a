// Shared helpers for the tests: where the worlds are, and small scenes with known answers.
#pragma once

#include <filesystem>
#include <string>

#include "src/model.h"
#include "src/state.h"
#include "src/world/world.h"

namespace jello::test {

// True in the sanitizer build, whose runs are 5-10x slower (and validated at every step): the
// few tests that loop over many random cases or long runs do a share of them there, the release
// run all of them.
#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif

std::filesystem::path worldsDir();
World loadWorld(const std::string& name);  // a file of worlds/
std::string readFile(const std::filesystem::path& path);

// A program run through the shell: its exit code (-1 when it did not exit normally) and its
// standard output and error together.
struct Outcome {
  int code;
  std::string output;
};
Outcome run(const std::string& command);

// A fresh, empty directory under the system temp dir, removed when the object dies.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// Two points joined by one spring along x, point 0 at the origin, no walls, no field.
ModelSpec singleSpring(double stiffness, double damping, double rest, double mass);

// One point of 10 g, no spring, no walls: the contact tests' model, with contact constants k.
ModelSpec onePoint(const ContactConstants& k);
// The state of one point at x moving at v.
State pointAt(const Vec3& x, const Vec3& v);
// The mean of the points' positions (m): the centre of mass of equal masses.
Vec3 centre(const State& s);
// The mean velocity of the points (equal masses: the centre of mass's).
Vec3 meanVelocity(const State& s);

// Two points of mass m joined by a spring of rest length 0: the force k (x_j - x_i) is exactly
// linear, so the relative motion is an undamped isotropic oscillator with w = sqrt(2k/m). The
// start state keeps the centre of mass at rest at the origin, so energy() is that of the
// relative motion.
struct LinearOscillator {
  double mass = 0.01, stiffness = 2.0;
  Model model{singleSpring(stiffness, 0.0, 0.0, mass)};

  double omega() const;
  double energy(const State& s) const;
  State start() const;
};

// jello.w's cube (skewed corner, moving) with walls, plane and field switched off: a free body.
ModelSpec freeCube(const World& world);

// Dense checks, instantiated here once: Eigen's eigensolvers cost each test file that named
// them 10-30 s of compile time (more under the sanitizers).
// The eigenvalues of symmetric a, ascending.
Eigen::VectorXd symmetricEigenvalues(const Eigen::MatrixXd& a);
// The eigenvalues l of a v = l b v (a symmetric, b symmetric positive definite), ascending.
Eigen::VectorXd generalizedEigenvalues(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b);
// Whether a dense Cholesky factorization of a succeeds (a symmetric positive definite).
bool choleskySucceeds(const Eigen::MatrixXd& a);
// The inverse of invertible a (partial-pivoting LU).
Eigen::MatrixXd inverse(const Eigen::MatrixXd& a);

}  // namespace jello::test
