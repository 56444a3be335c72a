// The cube's lattice: N^3 points resting at (i,j,k)/(N-1), flat index i*N*N + j*N + k, and the
// spring offsets that connect them. Each pair of points is one spring, counted once:
//   structural  3 axis offsets          3 N^2 (N-1)   springs, rest 1/(N-1)
//   face shear  6 face diagonals        6 N (N-1)^2   springs, rest sqrt(2)/(N-1)
//   body shear  4 body diagonals        4 (N-1)^3     springs, rest sqrt(3)/(N-1)
//   bend        3 second axis offsets   3 N^2 (N-2)   springs, rest 2/(N-1)
// (src/PHYSICS.md; for N = 8: 1344 + 2352 + 1372 + 1152 = 6220.) Rest lengths always come from this
// ideal lattice, never from a file's initial positions.
#pragma once

#include <array>
#include <span>

#include "src/base/vec3.h"

namespace jello {

enum class SpringKind { Structural, FaceShear, BodyShear, Bend };
inline constexpr int kSpringKinds = 4;

const char* springKindName(SpringKind kind);

struct LatticeOffset {
  int di, dj, dk;
  SpringKind kind;
};

// The 16 offsets, one per direction (the opposite direction would count each pair twice).
std::span<const LatticeOffset> latticeOffsets();

struct Lattice {
  int n = 8;  // points per axis, >= 2

  int numPoints() const { return n * n * n; }
  int index(int i, int j, int k) const { return (i * n + j) * n + k; }
  double spacing() const { return 1.0 / (n - 1); }  // m
  Vec3 restPosition(int i, int j, int k) const {
    const double h = spacing();
    return {i * h, j * h, k * h};
  }
  bool contains(int i, int j, int k) const {
    return i >= 0 && i < n && j >= 0 && j < n && k >= 0 && k < n;
  }
};

// The closed-form counts above, indexed by SpringKind.
std::array<long, kSpringKinds> springCountFormula(int n);

}  // namespace jello
