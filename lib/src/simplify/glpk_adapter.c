/* The one file that talks to GLPK: a basic feasible solution of A x = b, x >= 0 with
 * the dual simplex, with GLPK's printing and aborting fenced off.
 *
 * Settings (measured with GLPK 5.0 on the simplification LPs): GLP_DUALP with a zero
 * objective (the all-logical basis is dual feasible, so no phase 1), presolver off and
 * no glp_scale_prob (both returned "optimal" with negative weights), iteration and time
 * limits. The caller supplies orthonormal rows and a right-hand side of mean-1 weights.
 *
 * Fencing: GLPK 5.0 keeps its environment (terminal switch, hooks, memory) in
 * thread-local storage (Debian's libglpk has a TLS segment), so each OpenMP thread has
 * its own and no lock is needed. For the duration of one call we switch terminal output
 * off and install a terminal hook that swallows (and records) every line -- GLPK's fatal
 * error routine turns output back on before printing -- and an error hook that longjmps
 * back here instead of letting GLPK call abort(). After such a jump the thread's GLPK
 * environment is undefined, so it is freed with glp_free_env() as GLPK's manual
 * prescribes (this also frees any other GLPK object of this thread). On return the hooks
 * are uninstalled and the previous terminal switch restored. */
#include "simplify/simplify_impl.h"

#include <glpk.h>
#include <limits.h>
#include <math.h>
#include <setjmp.h>
#include <stdio.h>
#include <string.h>

/* Shared with the hooks; lives in the caller of the function that calls setjmp, so
 * its contents stay determinate after longjmp. */
typedef struct guard {
  jmp_buf jump;
  char text[160]; /* last terminal output, for the failure message */
  size_t len;
} guard;

static int term_hook(void *info, const char *s)
{
  guard *g = info;
  /* Keep the tail of what GLPK prints: its fatal error is the last thing it says. */
  size_t n = strlen(s);
  if (g->len + n >= sizeof g->text) g->len = 0;
  if (n >= sizeof g->text) n = sizeof g->text - 1;
  memcpy(g->text + g->len, s, n);
  g->len += n;
  g->text[g->len] = '\0';
  return 1; /* suppress GLPK's own output */
}

static void error_hook(void *info)
{
  guard *g = info;
  longjmp(g->jump, 1);
}

/* The column data GLPK reads (1-based, as GLPK wants). */
typedef struct problem {
  int rows, cols, lda;
  const double *a, *b;
  const fcm__lp_params *prm;
  int *ind;    /* rows + 1 */
  double *val; /* rows + 1 */
} problem;

/* What a guarded solve found. */
typedef struct outcome {
  int ret, status, iterations;
} outcome;

/* Build and solve; on a GLPK fatal error the error hook jumps back and 0 is returned.
 * No local of this function is read after the jump. */
static int solve_guarded(guard *g, const problem *pb, double *x, outcome *out)
{
  glp_prob *lp;
  glp_smcp parm;
  if (setjmp(g->jump)) {
    glp_free_env();
    return 0;
  }
  lp = glp_create_prob();
  glp_set_obj_dir(lp, GLP_MIN);
  glp_add_rows(lp, pb->rows);
  for (int i = 0; i < pb->rows; i++)
    glp_set_row_bnds(lp, i + 1, GLP_FX, pb->b[i], pb->b[i]);
  glp_add_cols(lp, pb->cols);
  for (int j = 0; j < pb->cols; j++) {
    const double *col = pb->a + (size_t)j * (size_t)pb->lda;
    int len = 0;
    for (int i = 0; i < pb->rows; i++)
      if (col[i] != 0.0) {
        len++;
        pb->ind[len] = i + 1;
        pb->val[len] = col[i];
      }
    glp_set_col_bnds(lp, j + 1, GLP_LO, 0.0, 0.0);
    glp_set_mat_col(lp, j + 1, len, pb->ind, pb->val);
  }
  if (pb->prm->force_failure == 2) /* test hook: a column out of range is a fatal error */
    glp_set_col_bnds(lp, pb->cols + 1, GLP_LO, 0.0, 0.0);
  glp_init_smcp(&parm);
  parm.msg_lev = GLP_MSG_OFF;
  parm.meth = GLP_DUALP;
  parm.presolve = GLP_OFF;
  parm.it_lim = pb->prm->force_failure == 1 ? 0 : pb->prm->it_lim;
  parm.tm_lim = pb->prm->tm_lim > 0.0 && pb->prm->tm_lim < INT_MAX / 1000.0
                    ? (int)ceil(1000.0 * pb->prm->tm_lim)
                    : INT_MAX;
  out->ret = glp_simplex(lp, &parm);
  out->status = glp_get_status(lp);
  out->iterations = glp_get_it_cnt(lp);
  for (int j = 0; j < pb->cols; j++)
    x[j] = glp_get_col_prim(lp, j + 1);
  glp_delete_prob(lp);
  return 1;
}

