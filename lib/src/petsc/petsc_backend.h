/* petsc module: what the layer that chooses the PETSc backend (the scene's runner,
 * lib/src/scene/run_petsc.c) calls to make it: the backend object (fcm__backend,
 * lib/src/fem/fem_backend.h) on the processes of a communicator, the partition of the
 * cells it is handed, and the cross-process agreement. No PETSc type appears here (only MPI's),
 * so the caller compiles without PETSc's headers. */
#ifndef FCM_PETSC_BACKEND_H
#define FCM_PETSC_BACKEND_H

#include "fcm/petsc.h"

#include "embed/embed_impl.h"
#include "fem/fem_backend.h"

/* Every process learns whether any failed: on failure somewhere, every process returns the
 * status and message of the lowest failing process (the others record it as their error).
 * Collective on comm. */
fcm_status fcm__petsc_agree(fcm_ctx *ctx, MPI_Comm comm, fcm_status st);

/* The integrator backend's settings (fcm__petsc_backend_create()). */
typedef struct fcm__petsc_backend_options {
  fcm_petsc_solver_options solver; /* partition and KSP settings (checked) */
  int direct;                      /* 1: MUMPS (Cholesky) instead of the Krylov defaults */
  fcm_material mat;
} fcm__petsc_backend_options;

/* Make the PETSc backend object on the processes of comm (a duplicate of it): agree on st (the
 * caller's local checks so far) and the allocation first, then on the copy of the options;
 * *P is set also when the processes then fail (release it with fcm__petsc_backend_release()).
 * Collective. */
fcm_status fcm__petsc_backend_create(fcm_ctx *ctx, MPI_Comm comm, fcm_status st,
                                     const fcm__petsc_backend_options *o, fcm_petsc_problem **P);

/* Agree on st, then partition the cells of mesh that geom reaches, as fcm_petsc_problem_create()
 * partitions them (mesh and geom are read during the call only). Out: *mask (the cells whose
 * points this process integrates; the caller frees it with fcm__free()), *backend (borrowed,
 * P's: user, reduce and setup for fcm__integrator_attach_backend(), finish for the caller's
 * last agreement) and *exchange (the cells' classification shared between the processes for
 * fcm__cell_rules_create_distributed(); valid until the integrator's setup). Collective. */
fcm_status fcm__petsc_backend_partition(fcm_petsc_problem *P, fcm_status st, const fcm_mesh *mesh,
                                        const fcm_geometry *geom, unsigned char **mask,
                                        fcm__backend *backend, fcm__rules_exchange *exchange);

/* Drop the creator's reference to P (the integrators hold their own). NULL: nothing. */
void fcm__petsc_backend_release(fcm_petsc_problem *P);

/* 1 when b is a backend of fcm__petsc_backend_partition() (then *traffic, may be NULL, gets its
 * communication counters on this process and *comm, may be NULL, its communicator); else 0. */
int fcm__petsc_backend_info(const fcm__backend *b, fcm_petsc_traffic *traffic, MPI_Comm *comm);

/* P destroys mesh with itself (a mesh the caller built for fcm_petsc_problem_create()). */
void fcm__petsc_problem_adopt_mesh(fcm_petsc_problem *P, fcm_mesh *mesh);

#endif /* FCM_PETSC_BACKEND_H */
