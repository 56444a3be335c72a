#include "tests/test_support.h"

#include <sys/wait.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>

#include "src/world/world_reader.h"

namespace jello::test {

std::filesystem::path worldsDir() {
  return JELLO_WORLDS_DIR;
}

World loadWorld(const std::string& name) {
  return readWorld(worldsDir() / name);
}

Outcome run(const std::string& command) {
  std::string output;
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return {-1, "popen failed"};
  char buf[4096];
  while (std::size_t n = std::fread(buf, 1, sizeof buf, pipe)) output.append(buf, n);
  const int status = ::pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
}

std::string readFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TempDir::TempDir() {
  std::random_device rd;
  path_ = std::filesystem::temp_directory_path() /
          ("jello-test-" + std::to_string(rd()) + std::to_string(rd()));
  std::filesystem::create_directories(path_);
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::permissions(path_, std::filesystem::perms::owner_all,
                               std::filesystem::perm_options::add, ec);
  std::filesystem::remove_all(path_, ec);
}

ModelSpec onePoint(const ContactConstants& k) {
  ModelSpec spec;
  spec.numPoints = 1;
  spec.mass = 0.01;
  spec.walls = false;
  spec.contact = k;
  return spec;
}

State pointAt(const Vec3& x, const Vec3& v) {
  State s;
  s.x.resize(3);
  s.v.resize(3);
  State::set(s.x, 0, x);
  State::set(s.v, 0, v);
  return s;
}

Vec3 centre(const State& s) {
  Vec3 c{0, 0, 0};
  const int n = s.numPoints();
  for (int p = 0; p < n; ++p) c = c + s.position(p);
  return c * (1.0 / n);
}

Vec3 meanVelocity(const State& s) {
  Vec3 v{0, 0, 0};
  const int n = s.numPoints();
  for (int p = 0; p < n; ++p) v = v + s.velocity(p);
  return v * (1.0 / n);
}

ModelSpec singleSpring(double stiffness, double damping, double rest, double mass) {
  ModelSpec spec;
  spec.numPoints = 2;
  spec.mass = mass;
  SpringGroup g;
  g.delta = 1;
  g.first = 0;
  g.mask = {1.0};
  g.rest = rest;
  g.stiffness = stiffness;
  g.damping = damping;
  g.numSprings = 1;
  spec.springs.push_back(g);
  spec.walls = false;
  return spec;
}

double LinearOscillator::omega() const {
  return std::sqrt(2 * stiffness / mass);
}

double LinearOscillator::energy(const State& s) const {
  const Vec3 d = s.position(1) - s.position(0);
  return 0.5 * mass * s.v.squaredNorm() + 0.5 * stiffness * dot(d, d);
}

State LinearOscillator::start() const {
  State s;
  s.x.resize(6);
  s.v.resize(6);
  State::set(s.x, 0, {-0.3, 0.2, 0.1});
  State::set(s.x, 1, {0.3, -0.2, -0.1});
  State::set(s.v, 0, {0.5, 1.0, -2.0});
  State::set(s.v, 1, {-0.5, -1.0, 2.0});
  return s;
}

ModelSpec freeCube(const World& world) {
  ModelSpec spec = modelSpecFromWorld(world);
  spec.walls = false;
  spec.plane.reset();
  spec.sphere.reset();
  spec.field = {};
  return spec;
}

Eigen::VectorXd symmetricEigenvalues(const Eigen::MatrixXd& a) {
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(a, Eigen::EigenvaluesOnly).eigenvalues();
}

Eigen::VectorXd generalizedEigenvalues(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd>(a, b, Eigen::EigenvaluesOnly)
      .eigenvalues();
}

bool choleskySucceeds(const Eigen::MatrixXd& a) {
  return Eigen::LLT<Eigen::MatrixXd>(a).info() == Eigen::Success;
}

Eigen::MatrixXd inverse(const Eigen::MatrixXd& a) {
  return a.inverse();
}

}  // namespace jello::test
