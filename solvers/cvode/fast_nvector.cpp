#include "solvers/cvode/fast_nvector.h"

#include <nvector/nvector_serial.h>

#include <algorithm>
#include <cmath>

namespace jello {
namespace {

using Index = sunindextype;

Index length(N_Vector v) {
  return NV_LENGTH_S(v);
}
double* data(N_Vector v) {
  return NV_DATA_S(v);
}

void linearSum(double a, N_Vector x, double b, N_Vector y, N_Vector z) {
  const double* xs = data(x);
  const double* ys = data(y);
  double* zs = data(z);
  const Index n = length(x);
#pragma omp simd
  for (Index i = 0; i < n; ++i) zs[i] = a * xs[i] + b * ys[i];
}

void constant(double c, N_Vector z) {
  std::fill(data(z), data(z) + length(z), c);
}

void product(N_Vector x, N_Vector y, N_Vector z) {
  const double* xs = data(x);
  const double* ys = data(y);
  double* zs = data(z);
  const Index n = length(x);
#pragma omp simd
  for (Index i = 0; i < n; ++i) zs[i] = xs[i] * ys[i];
}

void divide(N_Vector x, N_Vector y, N_Vector z) {
  const double* xs = data(x);
  const double* ys = data(y);
  double* zs = data(z);
  const Index n = length(x);
#pragma omp simd
  for (Index i = 0; i < n; ++i) zs[i] = xs[i] / ys[i];
}

void scale(double c, N_Vector x, N_Vector z) {
  const double* xs = data(x);
  double* zs = data(z);
  const Index n = length(x);
#pragma omp simd
  for (Index i = 0; i < n; ++i) zs[i] = c * xs[i];
}

void absolute(N_Vector x, N_Vector z) {
  const double* xs = data(x);
  double* zs = data(z);
  const Index n = length(x);
#pragma omp simd
  for (Index i = 0; i < n; ++i) zs[i] = std::abs(xs[i]);
}

void inverse(N_Vector x, N_Vector z) {
  const double* xs = data(x);
  double* zs = data(z);
  const Index n = length(x);
#pragma omp simd
  for (Index i = 0; i < n; ++i) zs[i] = 1.0 / xs[i];
}

void addConstant(N_Vector x, double b, N_Vector z) {
  const double* xs = data(x);
  double* zs = data(z);
  const Index n = length(x);
#pragma omp simd
  for (Index i = 0; i < n; ++i) zs[i] = xs[i] + b;
}

double dotProduct(N_Vector x, N_Vector y) {
  const double* xs = data(x);
  const double* ys = data(y);
  const Index n = length(x);
  double sum = 0.0;
#pragma omp simd reduction(+ : sum)
  for (Index i = 0; i < n; ++i) sum += xs[i] * ys[i];
  return sum;
}

double maxNorm(N_Vector x) {
  const double* xs = data(x);
  const Index n = length(x);
  double largest = 0.0;
#pragma omp simd reduction(max : largest)
  for (Index i = 0; i < n; ++i) largest = std::max(largest, std::abs(xs[i]));
  return largest;
}

double weightedSquareSum(N_Vector x, N_Vector w) {
  const double* xs = data(x);
  const double* ws = data(w);
  const Index n = length(x);
  double sum = 0.0;
#pragma omp simd reduction(+ : sum)
  for (Index i = 0; i < n; ++i) sum += (xs[i] * ws[i]) * (xs[i] * ws[i]);
  return sum;
}

double weightedSquareSumMask(N_Vector x, N_Vector w, N_Vector id) {
  const double* xs = data(x);
  const double* ws = data(w);
  const double* ids = data(id);
  const Index n = length(x);
  double sum = 0.0;
#pragma omp simd reduction(+ : sum)
  for (Index i = 0; i < n; ++i) sum += ids[i] > 0.0 ? (xs[i] * ws[i]) * (xs[i] * ws[i]) : 0.0;
  return sum;
}

double weightedRmsNorm(N_Vector x, N_Vector w) {
  return std::sqrt(weightedSquareSum(x, w) / static_cast<double>(length(x)));
}

double weightedRmsNormMask(N_Vector x, N_Vector w, N_Vector id) {
  return std::sqrt(weightedSquareSumMask(x, w, id) / static_cast<double>(length(x)));
}

double weightedL2Norm(N_Vector x, N_Vector w) {
  return std::sqrt(weightedSquareSum(x, w));
}

double minimum(N_Vector x) {
  const double* xs = data(x);
  const Index n = length(x);
  double smallest = xs[0];
#pragma omp simd reduction(min : smallest)
  for (Index i = 0; i < n; ++i) smallest = std::min(smallest, xs[i]);
  return smallest;
}

double l1Norm(N_Vector x) {
  const double* xs = data(x);
  const Index n = length(x);
  double sum = 0.0;
#pragma omp simd reduction(+ : sum)
  for (Index i = 0; i < n; ++i) sum += std::abs(xs[i]);
  return sum;
}

void compare(double c, N_Vector x, N_Vector z) {
  const double* xs = data(x);
  double* zs = data(z);
  const Index n = length(x);
#pragma omp simd
  for (Index i = 0; i < n; ++i) zs[i] = std::abs(xs[i]) >= c ? 1.0 : 0.0;
}

// z = sum_k c_k X_k; z may be X_0 (SUNDIALS allows that alias only).
int linearCombination(int count, double* c, N_Vector* X, N_Vector z) {
  double* zs = data(z);
  const Index n = length(z);
  if (count < 1) return -1;
  const double* x0 = data(X[0]);
  const double c0 = c[0];
#pragma omp simd
  for (Index i = 0; i < n; ++i) zs[i] = c0 * x0[i];
  for (int k = 1; k < count; ++k) {
    const double* xs = data(X[k]);
    const double ck = c[k];
#pragma omp simd
    for (Index i = 0; i < n; ++i) zs[i] += ck * xs[i];
  }
  return 0;
}

// Z_k = a_k x + Y_k.
int scaleAddMulti(int count, double* a, N_Vector x, N_Vector* Y, N_Vector* Z) {
  const double* xs = data(x);
  const Index n = length(x);
  for (int k = 0; k < count; ++k) {
    const double* ys = data(Y[k]);
    double* zs = data(Z[k]);
    const double ak = a[k];
#pragma omp simd
    for (Index i = 0; i < n; ++i) zs[i] = ak * xs[i] + ys[i];
  }
  return 0;
}

}  // namespace

bool installFastOperations(N_Vector v) {
  if (!v || !v->ops || !v->ops->nvgetvectorid) return false;
  if (N_VGetVectorID(v) != SUNDIALS_NVEC_SERIAL) return false;
  N_Vector_Ops ops = v->ops;
  ops->nvlinearsum = linearSum;
  ops->nvconst = constant;
  ops->nvprod = product;
  ops->nvdiv = divide;
  ops->nvscale = scale;
  ops->nvabs = absolute;
  ops->nvinv = inverse;
  ops->nvaddconst = addConstant;
  ops->nvdotprod = dotProduct;
  ops->nvmaxnorm = maxNorm;
  ops->nvwrmsnorm = weightedRmsNorm;
  ops->nvwrmsnormmask = weightedRmsNormMask;
  ops->nvmin = minimum;
  ops->nvwl2norm = weightedL2Norm;
  ops->nvl1norm = l1Norm;
  ops->nvcompare = compare;
  ops->nvdotprodlocal = dotProduct;
  ops->nvmaxnormlocal = maxNorm;
  ops->nvminlocal = minimum;
  ops->nvl1normlocal = l1Norm;
  ops->nvwsqrsumlocal = weightedSquareSum;
  ops->nvwsqrsummasklocal = weightedSquareSumMask;
  ops->nvlinearcombination = linearCombination;
  ops->nvscaleaddmulti = scaleAddMulti;
  return true;
}

}  // namespace jello
