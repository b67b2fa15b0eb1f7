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
 * 5. the default unprojected tangent (the fictitious stabilization points carry the
 *    PSD-projected tangent, the physical points the exact one, and the Schwarz blocks are
 *    built from P = M + dt^2 K_psd, the PSD-projected tangent, while A stays the Krylov
 *    operator), stabilization and Schwarz: at every fraction of the sweep 1..1e-12,
 *    Tet10 and Hex20, kappa(S A) within 10x of its value at 1 — except where A itself is
 *    near-singular relative to P, i.e. where the ideal preconditioner built from P,
 *    S = P^-1 (fcm-condition's "exact"), misses the bound too: kappa(P^-1 A) > 10x its
 *    value at 1. The indefinite family A(phi) changes its inertia along the sweep (Hex20
 *    with the default simplification: 146 negative eigenvalues at 1, 159 at 1e-1, 87 at
 *    1e-12), so eigenvalues of the pencil (A, P) cross zero between sweep points; near a
 *    crossing kappa(S A) grows for every SPD S spectrally equivalent to P^-1 (S^(1/2) A
 *    S^(1/2) keeps the inertia of A), and which sampled fraction lands near one depends on
 *    small changes of A, e.g. the cut-cell quadrature. At most one such fraction per
 *    element and sweep is allowed; there S A and P^-1 A must have the same inertia and
 *    Schwarz must stay within 10x of P^-1 (both relative to their values at 1).
 *    kappa(P^-1 A) is measured only where the bound fails. Measured
 *    (lib/docs/conditioning_defaults.md): Hex20 at 1e-1 with the default simplification
 *    27x (P^-1: 44x), at 1e-3 without 18x (P^-1: 70x); elsewhere at most 6.3x (Tet10) and
 *    8.8x (Hex20).
 * 6. the same with the blocks built from the exact tangent (--pc-tangent exact): the bound
 *    fails (Tet10 59x at 1e-9, Hex20 54x at 1e-8, 70x with the default simplification), so
 *    claim 5 tests the default's choice.
 * Claims 1-3 use the PSD-projected tangent (A = M + dt^2 K symmetric positive definite, the
 * setting of the authors' FE model by default); with the unprojected SNH tangent at u = X
 * (1,1,-1), A is indefinite, and claim 1 holds there only with the preconditioner built from
 * a PSD tangent (claims 5, 6).
 * Claims 4-6 use the default unprojected tangent. Every claim runs without simplification
 * and with the default one (claim 5 on different fractions in the default run); MINRES is
 * skipped (--minres-max 1). One thread: the systems are small, and busy machines make OpenMP
 * barriers slow.
 * PART selects the claims, so that ctest runs them side by side: "1-4", "5" (without
 * simplification, every other decade: 1, 1e-2, ..., 1e-12), "5-simplify" (default
 * simplification, the decades in between: 1, 1e-1, ..., 1e-11), "5-full" (both, every
 * decade; label slow) or "6".
 * Usage: app_condition_claims PATH_TO_fcm-condition WORK_DIR PART */
#define _POSIX_C_SOURCE 200809L
#include "condition_csv.h"

/* One fcm-condition run with `args` (they choose the simplification), one thread, MINRES
 * skipped; the CSV rows into `rows`, their number returned (0 on failure). */
static int run_study(const char *exe, const char *csv, const char *args, cond_row *rows)
{
  char cmd[8192];
  remove(csv);
  snprintf(cmd, sizeof cmd,
           "OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 '%s' %s --minres-max 1 --csv '%s' > /dev/null",
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

/* Claim 5 on one sweep: `simplify` is "--simplify off" or "" (the default), `fractions` the
 * list starting at 1 with `nfrac` entries. Where stabilized Schwarz misses 10x its value at
 * 1, the ideal preconditioner S = P^-1 ("exact") is run at 1 and there: the fraction is
 * exempt only when it misses the bound too (A near-singular relative to P), and there Schwarz
 * must stay within 10x of it (both normalized at 1); at most one exempt fraction per element. */
static void claim5(const char *exe, const char *csv, const char *simplify, const char *fractions,
                   int nfrac)
{
  static const char *const quad[2] = {"tet10", "hex20"};
  static cond_row sweep[COND_MAX_ROWS], ideal[COND_MAX_ROWS];
  const char *label = *simplify ? simplify : "default simplification";
  char args[1024];
  snprintf(args, sizeof args,
           "%s --project off --elements tet10,hex20 --fractions %s --preconditioners schwarz "
           "--stabilization on",
           simplify, fractions);
  const int n = run_study(exe, csv, args, sweep);
  TEST_TRUE(n == 2 * nfrac);
  for (int e = 0; e < 2; e++) {
    const cond_row *one = cond_find(sweep, n, quad[e], "schwarz", 1, 1.0);
    TEST_TRUE(one != NULL);
    if (!one) continue;
    int checked = 0, exempt = 0;
    for (int k = 0; k < n; k++) {
      const cond_row *on = &sweep[k];
      if (strcmp(on->element, quad[e])) continue;
      TEST_TRUE(!strcmp(on->tangent, "unprojected") && !strcmp(on->fictitious, "projected") &&
                !strcmp(on->pc_tangent, "projected") && on->negative > 0);
      TEST_TRUE(on->phi_nominal == 1.0 || on->blocks > 0);
      checked++;
      if (on->kappa <= 10.0 * one->kappa) continue;
      snprintf(args, sizeof args,
               "%s --project off --elements %s --fractions 1,%.17g --preconditioners exact "
               "--stabilization on",
               simplify, quad[e], on->phi_nominal);
      const int ni = run_study(exe, csv, args, ideal);
      const cond_row *x1 = cond_find(ideal, ni, quad[e], "exact", 1, 1.0),
                     *x = cond_find(ideal, ni, quad[e], "exact", 1, on->phi_nominal);
      TEST_TRUE(ni == 2 && x1 && x);
      if (x1 && x && x->kappa > 10.0 * x1->kappa) {
        exempt++;
        /* S A and P^-1 A both have the inertia of A (Sylvester) */
        TEST_TRUE(x->negative == on->negative);
        if (!(on->kappa / one->kappa <= 10.0 * x->kappa / x1->kappa))
          fprintf(stderr,
                  "%s (%s) phi = %g: Schwarz kappa %.3e = %.1fx its value at 1, P^-1: %.3e = "
                  "%.1fx\n",
                  quad[e], label, on->phi_nominal, on->kappa, on->kappa / one->kappa, x->kappa,
                  x->kappa / x1->kappa);
        TEST_TRUE(on->kappa / one->kappa <= 10.0 * x->kappa / x1->kappa);
      } else {
        fprintf(stderr,
                "%s (%s): stabilized Schwarz kappa %.3e at %g vs %.3e at 1; P^-1: %.3e vs %.3e\n",
                quad[e], label, on->kappa, on->phi_nominal, one->kappa, x ? x->kappa : NAN,
                x1 ? x1->kappa : NAN);
        TEST_TRUE(on->kappa <= 10.0 * one->kappa);
      }
    }
    TEST_TRUE(checked == nfrac && exempt <= 1);
  }
}

int main(int argc, char **argv)
{
  if (argc != 4) return 2;
  const char *part = argv[3];
  const int part14 = !strcmp(part, "1-4"), part6 = !strcmp(part, "6");
  const int part5 = !strcmp(part, "5"), part5s = !strcmp(part, "5-simplify"),
            part5f = !strcmp(part, "5-full");
  if (!part14 && !part5 && !part5s && !part5f && !part6) return 2;
  char csv[1024];
  static cond_row rows[COND_MAX_ROWS], paper[COND_MAX_ROWS];
  snprintf(csv, sizeof csv, "%s/condition-claims-%s.csv", argv[2], part);
  const double lo = 1e-12;
  static const char *const quad[2] = {"tet10", "hex20"};
  /* claims 1-4 and 6 without and with the default simplification */
  static const char *const simplify[2] = {"--simplify off", ""};
  char args[1024];
  int n = 0;
  for (int sm = 0; sm < 2 && part14; sm++) {

    /* claims 1 and 2 */
    snprintf(args, sizeof args,
             "%s --project on --elements tet10,hex20 --fractions 1,1e-12 "
             "--preconditioners schwarz --stabilization on,off",
             simplify[sm]);
    n = run_study(argv[1], csv, args, rows);
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
    snprintf(args, sizeof args,
             "%s --project on --elements hex20 --fractions 1e-12 "
             "--preconditioners schwarz-paper --stabilization off",
             simplify[sm]);
    int np = run_study(argv[1], csv, args, paper);
    TEST_TRUE(np == 1);
    const cond_row *clamp = cond_find(rows, n, "hex20", "schwarz", 0, lo),
                   *pap = cond_find(paper, np, "hex20", "schwarz-paper", 0, lo);
    TEST_TRUE(clamp && pap);
    if (clamp && pap) {
      TEST_TRUE(clamp->clamped > 0 && pap->clamped == clamp->clamped);
      TEST_TRUE(pap->kappa >= clamp->kappa);
    }

    /* claim 4 */
    snprintf(args, sizeof args,
             "%s --elements tet4,hex8 --fractions 1,1e-12 --preconditioners none,jacobi "
             "--stabilization off",
             simplify[sm]);
    n = run_study(argv[1], csv, args, rows);
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
  /* claim 5: the default unprojected tangent; every other decade without simplification
   * (1, 1e-2, ..., 1e-12), the decades in between with the default one (1, 1e-1, ...,
   * 1e-11), every decade with both under slow */
  static const char *const even = "1,1e-2,1e-4,1e-6,1e-8,1e-10,1e-12",
                           *odd = "1,1e-1,1e-3,1e-5,1e-7,1e-9,1e-11", *all = "1:1e-12:13";
  if (part5) claim5(argv[1], csv, simplify[0], even, 7);
  if (part5s) claim5(argv[1], csv, simplify[1], odd, 7);
  for (int sm = 0; sm < 2 && part5f; sm++)
    claim5(argv[1], csv, simplify[sm], all, 13);
  for (int sm = 0; sm < 2 && part6; sm++) {
    /* claim 6: built from the exact tangent instead, Schwarz misses the bound (the
     * experiment discriminates the default): Tet10 at 1e-9, Hex20 at 1e-8 */
    for (int e = 0; e < 2; e++) {
      const double at = e == 0 ? 1e-9 : 1e-8;
      snprintf(args, sizeof args,
               "%s --project off --pc-tangent exact --elements %s --fractions 1,%g "
               "--preconditioners schwarz --stabilization on",
               simplify[sm], quad[e], at);
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