static const char *ret_name(int ret)
{
  switch (ret) {
  case GLP_EBADB:
    return "invalid initial basis";
  case GLP_ESING:
    return "singular basis matrix";
  case GLP_ECOND:
    return "ill-conditioned basis matrix";
  case GLP_EBOUND:
    return "incorrect bounds";
  case GLP_EFAIL:
    return "solver failure";
  case GLP_EITLIM:
    return "iteration limit reached";
  case GLP_ETMLIM:
    return "time limit reached";
  case GLP_ENOPFS:
    return "no primal feasible solution";
  case GLP_ENODFS:
    return "no dual feasible solution";
  default:
    return "unknown return code";
  }
}

static const char *status_name(int status)
{
  switch (status) {
  case GLP_UNDEF:
    return "undefined";
  case GLP_INFEAS:
    return "infeasible";
  case GLP_NOFEAS:
    return "no feasible solution";
  case GLP_UNBND:
    return "unbounded";
  default:
    return "unknown";
  }
}

fcm_status fcm__simplify_lp_solve(fcm_ctx *ctx, int rows, int cols, const double *a, int lda,
                                  const double *b, const fcm__lp_params *prm, double *x,
                                  fcm__lp_report *rep)
{
  fcm_status st = FCM_OK;
  guard g;
  problem pb = {rows, cols, lda, a, b, prm, NULL, NULL};
  outcome res = {0, 0, 0};
  memset(rep, 0, sizeof *rep);
  memset(&g, 0, sizeof g);
  FCM_CHECK(rows >= 1 && cols >= 1 && lda >= rows, ctx, FCM_ERR_INTERNAL,
            "simplify LP: rows = %d, cols = %d, lda = %d", rows, cols, lda);
  FCM_ALLOC(ctx, (size_t)rows + 1, pb.ind);
  FCM_ALLOC(ctx, (size_t)rows + 1, pb.val);

  const int old_out = glp_term_out(GLP_OFF);
  glp_term_hook(term_hook, &g);
  glp_error_hook(error_hook, &g);
  const int completed = solve_guarded(&g, &pb, x, &res);
  glp_error_hook(NULL, NULL);
  glp_term_hook(NULL, NULL);
  glp_term_out(old_out);

  rep->iterations = res.iterations;
  if (!completed) {
    rep->reason = FCM_SIMPLIFY_REASON_LP_ERROR;
    /* GLPK's message ends with "Error detected in file ... at line ..."; keep one line. */
    for (size_t i = 0; i < g.len; i++)
      if (g.text[i] == '\n') g.text[i] = ' ';
    while (g.len > 0 && g.text[g.len - 1] == ' ')
      g.text[--g.len] = '\0';
    snprintf(rep->message, sizeof rep->message, "GLPK fatal error: %.130s", g.text);
  } else if (res.ret != 0) {
    rep->reason = FCM_SIMPLIFY_REASON_LP;
    snprintf(rep->message, sizeof rep->message,
             "GLPK dual simplex: %s (code %d) after %d iterations", ret_name(res.ret), res.ret,
             res.iterations);
  } else if (res.status != GLP_OPT && res.status != GLP_FEAS) {
    rep->reason = FCM_SIMPLIFY_REASON_LP;
    snprintf(rep->message, sizeof rep->message,
             "GLPK dual simplex: status %s (%d) after %d iterations", status_name(res.status),
             res.status, res.iterations);
  } else {
    rep->ok = 1;
  }
cleanup:
  fcm__free(ctx, pb.ind);
  fcm__free(ctx, pb.val);
  return st;
}
