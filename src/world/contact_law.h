// How contact pushes a point out of a solid (src/PHYSICS.md, "Contact models"): the course's
// penalty, whose stiffness jumps from 0 to kCollision at the surface; a smooth penalty whose
// energy is C2 in the depth, so its force and stiffness rise continuously over a thin layer; or
// a log barrier in the distance d outside the solid, which no point ever crosses.
// One table; the world file's `contact` extension, jello-create-world's and jello-sim's
// `--contact` read and write the names through it.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace jello {

// Each row: enumerator, name (world files, flags, statistics), one-line summary.
#define JELLO_CONTACT_MODELS(X)                                                             \
  X(Penalty, "penalty", "the course's: 1/2 kc depth^2, its stiffness jumps at the surface") \
  X(Smooth, "smooth",                                                                       \
    "C2 onset over a layer: kc depth^3 / (6 layer), then the penalty shifted by layer / 2") \
  X(Barrier, "barrier",                                                                     \
    "IPC's log barrier: -kappa (d - dhat)^2 ln(d / dhat) within dhat of the surface")

enum class ContactModel {
#define JELLO_CONTACT_MODEL_ENUMERATOR(kind, name, summary) kind,
  JELLO_CONTACT_MODELS(JELLO_CONTACT_MODEL_ENUMERATOR)
#undef JELLO_CONTACT_MODEL_ENUMERATOR
};

std::string_view contactModelName(ContactModel model);
// Every model, in the table's order.
std::span<const ContactModel> allContactModels();
// The model named (any case), or nothing.
std::optional<ContactModel> contactModelFromName(std::string_view name);
// "penalty, smooth": for help texts and messages.
std::string contactModelNames();

// m: the smooth model's layer unless a file or flag gives one; thin against the lattice's
// spacing (1/7 m at 8^3) and thick against a resting cube's penalty depth (about 0.4 mm on
// jello.w).
inline constexpr double kDefaultContactLayer = 0.005;

// m: the barrier's reach dhat unless a file or flag gives one (the same thinness argument).
inline constexpr double kDefaultBarrierDistance = 0.005;

// m/s: the slip speed over which friction rises from 0 to mu times the normal force.
inline constexpr double kDefaultSlipSpeed = 0.001;

// The model and its parameters, as the world file's `contact` extension gives them, and
// Coulomb friction (the `friction` extension; mu = 0: none, as the course has).
struct ContactLaw {
  ContactModel model = ContactModel::Penalty;
  double layer = 0.0;  // m, > 0 for smooth: the depth over which stiffness rises to kc
  double dhat = 0.0;   // m, > 0 for barrier: the distance where the barrier begins
  double kappa = 0.0;  // N/m, > 0 for barrier: its stiffness scale (default the world's kc)
  double mu = 0.0;     // Coulomb's coefficient, >= 0
  double slipSpeed = kDefaultSlipSpeed;  // m/s, > 0: eps_v, where static turns kinetic
  bool operator==(const ContactLaw&) const = default;
  // False when the file needs the `friction` extension to say mu and eps_v.
  bool frictionIsDefault() const { return mu == 0.0 && slipSpeed == kDefaultSlipSpeed; }
};

}  // namespace jello
