// Threading settings that OpenBLAS and libgomp (pulled in by CHOLMOD) read once, when they
// load: a program that wants them different must set them and start itself again.
//
// At the sizes this project factors (1,536 to 100,000 unknowns) their thread pools only cost:
// CHOLMOD 5.12 is built with 4 OpenMP threads fixed at compile time (CHOLMOD_OMP_NUM_THREADS,
// which OMP_NUM_THREADS does not override; OMP_THREAD_LIMIT does), and OpenBLAS wakes its
// threads for every small BLAS call of the supernodal factorization: on jello.w under implicit
// the single-threaded libraries took half the wall time (and a thirtieth of the system time)
// of their defaults.
#pragma once

#include <string>

namespace jello {

// Unless the user set them, sets OMP_THREAD_LIMIT=1, OPENBLAS_NUM_THREADS=1 and
// OMP_WAIT_POLICY=passive, then re-executes this program with the same arguments. Returns
// (doing nothing) when all are already set or the re-execution is impossible.
void applySolverThreadSettings(char** argv);

// Which BLAS this process loaded (CHOLMOD's supernodal factorization depends on it): the path
// of its shared library, or "none loaded".
std::string loadedBlas();

}  // namespace jello
