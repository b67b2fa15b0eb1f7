/* The claims of Longva et al. 2020, Fig. 5, on fcm-condition's systems (4x4x4 grid, box
 * [0,1+eps/3]^3, smallest volume fraction phi = eps^3), at phi = 1 and phi = 1e-12 (claims
 * 1-4) and on the whole sweep 1..1e-12 (claims 5-6):
 * 1. quadratic elements (Tet10, Hex20) with stabilization (alpha 1e-6) and Schwarz:
 *    kappa(S A) at 1e-12 is at most 10x kappa at 1;
 * 2. the same without stabilization: kappa > 1e10 (the experiment discriminates);
 * 3. Hex20 without stabilization, where block eigenvalues get clamped: eq. 14 as printed
 *    (schwarz-paper) is no better than the clamp (schwarz);
 * 4. linear elements (Tet4, Hex8) without stabilization: Jacobi keeps kappa within 10x of its
 *    value at 1, while unpreconditioned kappa exceeds 1e10.
 * 5. the default unprojected tangent (issue 19: the fictitious stabilization points carry the
 *    PSD-projected tangent, the physical points the exact one, and the Schwarz blocks are
 *    built from P = M + dt^2 K_psd, the PSD-projected tangent, while A stays the Krylov
 *    operator), stabilization and Schwarz: at every fraction of the sweep 1..1e-12,
 *    Tet10 and Hex20, kappa(S A) within 10x of its value at 1 — except where A itself is
 *    numerically singular, kappa(A) > 1e12: the indefinite family A(phi) changes its
 *    inertia along the sweep (Hex20: 146 negative eigenvalues at 1, 156 at 1e-2, 87 at
 *    1e-12), so eigenvalues cross zero between sweep points, and at a crossing kappa(S A) is
 *    unbounded for every SPD S (Sylvester: S^(1/2) A S^(1/2) keeps the inertia of A).
 *    Measured: Hex20 at 1e-2 has kappa(A) = 6.1e12 (kappa(S A) = 799x its value at 1);
 *    at most one such fraction per element is allowed, and there Schwarz must still divide
 *    kappa(A) by 1e3. Measured on the other fractions: at most 6.3x (Tet10) and 5.8x (Hex20).
 *    kappa(A) (a run without preconditioner) is measured only where the bound fails.
 * 6. the same with the blocks built from the exact tangent (--pc-tangent exact, the state
 *    before): the bound fails (Tet10 59x at 1e-9, Hex20 54x at 1e-8), so claim 5 tests the
 *    default's choice.
 * Claims 1-3 use the PSD-projected tangent (A = M + dt^2 K symmetric positive definite, the
 * setting of the authors' FE model by default); with the unprojected SNH tangent at u = X
 * (1,1,-1), A is indefinite, and claim 1 holds there only with the preconditioner built from
 * a PSD tangent (claims 5, 6).
 * Claims 4-6 use the default unprojected tangent. Simplification off (it does not change the
 * claims and costs most of the run time for Hex20); MINRES is skipped (--minres-max 1). One
 * thread: the systems are small, and busy machines make OpenMP barriers slow.
 * PART selects the claims, so that ctest runs them side by side: "1-4", "5" (every other
 * decade, 7 fractions), "5-full" (every decade, 13 fractions; label slow) or "6".
 * Usage: app_condition_claims PATH_TO_fcm-condition WORK_DIR PART */
#define _POSIX_C_SOURCE 200809L
#include "condition_csv.h"

static int run_study(const char *exe, const char *csv, const char *args, cond_row *rows)
{
  char cmd[8192];
  remove(csv);
  snprintf(cmd, sizeof cmd,
           "OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 '%s' %s --simplify off --minres-max 1 "
           "--csv '%s' > /dev/null",
           exe, args, csv);
  int rc = app_run(cmd);
  if (rc != 0) {
    fprintf(stderr, "'%s' exited with %d\n", cmd, rc);
    return 0;
  }
  int n = cond_read(csv, rows, COND_MAX_ROWS);
  TEST_TRUE(n > 0);
  return n > 0 ? n : 0;
}

