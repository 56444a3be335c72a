// The contact flags jello-create-world and jello-sim share: --contact MODEL, --contact-layer M
// (smooth), --dhat M and --kappa K (barrier), --friction MU and --slip-speed EPS (Coulomb friction
// on every solid) (src/world/contact_law.h). jello-sim's override the world file's.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

#include "src/world/contact_law.h"

namespace jello {

struct ContactFlags {
  std::string model;            // empty: not given
  std::optional<double> layer;  // m
  std::optional<double> dhat;   // m
  std::optional<double> kappa;  // N/m
  std::optional<double> mu;
  std::optional<double> slipSpeed;  // m/s
};

// Registers both; `what` ends the model's help ("default penalty", "overriding the file's").
void addContactFlags(CLI::App& app, ContactFlags& flags, const std::string& what);
// Applies the flags given over `law`: a smooth model without --contact-layer keeps the law's
// layer or takes kDefaultContactLayer; a barrier without --dhat or --kappa keeps the law's or
// takes kDefaultBarrierDistance and kCollision; --friction and --slip-speed replace the law's
// mu and eps_v (--slip-speed needs friction, the file's or the flag's). A usage error's text,
// or empty.
std::string applyContactFlags(const ContactFlags& flags, ContactLaw& law, double kCollision);

}  // namespace jello
