// The hot loops' entry points are compiled for three levels of x86-64 and the best the CPU has
// is chosen when the program loads (GCC's target_clones, an ifunc): a default build runs on any
// x86-64 and still vectorizes the spring forces, the matrix-free product and the kept factor's
// substitutions with AVX2 or AVX-512 where present (a generic build without them is several
// times slower: solvers/README.md, "Portable builds"). A native build (JELLO_NATIVE, -march=native:
// what the benchmarks and the README's speed figures use) and clang (the fuzzers) compile them
// once, for their target; so does a sanitized build, which is how CI tests the generic path the
// host never picks. `flatten` inlines every call an entry point makes into each clone, so the
// kernels under it are compiled for the clone's level too.
#pragma once

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && \
    !defined(JELLO_NATIVE_BUILD) && !defined(__SANITIZE_ADDRESS__) &&  \
    !defined(__SANITIZE_THREAD__)
#define JELLO_VECTOR_CLONES \
  __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default"), flatten))
#else
#define JELLO_VECTOR_CLONES
#endif
