/* fcm-condition: shared declarations of the conditioning study (Longva et al. 2020, §5.4 /
 * Fig. 5) — the settings, one result row, the study (fcm-condition-study.c) and its output
 * (fcm-condition-output.c). fcm-condition.c parses the options and runs the study. */
#ifndef FCM_CONDITION_STUDY_H
#define FCM_CONDITION_STUDY_H

#include <fcm/core.h>
#include <fcm/element.h>
#include <fcm/fem.h>
#include <fcm/mesh.h>
#include <fcm/solve.h>

#define PROG          "fcm-condition"
#define MAX_FRACTIONS 64

/** The preconditioners compared; PREC_EXACT (S = P^-1, the ideal preconditioner built from
 *  P) is not among the defaults: it separates what no preconditioner built from P removes
 *  (the indefiniteness of A relative to P) from what Schwarz leaves. */
enum { PREC_NONE, PREC_JACOBI, PREC_SCHWARZ, PREC_SCHWARZ_PAPER, PREC_EXACT, PREC_COUNT };
/** The preconditioners run by default: the four of the paper's Fig. 5. */
#define PREC_DEFAULT_COUNT PREC_EXACT
/** Names of the preconditioners, as on the command line and in the CSV. */
extern const char *const prec_names[PREC_COUNT];
/** Names of the tangent models in the order of fcm_fictitious_model ("projected", "linear",
 *  "exact"; NULL-terminated), as on the command line and in the CSV. */
extern const char *const tangent_model_names[FCM_FICTITIOUS_MODEL_COUNT + 1];

/** The study's settings (fcm-condition.c fills them from the command line). */
typedef struct config {
  fcm_element_type elements[4];
  int num_elements;
  double fractions[MAX_FRACTIONS];
  int num_fractions;
  int precs[PREC_COUNT];
  int num_precs;
  int stab_on, stab_off; /* which stabilization settings to run */
  double alpha;          /* stabilization weight factor when on */
  fcm_stabilization_mode stab_mode;
  double theta;   /* Schwarz: cut cells with phi < theta get a block */
  double epsilon; /* Schwarz eigenvalue threshold */
  int simplify;
  int stiffness_strength; /* strength of the stiffness rules, FCM_DEFAULT: the element's */
  int project;            /* 1: PSD-projected material tangent */
  int fictitious;         /* fcm_fictitious_model of the stabilization points */
  int pc_tangent;         /* fcm_fictitious_model: tangent of the preconditioners' matrix */
  double density, young, poisson, dt;
  double u_scale; /* u(X) = u_scale X_1 (1, 1, -1) */
  double rtol;
  int minres_max;
  const char *csv, *png;
  int quick;
} config;

/** One measured system: kappa of S A and the MINRES solve for one preconditioner. */
typedef struct result {
  fcm_element_type element;
  int prec;
  double alpha; /* 0: no stabilization */
  double phi_nominal, phi_min;
  double kappa, lmin_abs, lmax_abs;
  fcm_index negative;
  fcm_index dofs;
  fcm_index blocks, clamped;
  int iterations;
  fcm_krylov_reason reason;
  double true_residual;
} result;

/** All preconditioners for one (element, fraction phi, stabilization weight alpha; 0: off):
 *  appends one result per preconditioner in `c` to res[*nres...] and advances *nres; progress
 *  on stderr. */
fcm_status condition_run_case(fcm_ctx *ctx, const config *c, fcm_mesh *mesh, double phi,
                              double alpha, result *res, int *nres);

/** kappa and MINRES tables on stdout: one row per (element, stabilization, preconditioner),
 *  one column per fraction. */
void condition_print_tables(const config *c, const result *res, int nres);

/** The results as CSV at `path`, written atomically; 1 on success, 0 (message on stderr) on
 *  failure. */
int condition_write_csv(const char *path, const config *c, const result *res, int nres);

/** kappa against phi plotted with gnuplot into the PNG `path` (atomically); without gnuplot a
 *  message and success. 1 on success, 0 (message on stderr) on failure. */
int condition_write_png(const config *c, const char *path, const result *res, int nres);

#endif
