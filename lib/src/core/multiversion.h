/* Per-CPU clones of hot loops: with FCM_MULTIVERSION defined for the source (its module's
 * sources.cmake passes it when the CMake option FCM_MULTIVERSION is on), on x86-64 with GCC and
 * glibc, a function marked FCM_MULTIVERSION_CLONES is compiled for x86-64-v4 (AVX-512),
 * x86-64-v3 (AVX2 + FMA) and the baseline, and the loader picks the clone for the CPU (an
 * ifunc). Elsewhere the mark is empty and the function is compiled once. Without
 * -ffp-contract=fast and with ISO C's strict evaluation, the clones compute the same roundings
 * as the baseline (wider vectors, no fused multiply-adds, no reassociated sums). */
#ifndef FCM_CORE_MULTIVERSION_H
#define FCM_CORE_MULTIVERSION_H

#include <limits.h> /* any C library header: defines __GLIBC__ on glibc */

#if defined(FCM_MULTIVERSION) && defined(__x86_64__) && defined(__GNUC__) &&                       \
    !defined(__clang__) && __GNUC__ >= 11 && defined(__GLIBC__)
#define FCM_MULTIVERSION_CLONES                                                                    \
  __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#define FCM_MULTIVERSION_ON 1
#else
#define FCM_MULTIVERSION_CLONES
#define FCM_MULTIVERSION_ON 0
#endif

#endif
