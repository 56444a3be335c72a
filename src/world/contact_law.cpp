#include "src/world/contact_law.h"

#include "src/base/closed_set.h"

namespace jello {
namespace {

constexpr closed_set::Row<ContactModel> kRows[] = {
#define JELLO_CONTACT_MODEL_ROW(kind, name, summary) {ContactModel::kind, name, summary},
    JELLO_CONTACT_MODELS(JELLO_CONTACT_MODEL_ROW)
#undef JELLO_CONTACT_MODEL_ROW
};
constexpr auto kKinds = closed_set::kinds(kRows);

}  // namespace

std::span<const ContactModel> allContactModels() {
  return kKinds;
}

std::string_view contactModelName(ContactModel model) {
  return closed_set::row(kRows, model).name;
}

std::optional<ContactModel> contactModelFromName(std::string_view name) {
  return closed_set::parse(kRows, name);
}

std::string contactModelNames() {
  return closed_set::names(kRows);
}

}  // namespace jello
