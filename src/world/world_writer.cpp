#include "src/world/world_writer.h"

#include <cstdio>
#include <initializer_list>
#include <string>

#include "src/base/atomic_file.h"

namespace jello {
namespace {

class Printer {
 public:
  explicit Printer(NumberFormat format) : fmt_(format == NumberFormat::Exact ? "%.17g" : "%f") {}

  void numbers(std::initializer_list<double> values) {
    bool first = true;
    for (double v : values) {
      if (!first) out_ += ' ';
      first = false;
      char buf[64];
      const int n = std::snprintf(buf, sizeof buf, fmt_, v);
      out_.append(buf, static_cast<std::size_t>(n));
    }
    out_ += '\n';
  }
  void vec(const Vec3& v) { numbers({v.x, v.y, v.z}); }
  void text(std::string_view s) {
    out_ += s;
    out_ += '\n';
  }
  void textInt(std::string_view prefix, int value) {
    out_ += prefix;
    out_ += std::to_string(value);
    out_ += '\n';
  }
  void numberInt(double value, int i) {
    char buf[64];
    const int n = std::snprintf(buf, sizeof buf, fmt_, value);
    out_.append(buf, static_cast<std::size_t>(n));
    textInt(" ", i);
  }
  std::string take() { return std::move(out_); }

 private:
  const char* fmt_;
  std::string out_;
};

}  // namespace

// The original loader reads line 1 into a 10-byte buffer and knows only these two names.
bool originalIntegrator(IntegratorKind kind) {
  return kind == IntegratorKind::Euler || kind == IntegratorKind::RK4;
}

std::string formatWorld(const World& w, NumberFormat format) {
  Printer p(format);
  // Line 1 always holds a name the original loader knows; another integrator goes into the
  // extension block, which that loader never reads.
  p.text(integratorFileName(originalIntegrator(w.integrator) ? w.integrator : IntegratorKind::RK4));
  p.numberInt(w.dt, w.stepsPerFrame);
  p.numbers({w.kElastic, w.dElastic, w.kCollision, w.dCollision});
  p.numbers({w.mass});
  p.textInt("", w.plane ? 1 : 0);
  if (w.plane) p.numbers({w.plane->a, w.plane->b, w.plane->c, w.plane->d});
  p.textInt("", w.field.resolution);
  for (const Vec3& f : w.field.forces) p.vec(f);
  for (const Vec3& x : w.positions) p.vec(x);
  for (const Vec3& v : w.velocities) p.vec(v);
  // The extension block: after the velocities, where the original loader stops reading.
  if (!originalIntegrator(w.integrator)) {
    p.text("integrator " + std::string(integratorFileName(w.integrator)));
  }
  if (w.cubeResolution != kDefaultCubeResolution) p.textInt("cube ", w.cubeResolution);
  // One line: the keyword, then its numbers.
  const auto extension = [&](const std::string& keyword, std::initializer_list<double> numbers) {
    Printer q(format);
    q.numbers(numbers);
    std::string line = keyword + " " + q.take();
    line.pop_back();  // the numbers' newline
    p.text(line);
  };
  if (w.sphere) {
    const Sphere& s = *w.sphere;
    extension("sphere", {s.center.x, s.center.y, s.center.z, s.radius});
  }
  if (w.cone) {
    const Cone& c = *w.cone;
    extension("cone",
              {c.apex.x, c.apex.y, c.apex.z, c.axis.x, c.axis.y, c.axis.z, c.height, c.radius});
  }
  if (w.spiral) {
    const Spiral& s = *w.spiral;
    extension("spiral", {s.cx, s.cy, s.zTop, s.rInner, s.rOuter, s.pitch, s.turns, s.thickness});
  }
  // Penalty, the course's contact, is what a file without the line means.
  const std::string contact = "contact " + std::string(contactModelName(w.contact.model));
  if (w.contact.model == ContactModel::Smooth) extension(contact, {w.contact.layer});
  if (w.contact.model == ContactModel::Barrier) {
    extension(contact, {w.contact.dhat, w.contact.kappa});
  }
  if (!w.contact.frictionIsDefault()) {
    extension("friction", {w.contact.mu, w.contact.slipSpeed});
  }
  return p.take();
}

void writeWorld(const World& world, const std::filesystem::path& path, NumberFormat format) {
  writeFileAtomically(path, formatWorld(world, format));
}

}  // namespace jello