int main(int argc, char **argv)
{
  if (argc != 4) return 2;
  const char *part = argv[3];
  const int part14 = !strcmp(part, "1-4"), part6 = !strcmp(part, "6");
  const int part5 = !strcmp(part, "5") || !strcmp(part, "5-full");
  if (!part14 && !part5 && !part6) return 2;
  const int nfrac = !strcmp(part, "5-full") ? 13 : 7; /* claim 5: every decade, or every other */
  char csv[1024];
  static cond_row rows[COND_MAX_ROWS], paper[COND_MAX_ROWS];
  snprintf(csv, sizeof csv, "%s/condition-claims-%s.csv", argv[2], part);
  const double lo = 1e-12;
  static const char *const quad[2] = {"tet10", "hex20"};
  char args[1024];
  int n = 0;
  if (part14) {

    /* claims 1 and 2 */
    n = run_study(argv[1], csv,
                  "--project on --elements tet10,hex20 --fractions 1,1e-12 "
                  "--preconditioners schwarz --stabilization on,off",
                  rows);
    TEST_TRUE(n == 2 * 2 * 2);
    for (int e = 0; e < 2; e++) {
      const cond_row *one = cond_find(rows, n, quad[e], "schwarz", 1, 1.0),
                     *on = cond_find(rows, n, quad[e], "schwarz", 1, lo),
                     *off = cond_find(rows, n, quad[e], "schwarz", 0, lo);
      TEST_TRUE(one && on && off);
      if (!one || !on || !off) continue;
      TEST_TRUE(!strcmp(on->tangent, "projected") && on->negative == 0 && on->blocks > 0);
      TEST_NEAR(on->phi_min, lo, 1e-3, 0.0);
      if (!(on->kappa <= 10.0 * one->kappa))
        fprintf(stderr, "%s: stabilized Schwarz kappa %.3e at 1e-12 vs %.3e at 1\n", quad[e],
                on->kappa, one->kappa);
      TEST_TRUE(on->kappa <= 10.0 * one->kappa);
      if (!(off->kappa > 1e10))
        fprintf(stderr, "%s: unstabilized Schwarz kappa %.3e at 1e-12\n", quad[e], off->kappa);
      TEST_TRUE(off->kappa > 1e10);
    }

    /* claim 3 */
    int np = run_study(argv[1], csv,
                       "--project on --elements hex20 --fractions 1e-12 "
                       "--preconditioners schwarz-paper --stabilization off",
                       paper);
    TEST_TRUE(np == 1);
    const cond_row *clamp = cond_find(rows, n, "hex20", "schwarz", 0, lo),
                   *pap = cond_find(paper, np, "hex20", "schwarz-paper", 0, lo);
    TEST_TRUE(clamp && pap);
    if (clamp && pap) {
      TEST_TRUE(clamp->clamped > 0 && pap->clamped == clamp->clamped);
      TEST_TRUE(pap->kappa >= clamp->kappa);
    }

    /* claim 4 */
    n = run_study(argv[1], csv,
                  "--elements tet4,hex8 --fractions 1,1e-12 --preconditioners none,jacobi "
                  "--stabilization off",
                  rows);
    TEST_TRUE(n == 2 * 2 * 2);
    static const char *const lin[2] = {"tet4", "hex8"};
    for (int e = 0; e < 2; e++) {
      const cond_row *one = cond_find(rows, n, lin[e], "jacobi", 0, 1.0),
                     *j = cond_find(rows, n, lin[e], "jacobi", 0, lo),
                     *none = cond_find(rows, n, lin[e], "none", 0, lo);
      TEST_TRUE(one && j && none);
      if (!one || !j || !none) continue;
      if (!(j->kappa <= 10.0 * one->kappa))
        fprintf(stderr, "%s: Jacobi kappa %.3e at 1e-12 vs %.3e at 1\n", lin[e], j->kappa,
                one->kappa);
      TEST_TRUE(j->kappa <= 10.0 * one->kappa);
      TEST_TRUE(none->kappa > 1e10);
    }
  }
  if (part5) {
    /* claim 5: the default unprojected tangent, every fraction of the sweep */
    static cond_row sweep[COND_MAX_ROWS], plain[COND_MAX_ROWS];
    snprintf(args, sizeof args,
             "--project off --elements tet10,hex20 --fractions 1:1e-12:%d "
             "--preconditioners schwarz --stabilization on",
             nfrac);
    n = run_study(argv[1], csv, args, sweep);
    TEST_TRUE(n == 2 * nfrac);
    for (int e = 0; e < 2; e++) {
      const cond_row *one = cond_find(sweep, n, quad[e], "schwarz", 1, 1.0);
      TEST_TRUE(one != NULL);
      if (!one) continue;
      int checked = 0, singular = 0;
      for (int k = 0; k < n; k++) {
        const cond_row *on = &sweep[k];
        if (strcmp(on->element, quad[e])) continue;
        TEST_TRUE(!strcmp(on->tangent, "unprojected") && !strcmp(on->fictitious, "projected") &&
                  !strcmp(on->pc_tangent, "projected") && on->negative > 0);
        TEST_TRUE(on->phi_nominal == 1.0 || on->blocks > 0);
        checked++;
        if (on->kappa <= 10.0 * one->kappa) continue;
        /* Above the bound: is A itself numerically singular, kappa(A) > 1e12? Then an
         * eigenvalue crosses zero there (the inertia changes along the sweep) and no SPD
         * preconditioner lifts it; Schwarz must still remove the cut-cell part. */
        snprintf(args, sizeof args,
                 "--project off --elements %s --fractions %.17g --preconditioners none "
                 "--stabilization on",
                 quad[e], on->phi_nominal);
        const int np2 = run_study(argv[1], csv, args, plain);
        const cond_row *none = np2 == 1 ? &plain[0] : NULL;
        TEST_TRUE(none != NULL);
        if (none && none->kappa > 1e12) {
          singular++;
          TEST_TRUE(none->negative == on->negative); /* an SPD S keeps the inertia of A */
          fprintf(stderr,
                  "%s phi = %g: kappa(A) = %.3e (A numerically singular): bound not asserted; "
                  "Schwarz kappa %.3e = %.0fx its value at 1\n",
                  quad[e], on->phi_nominal, none->kappa, on->kappa, on->kappa / one->kappa);
          TEST_TRUE(on->kappa <= 1e-3 * none->kappa);
        } else {
          fprintf(stderr, "%s unprojected: stabilized Schwarz kappa %.3e at %g vs %.3e at 1%s\n",
                  quad[e], on->kappa, on->phi_nominal, one->kappa,
                  none ? "" : " (kappa(A) not measured)");
          TEST_TRUE(on->kappa <= 10.0 * one->kappa);
        }
      }
      TEST_TRUE(checked == nfrac && singular <= 1);
    }
  }
  if (part6) {
    /* claim 6: built from the exact tangent instead, Schwarz misses the bound (the
     * experiment discriminates the default): Tet10 at 1e-9, Hex20 at 1e-8 */
    for (int e = 0; e < 2; e++) {
      const double at = e == 0 ? 1e-9 : 1e-8;
      snprintf(args, sizeof args,
               "--project off --pc-tangent exact --elements %s --fractions 1,%g "
               "--preconditioners schwarz --stabilization on",
               quad[e], at);
      n = run_study(argv[1], csv, args, rows);
      TEST_TRUE(n == 2);
      const cond_row *one = cond_find(rows, n, quad[e], "schwarz", 1, 1.0),
                     *on = cond_find(rows, n, quad[e], "schwarz", 1, at);
      TEST_TRUE(one && on);
      if (!one || !on) continue;
      TEST_TRUE(!strcmp(on->pc_tangent, "exact"));
      if (!(on->kappa > 10.0 * one->kappa))
        fprintf(stderr, "%s exact-tangent Schwarz: kappa %.3e at %g vs %.3e at 1\n", quad[e],
                on->kappa, at, one->kappa);
      TEST_TRUE(on->kappa > 10.0 * one->kappa);
    }
  }
  remove(csv);
  return TEST_RESULT();
}
