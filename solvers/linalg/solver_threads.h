// Threading settings of OpenBLAS and libgomp (pulled in by CHOLMOD), made by their own calls
// as a program starts: no environment to export, no second start of the program.
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

// One thread for each, unless the user chose (OPENBLAS_NUM_THREADS, OMP_THREAD_LIMIT or
// OMP_NUM_THREADS set): OpenBLAS through openblas_set_num_threads(1), libgomp through
// omp_set_max_active_levels(0), under which every parallel region, CHOLMOD's fixed-width ones
// included, runs on the thread that meets it. Both are looked up in the loaded libraries (a
// BLAS other than OpenBLAS has no such call and is left as it is). Until the first
// factorization; the programs call it first thing in main. Earlier versions exported the
// variables and started the program again, which loaded every library twice and, under
// mpirun, failed in MPI_Init.
void applySolverThreadSettings();

// What applySolverThreadSettings set: "openblas 1 thread; openmp serial", for the sidecars.
std::string solverThreadSettings();

// Which BLAS this process loaded (CHOLMOD's supernodal factorization depends on it): the path
// of its shared library, or "none loaded".
std::string loadedBlas();

}  // namespace jello
