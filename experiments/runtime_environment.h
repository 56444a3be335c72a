// Settings that OpenBLAS and libgomp (pulled in by CHOLMOD) read once, when they load: a
// program that wants them different must set them and start itself again.
#pragma once

namespace jello {

// Unless the user chose them, sets OMP_WAIT_POLICY=passive (idle OpenMP threads spinning cost
// CHOLMOD's factorization 15-20% on a 2-core machine) and, with pinBlas, OPENBLAS_NUM_THREADS=1,
// then re-executes this program with the same arguments. Returns (doing nothing) when both are
// already set or the re-execution is impossible.
void applyRuntimeEnvironment(char** argv, bool pinBlas);

}  // namespace jello
