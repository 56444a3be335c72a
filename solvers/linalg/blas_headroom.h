// OpenBLAS (the BLAS Debian's CHOLMOD calls for supernodal factorizations) allocates a 128 MiB
// work buffer at its first level-3 call and, when that allocation fails, retries forever inside
// the library, deaf to SIGTERM. Under an address-space limit (`ulimit -v`) too tight for it,
// the factorizations refuse instead, saying why.
#pragma once

#include <string>

namespace jello {

// What OpenBLAS needs free before its first call: its buffer and a margin for CHOLMOD.
inline constexpr double kBlasHeadroomMiB = 160.0;

// Why a supernodal factorization cannot run under this process's address-space limit, or an
// empty string (always empty without a limit, and once one factorization has run).
std::string blasHeadroomProblem();

}  // namespace jello
