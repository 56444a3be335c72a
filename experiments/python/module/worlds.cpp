#include <algorithm>
#include <cstring>
#include <optional>
#include <sstream>

#include "experiments/python/module/bindings.h"
#include "src/model.h"
#include "src/world/scene_builder.h"
#include "src/world/world_reader.h"
#include "src/world/world_writer.h"

namespace jello::python {

using namespace py::literals;

namespace {

// ---- worlds --------------------------------------------------------------------------------

World loadWorld(const std::string& path, int maxFieldResolution, int maxCubeResolution) {
  jello::ReaderLimits limits;
  limits.maxFieldResolution = int(inRange(maxFieldResolution, 2, 1024, "max_field_resolution"));
  limits.maxCubeResolution = int(inRange(maxCubeResolution, 2, 256, "max_cube_resolution"));
  // The operating system reads a path up to its first NUL: refuse it rather than load another.
  if (path.find('\0') != std::string::npos) valueError("the path holds a NUL character");
  World world = jello::readWorld(path, limits);
  jello::checkStart(world, path);  // every term of its start's energy finite
  return world;
}

static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 is three packed doubles");

py::object fieldArray(const World& w) {
  if (w.field.empty()) return py::none();
  const py::ssize_t r = w.field.resolution;
  py::array_t<double> out({r, r, r, py::ssize_t(3)});
  std::memcpy(out.mutable_data(), w.field.forces.data(), w.field.forces.size() * sizeof(Vec3));
  return out;
}

void setField(World& w, const py::object& value) {
  if (value.is_none()) {
    w.field = {};
    return;
  }
  const Array a = Array::ensure(value);
  if (!a || a.ndim() != 4 || a.shape(3) != 3 || a.shape(0) != a.shape(1) ||
      a.shape(0) != a.shape(2)) {
    valueError("field must be an (R, R, R, 3) array of forces (N), or None");
  }
  const py::ssize_t r = a.shape(0);
  if (r < 2 || r > 128) valueError("field resolution R must be between 2 and 128");
  jello::ForceField f;
  f.resolution = int(r);
  f.forces.resize(static_cast<std::size_t>(r * r * r));
  const double* d = a.data();
  for (std::size_t i = 0; i < f.forces.size(); ++i) {
    f.forces[i] = {finite(d[3 * i], "field"), finite(d[3 * i + 1], "field"),
                   finite(d[3 * i + 2], "field")};
  }
  w.field = std::move(f);
}

bool sameWorld(const World& a, const World& b) {
  const auto samePoints = [](const std::vector<Vec3>& p, const std::vector<Vec3>& q) {
    return p.size() == q.size() &&
           std::equal(p.begin(), p.end(), q.begin(), [](const Vec3& u, const Vec3& v) {
             return u.x == v.x && u.y == v.y && u.z == v.z;
           });
  };
  const auto samePlane = [](const std::optional<jello::Plane>& p,
                            const std::optional<jello::Plane>& q) {
    return p.has_value() == q.has_value() &&
           (!p || (p->a == q->a && p->b == q->b && p->c == q->c && p->d == q->d));
  };
  const auto sameSphere = [](const std::optional<jello::Sphere>& p,
                             const std::optional<jello::Sphere>& q) {
    return p.has_value() == q.has_value() &&
           (!p || (p->center.x == q->center.x && p->center.y == q->center.y &&
                   p->center.z == q->center.z && p->radius == q->radius));
  };
  return a.integrator == b.integrator && a.dt == b.dt && a.stepsPerFrame == b.stepsPerFrame &&
         a.kElastic == b.kElastic && a.dElastic == b.dElastic && a.kCollision == b.kCollision &&
         a.dCollision == b.dCollision && a.mass == b.mass && samePlane(a.plane, b.plane) &&
         a.field.resolution == b.field.resolution && samePoints(a.field.forces, b.field.forces) &&
         a.cubeResolution == b.cubeResolution && samePoints(a.positions, b.positions) &&
         samePoints(a.velocities, b.velocities) && sameSphere(a.sphere, b.sphere) &&
         a.cone == b.cone && a.spiral == b.spiral && a.contact == b.contact;
}

}  // namespace

void saveWorld(const World& w, const std::string& path, bool legacy) {
  // What the reader would refuse is not written: the setters check each value, this the whole
  // (a sphere that swallows the cube, an energy no step can start from).
  jello::checkStart(w, path);
  try {
    jello::writeWorld(w, path, legacy ? jello::NumberFormat::Legacy : jello::NumberFormat::Exact);
  } catch (const std::runtime_error& e) {
    PyErr_SetString(PyExc_OSError, e.what());
    throw py::error_already_set();
  }
}

namespace {

// The law a model's name gives: smooth keeps a layer already set, else takes the default; the
// barrier keeps its dhat and kappa, else takes kDefaultBarrierDistance and kCollision; friction
// is kept.
jello::ContactLaw contactLaw(const std::string& name, const jello::ContactLaw& was,
                             double kCollision) {
  const std::optional<jello::ContactModel> model = jello::contactModelFromName(name);
  if (!model) valueError("contact must be one of " + jello::contactModelNames());
  jello::ContactLaw law;
  law.model = *model;
  law.mu = was.mu;
  law.slipSpeed = was.slipSpeed;
  if (*model == jello::ContactModel::Smooth) {
    law.layer = was.layer > 0.0 ? was.layer : jello::kDefaultContactLayer;
  }
  if (*model == jello::ContactModel::Barrier) {
    law.dhat = was.dhat > 0.0 ? was.dhat : jello::kDefaultBarrierDistance;
    law.kappa = was.kappa > 0.0 ? was.kappa : kCollision;
    if (!(law.kappa > 0.0)) valueError("the barrier's kappa defaults to k_collision, which is 0");
  }
  return law;
}

// Sets a barrier parameter (dhat or kappa), refused for the other models.
void setBarrierParameter(jello::ContactLaw& law, double& field, double value, const char* name) {
  if (law.model != jello::ContactModel::Barrier) {
    valueError(std::string(name) + " applies to the barrier contact model only");
  }
  field = positive(value, name);
}

// Long: one branch per keyword, as jello-create-world's flags.
// jello-create-world's flags as keywords ('-' -> '_'): the same presets, and the same check
// that the world reads back.
World createWorld(const py::kwargs& kwargs) {
  jello::SceneSpec spec;
  std::optional<double> fieldStrength, contactLayer, dhat, kappa, mu, slipSpeed;
  for (const auto& [key, value] : kwargs) {
    const std::string name = py::cast<std::string>(key);
    const char* n = name.c_str();
    const auto real = [&] { return as<double>(value, name); };
    if (name == "integrator") {
      spec.integrator = integratorFrom(as<std::string>(value, name));
    } else if (name == "dt") {
      spec.dt = positive(real(), n);
    } else if (name == "steps_per_frame") {
      spec.stepsPerFrame = int(inRange(as<long>(value, name), 1, 1000000, n));
    } else if (name == "k_elastic") {
      spec.kElastic = nonNegative(real(), n);
    } else if (name == "d_elastic") {
      spec.dElastic = nonNegative(real(), n);
    } else if (name == "k_collision") {
      spec.kCollision = nonNegative(real(), n);
    } else if (name == "d_collision") {
      spec.dCollision = nonNegative(real(), n);
    } else if (name == "mass") {
      spec.mass = positive(real(), n);
    } else if (name == "contact") {
      spec.contact.model = contactLaw(as<std::string>(value, name), {}, 1.0).model;
    } else if (name == "contact_layer") {
      contactLayer = positive(real(), n);
    } else if (name == "dhat") {
      dhat = positive(real(), n);
    } else if (name == "kappa") {
      kappa = positive(real(), n);
    } else if (name == "friction") {
      mu = nonNegative(real(), n);
    } else if (name == "slip_speed") {
      slipSpeed = positive(real(), n);
    } else if (name == "plane") {
      if (value.is_none()) {
        spec.plane.reset();
      } else {
        const auto p = as<std::vector<double>>(value, name);
        if (p.size() != 4) valueError("plane takes 4 numbers A B C D, or None");
        spec.plane =
            jello::Plane{finite(p[0], n), finite(p[1], n), finite(p[2], n), finite(p[3], n)};
      }
    } else if (name == "field") {
      const std::string f = as<std::string>(value, name);
      if (f == "none")
        spec.field = jello::FieldPreset::None;
      else if (f == "gravity")
        spec.field = jello::FieldPreset::Gravity;
      else if (f == "vortex")
        spec.field = jello::FieldPreset::Vortex;
      else if (f == "radial")
        spec.field = jello::FieldPreset::Radial;
      else
        valueError("field must be 'none', 'gravity', 'vortex' or 'radial'");
    } else if (name == "field_strength") {
      fieldStrength = finite(real(), n);
    } else if (name == "field_resolution") {
      const long r = inRange(as<long>(value, name), 0, 128, n);
      if (r == 1) valueError("field_resolution must be 0 (no field) or between 2 and 128");
      spec.fieldResolution = int(r);
    } else if (name == "pose") {
      const std::string p = as<std::string>(value, name);
      if (p == "rest")
        spec.pose = jello::PosePreset::Rest;
      else if (p == "skewed")
        spec.pose = jello::PosePreset::SkewedCorner;
      else if (p == "stretched")
        spec.pose = jello::PosePreset::Stretched;
      else if (p == "rotated")
        spec.pose = jello::PosePreset::Rotated;
      else if (p == "translated")
        spec.pose = jello::PosePreset::Translated;
      else
        valueError("pose must be 'rest', 'skewed', 'stretched', 'rotated' or 'translated'");
    } else if (name == "stretch") {
      spec.stretch = positive(real(), n);
    } else if (name == "rotate") {
      spec.rotateDegrees = finite(real(), n);
    } else if (name == "axis") {
      spec.rotateAxis = vec3From(value, n);
      if (jello::maxAbs(spec.rotateAxis) == 0.0) valueError("axis must not be zero");
    } else if (name == "translate") {
      spec.translate = vec3From(value, n);
    } else if (name == "velocity") {
      spec.velocity = vec3From(value, n);
    } else if (name == "spin") {
      spec.spin = finite(real(), n);
    } else if (name == "sphere") {
      if (value.is_none()) {
        spec.sphere.reset();
      } else {
        const auto s = as<std::vector<double>>(value, name);
        if (s.size() != 4) valueError("sphere takes 4 numbers CX CY CZ R, or None");
        spec.sphere = jello::Sphere{{finite(s[0], n), finite(s[1], n), finite(s[2], n)},
                                    positive(s[3], "sphere radius")};
      }
    } else if (name == "cube") {
      spec.cubeResolution = int(inRange(as<long>(value, name), 2, 64, n));
    } else {
      valueError("unknown create_world option '" + name +
                 "' (known: integrator, dt, steps_per_frame, k_elastic, d_elastic, k_collision, "
                 "d_collision, mass, plane, field, field_strength, field_resolution, pose, "
                 "stretch, rotate, axis, translate, velocity, spin, sphere, cube, contact, "
                 "contact_layer, dhat, kappa, friction, slip_speed)");
    }
  }
  // The model's parameters once every keyword is read (k_collision may come after contact).
  const jello::ContactModel model = spec.contact.model;
  spec.contact = contactLaw(std::string(jello::contactModelName(model)), {}, spec.kCollision);
  if (contactLayer) {
    if (model != jello::ContactModel::Smooth) {
      valueError("contact_layer applies to the smooth contact model only");
    }
    spec.contact.layer = *contactLayer;
  }
  if (dhat) setBarrierParameter(spec.contact, spec.contact.dhat, *dhat, "dhat");
  if (kappa) setBarrierParameter(spec.contact, spec.contact.kappa, *kappa, "kappa");
  spec.contact.mu = mu.value_or(0.0);
  if (slipSpeed) {
    if (!(spec.contact.mu > 0.0)) valueError("slip_speed applies with friction only");
    spec.contact.slipSpeed = *slipSpeed;
  }
  spec.fieldStrength = fieldStrength.value_or(jello::defaultFieldStrength(spec.field, spec.mass));
  const World world = jello::buildWorld(spec);
  try {
    // As jello-create-world: whatever the options, the world must read back.
    return jello::parseWorld(jello::formatWorld(world), "create_world");
  } catch (const jello::WorldFileError& e) {
    valueError(std::string("these options make no valid world: ") + e.what());
  }
}

}  // namespace

// Long: the class's table of attributes and functions, one def each.
void bindWorlds(py::module_& m) {
  // ---- World
  py::class_<World>(m, "World",
                    "One jello scene as a world file holds it. Attributes are copies; set them "
                    "to change the world (checked: ValueError on a bad value).")
      .def(py::init([] { return jello::buildWorld(jello::SceneSpec{}); }),
           "The course creator's default world (jello.w's values); see create_world")
      .def_property(
          "integrator",
          [](const World& w) { return std::string(jello::integratorName(w.integrator)); },
          [](World& w, const std::string& name) { w.integrator = integratorFrom(name); })
      .def_property(
          "dt", [](const World& w) { return w.dt; },
          [](World& w, double v) { w.dt = positive(v, "dt"); }, "time step, s")
      .def_property(
          "steps_per_frame", [](const World& w) { return w.stepsPerFrame; },
          [](World& w, long v) {
            w.stepsPerFrame = int(inRange(v, 1, 1000000, "steps_per_frame"));
          })
      .def_property(
          "k", [](const World& w) { return w.kElastic; },
          [](World& w, double v) { w.kElastic = nonNegative(v, "k"); },
          "spring stiffness, N/m (structural, shear and bend)")
      .def_property(
          "damping", [](const World& w) { return w.dElastic; },
          [](World& w, double v) { w.dElastic = nonNegative(v, "damping"); },
          "spring damping, N*s/m")
      .def_property(
          "k_collision", [](const World& w) { return w.kCollision; },
          [](World& w, double v) { w.kCollision = nonNegative(v, "k_collision"); },
          "contact stiffness, N/m")
      .def_property(
          "d_collision", [](const World& w) { return w.dCollision; },
          [](World& w, double v) { w.dCollision = nonNegative(v, "d_collision"); },
          "contact damping, N*s/m")
      .def_property(
          "contact",
          [](const World& w) { return std::string(jello::contactModelName(w.contact.model)); },
          [](World& w, const std::string& name) {
            w.contact = contactLaw(name, w.contact, w.kCollision);
          },
          "contact model: penalty (the course's), smooth (stiffening over contact_layer) or "
          "barrier (a log barrier within dhat of every solid, stiffness scale kappa)")
      .def_property(
          "contact_layer", [](const World& w) { return w.contact.layer; },
          [](World& w, double layer) {
            if (w.contact.model != jello::ContactModel::Smooth) {
              valueError("contact_layer applies to the smooth contact model only");
            }
            w.contact.layer = positive(layer, "contact_layer");
          },
          "the smooth contact model's layer, m (0 for the others)")
      .def_property(
          "dhat", [](const World& w) { return w.contact.dhat; },
          [](World& w, double v) { setBarrierParameter(w.contact, w.contact.dhat, v, "dhat"); },
          "the barrier's reach, m (0 for the other models)")
      .def_property(
          "kappa", [](const World& w) { return w.contact.kappa; },
          [](World& w, double v) { setBarrierParameter(w.contact, w.contact.kappa, v, "kappa"); },
          "the barrier's stiffness scale, N/m (0 for the other models)")
      .def_property(
          "friction", [](const World& w) { return w.contact.mu; },
          [](World& w, double v) { w.contact.mu = nonNegative(v, "friction"); },
          "Coulomb friction's coefficient mu on every solid (0: none, the course's)")
      .def_property(
          "slip_speed", [](const World& w) { return w.contact.slipSpeed; },
          [](World& w, double v) { w.contact.slipSpeed = positive(v, "slip_speed"); },
          "friction's slip speed eps_v, m/s: below it friction is static, a stiff damper")
      .def_property(
          "mass", [](const World& w) { return w.mass; },
          [](World& w, double v) {
            const double mass = positive(v, "mass");
            if (const auto bad = jello::velocitiesProblem(w.velocities, mass)) {
              valueError("with mass " + std::to_string(mass) + " kg, " + bad->message);
            }
            w.mass = mass;
          },
          "mass of each point, kg")
      .def_property(
          "plane",
          [](const World& w) -> py::object {
            if (!w.plane) return py::none();
            return py::make_tuple(w.plane->a, w.plane->b, w.plane->c, w.plane->d);
          },
          [](World& w, const py::object& v) {
            if (v.is_none()) {
              w.plane.reset();
              return;
            }
            const auto p = as<std::vector<double>>(v, "value");
            if (p.size() != 4) valueError("plane takes 4 numbers (a, b, c, d), or None");
            const jello::Plane plane{finite(p[0], "plane"), finite(p[1], "plane"),
                                     finite(p[2], "plane"), finite(p[3], "plane")};
            if (plane.a == 0.0 && plane.b == 0.0 && plane.c == 0.0) {
              valueError("the plane normal (a, b, c) is zero");
            }
            w.plane = plane;
          },
          "inclined plane (a, b, c, d): a x + b y + c z + d = 0, free where positive; or None")
      .def_property(
          "sphere",
          [](const World& w) -> py::object {
            if (!w.sphere) return py::none();
            const jello::Sphere& s = *w.sphere;
            return py::make_tuple(s.center.x, s.center.y, s.center.z, s.radius);
          },
          [](World& w, const py::object& v) {
            if (v.is_none()) {
              w.sphere.reset();
              return;
            }
            const auto s = as<std::vector<double>>(v, "value");
            if (s.size() != 4) valueError("sphere takes 4 numbers (cx, cy, cz, r), or None");
            w.sphere = jello::Sphere{
                {finite(s[0], "sphere"), finite(s[1], "sphere"), finite(s[2], "sphere")},
                positive(s[3], "sphere radius")};
          },
          "sphere obstacle (cx, cy, cz, r), m; or None")
      .def_property("field", &fieldArray, &setField,
                    "force field on R^3 nodes over the box [-2, 2]^3, an (R, R, R, 3) array (N), "
                    "node (i, j, k) at x = -2 + 4 i/(R-1), ...; or None")
      .def_property(
          "cube_resolution", [](const World& w) { return w.cubeResolution; },
          [](World& w, long n) {
            w = jello::resampleCube(w, int(inRange(n, 2, 64, "cube_resolution")));
          },
          "N: the cube has N^3 points; setting it resamples the state (as jello-sim --cube)")
      .def_property_readonly("num_points", &World::numPoints)
      .def_property(
          "positions", [](const World& w) { return pointsArray(w.positions); },
          [](World& w, const py::object& v) {
            std::vector<Vec3> positions = vec3List(v, w.numPoints(), "positions");
            if (const auto bad = jello::positionsProblem(positions)) valueError(bad->message);
            w.positions = std::move(positions);
          },
          "(n, 3) initial positions, m (a copy)")
      .def_property(
          "velocities", [](const World& w) { return pointsArray(w.velocities); },
          [](World& w, const py::object& v) {
            std::vector<Vec3> velocities = vec3List(v, w.numPoints(), "velocities");
            if (const auto bad = jello::velocitiesProblem(velocities, w.mass)) {
              valueError(bad->message);
            }
            w.velocities = std::move(velocities);
          },
          "(n, 3) initial velocities, m/s (a copy)")
      .def("save", &saveWorld, "path"_a, "legacy"_a = false,
           "Writes the world file atomically (exact numbers; legacy=True: six decimals)")
      .def("copy", [](const World& w) { return World(w); })
      .def("__copy__", [](const World& w) { return World(w); })
      .def("__deepcopy__", [](const World& w, const py::object&) { return World(w); })
      .def("__eq__", [](const World& a, const World& b) { return sameWorld(a, b); })
      .def("__repr__", [](const World& w) {
        std::ostringstream os;
        os << "<jello.World " << w.cubeResolution << "^3 points, "
           << jello::integratorName(w.integrator) << " dt=" << w.dt << ", k=" << w.kElastic
           << ", damping=" << w.dElastic << (w.plane ? ", plane" : "")
           << (w.sphere ? ", sphere" : "")
           << (w.field.empty() ? "" : ", field " + std::to_string(w.field.resolution) + "^3")
           << ">";
        return os.str();
      });

  m.def("load_world", &loadWorld, "path"_a, "max_field_resolution"_a = 128,
        "max_cube_resolution"_a = 64,
        "Reads a world file; raises jello.WorldError (file, line, token) on a bad one.",
        py::call_guard<py::gil_scoped_release>());
  m.def(
      "parse_world",
      [](const std::string& text, const std::string& name) {
        return jello::parseWorld(text, name);
      },
      "text"_a, "name"_a = "<string>", "Reads a world from text (errors call it `name`).");
  m.def("create_world", &createWorld,
        "A world from jello-create-world's options as keywords ('-' becomes '_'): integrator, "
        "dt, steps_per_frame, k_elastic, d_elastic, k_collision, d_collision, mass, plane "
        "(4 numbers or None), field ('none', 'gravity', 'vortex', 'radial'), field_strength, "
        "field_resolution, pose ('rest', 'skewed', 'stretched', 'rotated', 'translated'), "
        "stretch, rotate, axis, translate, velocity, spin, sphere (4 numbers), cube. With none: "
        "the course's jello.w.");
}

}  // namespace jello::python
