#include "src/world/lattice.h"

namespace jello {
namespace {

constexpr std::array<LatticeOffset, 16> kOffsets{{
    {1, 0, 0, SpringKind::Structural},
    {0, 1, 0, SpringKind::Structural},
    {0, 0, 1, SpringKind::Structural},
    {1, 1, 0, SpringKind::FaceShear},
    {1, -1, 0, SpringKind::FaceShear},
    {1, 0, 1, SpringKind::FaceShear},
    {1, 0, -1, SpringKind::FaceShear},
    {0, 1, 1, SpringKind::FaceShear},
    {0, 1, -1, SpringKind::FaceShear},
    {1, 1, 1, SpringKind::BodyShear},
    {1, 1, -1, SpringKind::BodyShear},
    {1, -1, 1, SpringKind::BodyShear},
    {1, -1, -1, SpringKind::BodyShear},
    {2, 0, 0, SpringKind::Bend},
    {0, 2, 0, SpringKind::Bend},
    {0, 0, 2, SpringKind::Bend},
}};

}  // namespace

const char* springKindName(SpringKind kind) {
  switch (kind) {
    case SpringKind::Structural:
      return "structural";
    case SpringKind::FaceShear:
      return "face shear";
    case SpringKind::BodyShear:
      return "body shear";
    case SpringKind::Bend:
      return "bend";
  }
  return "?";
}

std::span<const LatticeOffset> latticeOffsets() {
  return kOffsets;
}

std::array<long, kSpringKinds> springCountFormula(int n) {
  const long N = n;
  return {3 * N * N * (N - 1), 6 * N * (N - 1) * (N - 1), 4 * (N - 1) * (N - 1) * (N - 1),
          N >= 2 ? 3 * N * N * (N - 2) : 0};
}

}  // namespace jello
