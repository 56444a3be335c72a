#include "experiments/tools/contact_flags.h"

#include <cstdio>

#include "src/base/finite_options.h"

namespace jello {

void addContactFlags(CLI::App& app, ContactFlags& flags, const std::string& what) {
  const auto number = [](double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", v);
    return std::string(text);
  };
  app.add_option("--contact", flags.model,
                 "Contact model: " + contactModelNames() + " (" + what + ")");
  app.add_option("--contact-layer", flags.layer,
                 "The smooth model's layer, m: the depth over which contact stiffens to "
                 "kCollision (default " +
                     number(kDefaultContactLayer) + ")")
      ->check(cli::positive());
  app.add_option("--dhat", flags.dhat,
                 "The barrier's reach, m: the distance from a solid where it begins (default " +
                     number(kDefaultBarrierDistance) + ")")
      ->check(cli::positive());
  app.add_option("--kappa", flags.kappa,
                 "The barrier's stiffness scale, N/m (default the world's kCollision)")
      ->check(cli::positive());
  app.add_option("--friction", flags.mu,
                 "Coulomb friction's coefficient mu on every solid (default 0: none)")
      ->check(cli::nonNegative());
  app.add_option("--slip-speed", flags.slipSpeed,
                 "Friction's slip speed, m/s: below it friction is static, a stiff damper "
                 "(default " +
                     number(kDefaultSlipSpeed) + ")")
      ->check(cli::positive());
}

std::string applyContactFlags(const ContactFlags& flags, ContactLaw& law, double kCollision) {
  if (!flags.model.empty()) {
    const std::optional<ContactModel> model = contactModelFromName(flags.model);
    if (!model) {
      return "unknown contact model '" + flags.model + "' (known: " + contactModelNames() + ")";
    }
    law.model = *model;
  }
  const bool smooth = law.model == ContactModel::Smooth;
  const bool barrier = law.model == ContactModel::Barrier;
  if (!smooth && flags.layer) return "--contact-layer applies to the smooth contact model only";
  if (!barrier && (flags.dhat || flags.kappa)) {
    return std::string(flags.dhat ? "--dhat" : "--kappa") +
           " applies to the barrier contact model only";
  }
  law.layer =
      smooth ? flags.layer.value_or(law.layer > 0.0 ? law.layer : kDefaultContactLayer) : 0.0;
  law.dhat =
      barrier ? flags.dhat.value_or(law.dhat > 0.0 ? law.dhat : kDefaultBarrierDistance) : 0.0;
  law.kappa = barrier ? flags.kappa.value_or(law.kappa > 0.0 ? law.kappa : kCollision) : 0.0;
  if (barrier && !(law.kappa > 0.0)) {
    return "the barrier's kappa defaults to kCollision, which is 0 here: give --kappa";
  }
  if (flags.mu) law.mu = *flags.mu;
  if (flags.slipSpeed) {
    if (!(law.mu > 0.0)) return "--slip-speed applies with friction only (give --friction)";
    law.slipSpeed = *flags.slipSpeed;
  }
  return "";
}

}  // namespace jello
