/* The end of an MPI test's main(): a check that failed on any process fails the run on every
 * process, so that mpiexec's exit status does not depend on which process failed. */
#ifndef FCM_TEST_MPI_H
#define FCM_TEST_MPI_H

#include "fcm/petsc.h"
#include "test.h"

/* Sums the failed checks over MPI_COMM_WORLD and finalizes PETSc (and MPI): the exit status
 * of main(), 0 when no process failed a check; else 1, or 2 on a process whose own checks
 * failed (their count printed). Collective: every process calls it last. */
static inline int test_mpi_result(void)
{
  int mine = test_failures_, all = 0;
  MPI_Allreduce(&mine, &all, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  fcm_petsc_finalize();
  return all ? TEST_RESULT() + 1 : 0;
}

#endif
