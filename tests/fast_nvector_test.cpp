// installFastOperations (solvers/cvode/fast_nvector.h): every replaced operation gives what
// SUNDIALS' own serial operation gives (to round-off: sums may add in another order), clones
// inherit the replacements, and vectors of another kind are left alone.
#include "solvers/cvode/fast_nvector.h"

#include <gtest/gtest.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "solvers/cvode/sundials_handles.h"

namespace jello {
namespace {

struct Vectors {
  sundials::Context context;
  std::vector<sundials::Vector> own, fast;  // the same values, SUNDIALS' operations and ours

  explicit Vectors(sunindextype n) {
    SUNContext ctx = nullptr;
    EXPECT_EQ(SUNContext_Create(nullptr, &ctx), 0);
    context.reset(ctx);
    for (int k = 0; k < 5; ++k) {
      own.emplace_back(N_VNew_Serial(n, ctx));
      fast.emplace_back(N_VNew_Serial(n, ctx));
      EXPECT_TRUE(installFastOperations(fast.back().get()));
      for (sunindextype i = 0; i < n; ++i) {
        // Mixed signs and sizes, a few exact zeros, no value the division would choke on.
        const double v = std::sin(1.7 * double(i) + 0.3 * k) * std::pow(10.0, double(i % 7) - 3.0);
        NV_Ith_S(own.back().get(), i) = NV_Ith_S(fast.back().get(), i) = v == 0.0 ? 0.5 : v;
      }
    }
    // A mask of 1s and 0s in vector 4.
    for (sunindextype i = 0; i < n; ++i) {
      NV_Ith_S(own[4].get(), i) = NV_Ith_S(fast[4].get(), i) = (i % 3 == 0) ? 1.0 : 0.0;
    }
  }
  N_Vector o(int k) { return own[static_cast<std::size_t>(k)].get(); }
  N_Vector f(int k) { return fast[static_cast<std::size_t>(k)].get(); }
};

double largestDifference(N_Vector a, N_Vector b) {
  double worst = 0.0, scale = 0.0;
  for (sunindextype i = 0; i < NV_LENGTH_S(a); ++i) {
    worst = std::max(worst, std::abs(NV_Ith_S(a, i) - NV_Ith_S(b, i)));
    scale = std::max(scale, std::abs(NV_Ith_S(a, i)));
  }
  return worst / std::max(scale, 1e-300);
}

TEST(FastNVector, EveryReplacedOperationEqualsSundials) {
  for (sunindextype n : {1, 7, 3001}) {  // odd lengths: the vector loops' remainders
    SCOPED_TRACE(n);
    Vectors v(n);
    // Elementwise operations writing vector 3.
    const std::vector<std::pair<std::string, std::function<void(Vectors&, bool)>>> writes = {
        {"linearsum",
         [](Vectors& w, bool f) {
           N_VLinearSum(0.3, f ? w.f(0) : w.o(0), -1.2, f ? w.f(1) : w.o(1), f ? w.f(3) : w.o(3));
         }},
        {"const", [](Vectors& w, bool f) { N_VConst(2.5, f ? w.f(3) : w.o(3)); }},
        {"prod",
         [](Vectors& w, bool f) {
           N_VProd(f ? w.f(0) : w.o(0), f ? w.f(1) : w.o(1), f ? w.f(3) : w.o(3));
         }},
        {"div",
         [](Vectors& w, bool f) {
           N_VDiv(f ? w.f(0) : w.o(0), f ? w.f(2) : w.o(2), f ? w.f(3) : w.o(3));
         }},
        {"scale",
         [](Vectors& w, bool f) { N_VScale(-3.0, f ? w.f(0) : w.o(0), f ? w.f(3) : w.o(3)); }},
        {"abs", [](Vectors& w, bool f) { N_VAbs(f ? w.f(1) : w.o(1), f ? w.f(3) : w.o(3)); }},
        {"inv", [](Vectors& w, bool f) { N_VInv(f ? w.f(2) : w.o(2), f ? w.f(3) : w.o(3)); }},
        {"addconst",
         [](Vectors& w, bool f) { N_VAddConst(f ? w.f(0) : w.o(0), 0.7, f ? w.f(3) : w.o(3)); }},
        {"compare",
         [](Vectors& w, bool f) { N_VCompare(0.01, f ? w.f(0) : w.o(0), f ? w.f(3) : w.o(3)); }},
        {"linearcombination (z = X0)",
         [](Vectors& w, bool f) {
           double c[3] = {0.5, -2.0, 3.0};
           N_Vector X[3] = {f ? w.f(3) : w.o(3), f ? w.f(0) : w.o(0), f ? w.f(1) : w.o(1)};
           EXPECT_EQ(N_VLinearCombination(3, c, X, f ? w.f(3) : w.o(3)), 0);
         }},
        {"scaleaddmulti",
         [](Vectors& w, bool f) {
           double a[2] = {1.5, -0.25};
           N_Vector Y[2] = {f ? w.f(1) : w.o(1), f ? w.f(2) : w.o(2)};
           N_Vector Z[2] = {f ? w.f(3) : w.o(3), f ? w.f(2) : w.o(2)};
           EXPECT_EQ(N_VScaleAddMulti(2, a, f ? w.f(0) : w.o(0), Y, Z), 0);
         }},
    };
    for (const auto& [name, op] : writes) {
      SCOPED_TRACE(name);
      op(v, false);
      op(v, true);
      EXPECT_LE(largestDifference(v.o(3), v.f(3)), 1e-15);
      EXPECT_LE(largestDifference(v.o(2), v.f(2)), 1e-15);
    }
    // Reductions.
    const std::vector<std::pair<std::string, std::function<double(Vectors&, bool)>>> sums = {
        {"dotprod",
         [](Vectors& w, bool f) { return N_VDotProd(f ? w.f(0) : w.o(0), f ? w.f(1) : w.o(1)); }},
        {"maxnorm", [](Vectors& w, bool f) { return N_VMaxNorm(f ? w.f(0) : w.o(0)); }},
        {"wrmsnorm",
         [](Vectors& w, bool f) { return N_VWrmsNorm(f ? w.f(0) : w.o(0), f ? w.f(1) : w.o(1)); }},
        {"wrmsnormmask",
         [](Vectors& w, bool f) {
           return N_VWrmsNormMask(f ? w.f(0) : w.o(0), f ? w.f(1) : w.o(1), f ? w.f(4) : w.o(4));
         }},
        {"min", [](Vectors& w, bool f) { return N_VMin(f ? w.f(0) : w.o(0)); }},
        {"wl2norm",
         [](Vectors& w, bool f) { return N_VWL2Norm(f ? w.f(0) : w.o(0), f ? w.f(1) : w.o(1)); }},
        {"l1norm", [](Vectors& w, bool f) { return N_VL1Norm(f ? w.f(0) : w.o(0)); }},
        {"wsqrsumlocal",
         [](Vectors& w, bool f) {
           return N_VWSqrSumLocal(f ? w.f(0) : w.o(0), f ? w.f(1) : w.o(1));
         }},
        {"wsqrsummasklocal",
         [](Vectors& w, bool f) {
           return N_VWSqrSumMaskLocal(f ? w.f(0) : w.o(0), f ? w.f(1) : w.o(1),
                                      f ? w.f(4) : w.o(4));
         }},
    };
    for (const auto& [name, op] : sums) {
      SCOPED_TRACE(name);
      const double a = op(v, false), b = op(v, true);
      EXPECT_LE(std::abs(a - b), 1e-13 * std::max(std::abs(a), 1e-300)) << a << " vs " << b;
    }
  }
}

TEST(FastNVector, ClonesInheritTheOperationsAndOtherVectorsAreRefused) {
  Vectors v(10);
  sundials::Vector clone(N_VClone(v.f(0)));
  EXPECT_EQ(clone->ops->nvwsqrsumlocal, v.f(0)->ops->nvwsqrsumlocal);
  EXPECT_NE(clone->ops->nvwsqrsumlocal, v.o(0)->ops->nvwsqrsumlocal);
  EXPECT_FALSE(installFastOperations(nullptr));
  sundials::Vector empty(N_VNewEmpty(v.context.get()));  // no kind: refused, untouched
  EXPECT_FALSE(installFastOperations(empty.get()));
}

}  // namespace
}  // namespace jello
