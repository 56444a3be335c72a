// Faster elementwise operations for SUNDIALS' serial N_Vector. Profiled on 1 s of jello.w under
// CVODE Adams, 83% of the time was inside libsundials_cvode and 31% in one function,
// N_VWSqrSumLocal_Serial: Debian's build leaves the vector loops scalar (a sum of squares is a
// reduction the compiler may not reorder), and CVODE calls them several times per internal step
// on vectors of 6n entries. installFastOperations replaces the vector's operation table entries
// for the operations CVODE, its fixed-point solver and SPGMR use most with loops of our own,
// compiled with the project's flags, whose reductions are vectorized (`omp simd`): the same
// values up to the order of summation. Clones (N_VClone) copy the table, so every vector CVODE
// makes from the one given inherits them. The rest of the table is SUNDIALS' own.
#pragma once

#include <sundials/sundials_nvector.h>

namespace jello {

// v: a serial vector (N_VNew_Serial or a clone of one). Returns false, changing nothing, for any
// other kind of vector.
bool installFastOperations(N_Vector v);

}  // namespace jello
