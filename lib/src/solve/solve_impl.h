/* solve module internals: what the Krylov, Jacobi and Schwarz files share.
 * Not installed. */
#ifndef FCM_SOLVE_IMPL_H
#define FCM_SOLVE_IMPL_H

#include "core/core_impl.h"
#include "fcm/solve.h"
#include "la/la_impl.h"

/* Rows (or blocks) below this count are processed by one thread. */
#define FCM__SOLVE_PARALLEL_MIN 4096

#endif /* FCM_SOLVE_IMPL_H */
