#include "experiments/tools/contact_flags.h"

#include <cstdio>

#include "src/base/finite_options.h"

namespace jello {

void addContactFlags(CLI::App& app, ContactFlags& flags, const std::string& what) {
  char layer[32];
  std::snprintf(layer, sizeof layer, "%g", kDefaultContactLayer);
  app.add_option("--contact", flags.model,
                 "Contact model: " + contactModelNames() + " (" + what + ")");
  app.add_option("--contact-layer", flags.layer,
                 "The smooth model's layer, m: the depth over which contact stiffens to "
                 "kCollision (default " +
                     std::string(layer) + ")")
      ->check(cli::positive());
}

std::string applyContactFlags(const ContactFlags& flags, ContactLaw& law) {
  if (!flags.model.empty()) {
    const std::optional<ContactModel> model = contactModelFromName(flags.model);
    if (!model) {
      return "unknown contact model '" + flags.model + "' (known: " + contactModelNames() + ")";
    }
    law.model = *model;
  }
  if (law.model != ContactModel::Smooth) {
    if (flags.layer) return "--contact-layer applies to the smooth contact model only";
    law.layer = 0.0;
    return "";
  }
  law.layer = flags.layer.value_or(law.layer > 0.0 ? law.layer : kDefaultContactLayer);
  return "";
}

}  // namespace jello
