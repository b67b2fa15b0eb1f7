/* petsc module: PETSc's initialization and finalization, the error and cross-process
 * agreement helpers, the per-problem options prefix and the options' defaults. The design of
 * the module: lib/docs/petsc_backend.md. */
#include "petsc/petsc_impl.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

fcm_status fcm__petsc_error(fcm_ctx *ctx, PetscErrorCode ierr, const char *call, const char *file,
                            int line, const char *func)
{
  const char *text = NULL;
  char *specific = NULL;
  PetscErrorMessage((int)ierr, &text, &specific);
  return fcm__error(ctx, FCM_ERR_INTERNAL, file, line, func, "petsc: %s failed: %s%s%s (error %d)",
                    call, text ? text : "unknown error", specific && *specific ? ": " : "",
                    specific ? specific : "", (int)ierr);
}

/* Every process learns whether any failed: on failure somewhere, every process returns the
 * status and message of the lowest failing process (the others record it as their error). */
fcm_status fcm__petsc_agree(fcm_ctx *ctx, MPI_Comm comm, fcm_status st)
{
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  int mine = st != FCM_OK ? rank : size, first = size;
  MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm);
  if (first == size) return FCM_OK;
  char msg[1024];
  int code = (int)st;
  memset(msg, 0, sizeof msg);
  if (rank == first) snprintf(msg, sizeof msg, "%s", fcm_ctx_error_message(ctx));
  MPI_Bcast(msg, (int)sizeof msg, MPI_CHAR, first, comm);
  MPI_Bcast(&code, 1, MPI_INT, first, comm);
  if (rank == first) {
    if (size > 1) fcm__error_prefix(ctx, "(on this process)");
    return st;
  }
  return fcm__error(ctx, (fcm_status)code, __FILE__, __LINE__, __func__,
                    "process %d of %d failed: %s", first, size, msg);
}

/* fcm__petsc_agree() on P's communicator; a failure is remembered (P->agreed_fail), so that a
 * process that learnt of it here does not start another fcm__petsc_agree() the others never meet.
 */
fcm_status fcm__petsc_problem_agree(fcm_petsc_problem *P, fcm_status st)
{
  st = fcm__petsc_agree(P->ctx, P->comm, st);
  if (st != FCM_OK) P->agreed_fail = 1;
  return st;
}

/* ---------------------------------------------------------------- init */

/* Problems made so far by this process (every process makes them in the same order: the
 * creators are collective), for the options prefixes. */
static unsigned long fcm_petsc_num_problems = 0;

/* A new problem's options prefix "fcm<k>_" (k = 1, 2, ...). */
void fcm__petsc_set_prefix(fcm_petsc_problem *P)
{
  snprintf(P->prefix, sizeof P->prefix, "fcm%lu_", ++fcm_petsc_num_problems);
}

fcm_status fcm__petsc_adopt_solver(fcm_petsc_problem *P, const fcm_petsc_solver_options *o)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  FCM_CHECK((int)o->partition >= 0 && o->partition < FCM_PETSC_PARTITION_COUNT, ctx, FCM_ERR_ARG,
            "petsc: solver.partition = %d is not a method (0 auto, 1 ptscotch, 2 ordered)",
            (int)o->partition);
  FCM_CHECK(o->rtol > 0.0 && o->rtol < 1.0, ctx, FCM_ERR_ARG,
            "petsc: solver.rtol = %g outside (0, 1)", o->rtol);
  FCM_CHECK(o->max_iterations >= 1, ctx, FCM_ERR_ARG,
            "petsc: solver.max_iterations = %d must be >= 1", o->max_iterations);
  P->opts.solver = *o;
  P->opts.solver.petsc_options = NULL;
  if (o->petsc_options) {
    const size_t len = strlen(o->petsc_options);
    P->petsc_options = fcm__calloc(ctx, len + 1, 1);
    FCM_CHECK(P->petsc_options, ctx, FCM_ERR_ALLOC, "petsc: out of memory (options string)");
    memcpy(P->petsc_options, o->petsc_options, len);
  }
cleanup:
  return st;
}

static int fcm_petsc_started_mpi = 0;
static int fcm_petsc_pushed_handler = 0; /* fcm_petsc_initialize() pushed PETSc's error handler */

fcm_status fcm_petsc_initialize(fcm_ctx *ctx, int *argc, char ***argv)
{
  fcm_status st = FCM_OK;
  int mpi_on = 0;
  PetscBool on = PETSC_FALSE;
  MPI_Initialized(&mpi_on);
  fcm_petsc_started_mpi = !mpi_on;
  PCALL(ctx, PetscInitialized(&on));
  if (!on) {
    PetscErrorCode ierr = PetscInitialize(argc, argv, NULL, NULL);
    FCM_CHECK(ierr == 0, ctx, FCM_ERR_INTERNAL, "petsc: PetscInitialize failed (error %d)",
              (int)ierr);
    /* PETSc's default handler prints a traceback on stderr at every error; a library prints
     * nothing unasked: the error comes back as the fcm error of the failed call, with PETSc's
     * message (fcm__petsc_error()). A program that initialized PETSc itself keeps its own
     * handler. */
    ierr = PetscPushErrorHandler(PetscReturnErrorHandler, NULL);
    FCM_CHECK(ierr == 0, ctx, FCM_ERR_INTERNAL, "petsc: PetscPushErrorHandler failed (error %d)",
              (int)ierr);
    fcm_petsc_pushed_handler = 1;
  }
cleanup:
  return st;
}

void fcm_petsc_finalize(void)
{
  PetscBool on = PETSC_FALSE;
  if (PetscInitialized(&on) == 0 && on) {
    if (fcm_petsc_pushed_handler) PetscPopErrorHandler();
    fcm_petsc_pushed_handler = 0;
    PetscFinalize();
  }
}

const char *fcm_petsc_partition_name(fcm_petsc_partition p)
{
  switch (p) {
  case FCM_PETSC_PARTITION_AUTO:
    return "auto";
  case FCM_PETSC_PARTITION_PTSCOTCH:
    return "ptscotch";
  case FCM_PETSC_PARTITION_ORDERED:
    return "ordered";
  default:
    return "invalid";
  }
}

fcm_petsc_solver_options fcm_petsc_solver_options_default(void)
{
  fcm_petsc_solver_options o;
  memset(&o, 0, sizeof o);
  o.partition = FCM_PETSC_PARTITION_AUTO;
  o.petsc_options = NULL;
  o.rtol = 1e-10;
  o.max_iterations = 10000;
  return o;
}

fcm_petsc_options fcm_petsc_options_default(void)
{
  fcm_petsc_options o;
  memset(&o, 0, sizeof o);
  o.kind = FCM_INTEGRATOR_BACKWARD_EULER;
  o.dt = 1.0 / 60.0;
  o.solver = fcm_petsc_solver_options_default();
  o.rules = fcm_cell_rules_options_default();
  o.assembly = fcm_assembly_options_default();
  return o;
}
