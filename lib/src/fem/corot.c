/* The element-corotated linear kernel (FCM_MATERIAL_COROTATED_LINEAR; Dick et al. 2011 §5,
 * stiffness warping): one element's energy, force and tangent from its linear stiffness K
 * (kept by the assembly workspace) and one rotation R, the polar rotation of the deformation
 * gradient F averaged over the element's material (its authentic quadrature points; on an
 * affine element that is F at the centroid). In a cut cell the fictitious part's nodes move
 * almost freely: F at the centroid, which may lie there, would turn the material by the
 * fictitious part's motion, which also slows Newton's convergence (below).
 *
 * With x_a = X_a + u_a, c and c' the means of the nodes X_a and x_a (Dick's centres of mass)
 * and y_a = R^T (x_a - c'), the element's displacement in its rotated frame is
 * d_a = y_a - (X_a - c) and its energy E = 1/2 d^T K d (K ignores translations: the centring
 * changes E only by rounding, and keeps a rigid motion's d at rounding level). The force is
 * E's exact gradient: with F = R S (S symmetric), dR = R [w]x and
 * [w]x S + S [w]x = [(tr S I - S) w]x = the skew part of 2 R^T dF, so that
 *   dE/dx_b = R ((K d)_b - z x g_b),  z = (tr S I - S)^{-1} m,  m = sum_a y_a x (K d)_a,
 * g_b the mean physical gradient of node b's shape function (F = sum_a x_a g_a^T). m is the
 * moment of the element's elastic forces in its rotated frame, of second order in d (K's rigid
 * rotations carry no force): the z term is the small correction that makes the force a
 * gradient (Dick's warped force R K d drops it).
 *
 * The tangent (kd->corot_exact) is E's exact Hessian, or the warped [R] K [R]^T where the
 * material asks for a positive semi-definite one (project_psd, as the Newton loop's projection
 * fallback does) or the caller for it (fcm__assembly_corot_tangent(): the integrator assembles
 * it at the start of each substep and keeps it with solvers other than the direct one). The
 * warped tangent drops the terms of dR/dx, of the order of the element's stress, so that
 * Newton converges only linearly on it, at a rate of the order of the strains, and slowly where
 * a thin part carries a heavy one through a large rotation. The exact Hessian, with u_b =
 * R^T dx_b the nodal variation in the rotated frame (translations drop out: K ignores them and
 * the g_b sum to zero) and q_b = (K d)_b - z x g_b the rotated force, is [R] (K + D) [R]^T with
 *   dd_a = u_a + [y_a]x w,      w = A^{-1} sum_b [g_b]x u_b   (A = tr S I - S),
 *   dm = -h(Kd) u - C w + h(y) K dd,   C = sum_a [(Kd)_a]x [y_a]x,
 *   dA z = (sum_b g_b . u_b) z - sum_b (g_b . z) u_b - [S z]x w,
 *   dz = A^{-1} (dm - dA z),
 *   D u = K s(y) w - s(q) w + s(g) dz,
 * where s(v) stacks the nodes' [v_a]x in a column (3 nn x 3) and h(v) = -s(v)^T in a row: a
 * rank-6 correction U V^T of K (U = [K s(y) - s(q), s(g)], V^T = [dw/du; dz/du]), symmetric
 * as a Hessian is (symmetrized to rounding here). It may be indefinite (compression, or a
 * nearly degenerate element): the integrator's Cholesky factorization then fails and its
 * Newton loop takes the warped tangent for the rest of the substep (an LU factorization, the
 * direct_method UMFPACK or a distributed backend's, solves with it; a direction that does not
 * descend is then computed again on the warped tangent). */
#include "fem/kernels_impl.h"
#include "la/mat3.h"

#include <math.h>
#include <string.h>

/* Floor of the eigenvalues s_i + s_j of tr S I - S (signed singular values: >= 0; zero where
 * R is not differentiable, e.g. F = -I), as the corotated material's twist floor. */
#define COROT_FLOOR FCM__COROTATED_TWIST_FLOOR

/* y = K d for the symmetric element matrix given by its upper node blocks Kp. */
static void packed_matvec(int nn, const double *Kp, const double *d, double *y)
{
  memset(y, 0, sizeof *y * 3 * (size_t)nn);
  for (int a = 0; a < nn; a++) {
    const double *da = d + 3 * a;
    double *ya = y + 3 * a;
    for (int b = a; b < nn; b++, Kp += 9) {
      const double *db = d + 3 * b;
      ya[0] += Kp[0] * db[0] + Kp[1] * db[1] + Kp[2] * db[2];
      ya[1] += Kp[3] * db[0] + Kp[4] * db[1] + Kp[5] * db[2];
      ya[2] += Kp[6] * db[0] + Kp[7] * db[1] + Kp[8] * db[2];
      if (b == a) continue;
      double *yb = y + 3 * b;
      yb[0] += Kp[0] * da[0] + Kp[3] * da[1] + Kp[6] * da[2];
      yb[1] += Kp[1] * da[0] + Kp[4] * da[1] + Kp[7] * da[2];
      yb[2] += Kp[2] * da[0] + Kp[5] * da[1] + Kp[8] * da[2];
    }
  }
}

static void cross(const double a[3], const double b[3], double c[3])
{
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}

/* The rotation-variant SVD F = U diag(s) V^T (s signed) and R = U V^T. */
typedef struct polar {
  double R[9], V[9], s[3];
} polar;

/* The polar rotation of F into p; 0 for a non-finite F. */
static int polar_rotation(const double F[9], polar *p)
{
  double U[9];
  if (fcm__mat3_svd(F, U, p->s, p->V) < 0) return 0;
  const double *V = p->V;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      p->R[3 * i + j] =
          U[3 * i] * V[3 * j] + U[3 * i + 1] * V[3 * j + 1] + U[3 * i + 2] * V[3 * j + 2];
  return 1;
}

/* z = (tr S I - S)^{-1} m with S = V diag(s) V^T: tr S I - S = V diag(s1 + s2, s0 + s2,
 * s0 + s1) V^T, its eigenvalues floored at COROT_FLOOR. */
static void solve_spin(const polar *p, const double m[3], double z[3])
{
  const double *s = p->s;
  const double e[3] = {FCM_MAX(s[1] + s[2], COROT_FLOOR), FCM_MAX(s[0] + s[2], COROT_FLOOR),
                       FCM_MAX(s[0] + s[1], COROT_FLOOR)};
  double t[3];
  fcm__mat3_tmulv(p->V, m, t); /* V^T m */
  for (int k = 0; k < 3; k++)
    t[k] /= e[k];
  fcm__mat3_mulv(p->V, t, z);
}

/* The element's upper node blocks R K_ab R^T into Kt. */
static void warp_blocks(int nn, const double *Kp, const double R[9], double *Kt)
{
  const int nb = nn * (nn + 1) / 2;
  for (int k = 0; k < nb; k++, Kp += 9, Kt += 9) {
    double T[9]; /* K_ab R^T */
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        T[3 * i + j] =
            Kp[3 * i] * R[3 * j] + Kp[3 * i + 1] * R[3 * j + 1] + Kp[3 * i + 2] * R[3 * j + 2];
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        Kt[3 * i + j] = R[3 * i] * T[j] + R[3 * i + 1] * T[3 + j] + R[3 * i + 2] * T[6 + j];
  }
}

/* c = a x e_j (the column j of [a]x). */
static void cross_unit(const double a[3], int j, double c[3])
{
  const double e[3] = {j == 0, j == 1, j == 2};
  cross(a, e, c);
}

/* The exact Hessian's rotation terms (the header's D, in the rotated frame), rotated by R and
 * added to the element's upper node blocks Kt: Kt_ab += R sym(U V^T)_ab R^T. y: the nodes in
 * the rotated frame, Kd: K d, z: the force's spin term. */
static void add_rotation_terms(int nn, const double *Kp, const double *g, const polar *p,
                               const double *y, const double *Kd, const double z[3], double *Kt)
{
  enum { NMAX = 3 * FCM_ELEMENT_MAX_NODES };
  const int N = 3 * nn;
  double U[NMAX * 6], V[NMAX * 6], KY[NMAX * 3], col[NMAX], t[NMAX];
  for (int j = 0; j < 3; j++) { /* K s(y), a column at a time */
    for (int a = 0; a < nn; a++)
      cross_unit(y + 3 * a, j, col + 3 * a);
    packed_matvec(nn, Kp, col, t);
    for (int r = 0; r < N; r++)
      KY[3 * r + j] = t[r];
  }
  /* U = [K s(y) - s(q), s(g)]; C = sum_a [(Kd)_a]x [y_a]x; s(y)^T K s(y) */
  double C[9] = {0}, YKY[9] = {0};
  for (int a = 0; a < nn; a++) {
    double zg[3], q[3], P[9], Y[9];
    cross(z, g + 3 * a, zg);
    for (int i = 0; i < 3; i++)
      q[i] = Kd[3 * a + i] - zg[i];
    for (int j = 0; j < 3; j++) {
      double sq[3], sg[3], sp[3], sy[3];
      cross_unit(q, j, sq);
      cross_unit(g + 3 * a, j, sg);
      cross_unit(Kd + 3 * a, j, sp);
      cross_unit(y + 3 * a, j, sy);
      for (int i = 0; i < 3; i++) {
        const int r = 3 * a + i;
        U[6 * r + j] = KY[3 * r + j] - sq[i];
        U[6 * r + 3 + j] = sg[i];
        P[3 * i + j] = sp[i];
        Y[3 * i + j] = sy[i];
      }
    }
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) {
        C[3 * i + j] += P[3 * i] * Y[j] + P[3 * i + 1] * Y[3 + j] + P[3 * i + 2] * Y[6 + j];
        YKY[3 * i + j] += Y[i] * KY[3 * (3 * a) + j] + Y[3 + i] * KY[3 * (3 * a + 1) + j] +
                          Y[6 + i] * KY[3 * (3 * a + 2) + j];
      }
  }
  /* dm - dA z = (Mu - L) u + Mw w, Mw = -C - s(y)^T K s(y) + [S z]x */
  double Sz[3], vz[3], Mw[9];
  fcm__mat3_tmulv(p->V, z, vz);
  for (int k = 0; k < 3; k++)
    vz[k] *= p->s[k];
  fcm__mat3_mulv(p->V, vz, Sz);
  const double SzX[9] = {0, -Sz[2], Sz[1], Sz[2], 0, -Sz[0], -Sz[1], Sz[0], 0};
  for (int k = 0; k < 9; k++)
    Mw[k] = -C[k] - YKY[k] + SzX[k];
  /* V's rows: w and dz for the unit variation of DOF r = (b, i) */
  for (int b = 0; b < nn; b++) {
    const double *gb = g + 3 * b;
    const double gz = gb[0] * z[0] + gb[1] * z[1] + gb[2] * z[2];
    for (int i = 0; i < 3; i++) {
      const int r = 3 * b + i;
      double hg[3], w[3], hp[3], v[3], dz[3];
      cross_unit(gb, i, hg);
      solve_spin(p, hg, w);
      cross_unit(Kd + 3 * b, i, hp);
      for (int k = 0; k < 3; k++) /* Mu = -h(Kd) - (K s(y))^T, L = z g^T - (g.z) I */
        v[k] = -hp[k] - KY[3 * r + k] - (z[k] * gb[i] - (k == i ? gz : 0.0)) + Mw[3 * k] * w[0] +
               Mw[3 * k + 1] * w[1] + Mw[3 * k + 2] * w[2];
      solve_spin(p, v, dz);
      for (int k = 0; k < 3; k++) {
        V[6 * r + k] = w[k];
        V[6 * r + 3 + k] = dz[k];
      }
    }
  }
  /* into the global frame: each node's three rows of U and V turned by R */
  const double *R = p->R;
  for (int a = 0; a < nn; a++)
    for (int k = 0; k < 6; k++) {
      double *Ua = U + 6 * 3 * a + k, *Va = V + 6 * 3 * a + k;
      const double u0[3] = {Ua[0], Ua[6], Ua[12]}, v0[3] = {Va[0], Va[6], Va[12]};
      double ru[3], rv[3];
      fcm__mat3_mulv(R, u0, ru);
      fcm__mat3_mulv(R, v0, rv);
      for (int i = 0; i < 3; i++) {
        Ua[6 * i] = ru[i];
        Va[6 * i] = rv[i];
      }
    }
  for (int a = 0; a < nn; a++)
    for (int b = a; b < nn; b++, Kt += 9)
      for (int i = 0; i < 3; i++) {
        const double *ur = U + 6 * (3 * a + i), *vr = V + 6 * (3 * a + i);
        for (int j = 0; j < 3; j++) {
          const double *uc = U + 6 * (3 * b + j), *vc = V + 6 * (3 * b + j);
          double sum = 0.0;
          for (int k = 0; k < 6; k++)
            sum += ur[k] * vc[k] + uc[k] * vr[k];
          Kt[3 * i + j] += 0.5 * sum;
        }
      }
}

cell_result fcm__corot_kernel(const kernel_data *kd, const double *Kp, const double *gbar, int nn,
                              scratch *w)
{
  cell_result res = {0.0, 1.0, 0, 0};
  double F[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, c[3] = {0, 0, 0}, cu[3] = {0, 0, 0};
  for (int a = 0; a < nn; a++)
    for (int i = 0; i < 3; i++) {
      c[i] += w->X[3 * a + i] / nn;
      cu[i] += w->ue[3 * a + i] / nn;
      for (int j = 0; j < 3; j++)
        F[3 * i + j] += w->ue[3 * a + i] * gbar[3 * a + j];
    }
  polar pr;
  const double *R = pr.R;
  if (!polar_rotation(F, &pr)) {
    res.nonfinite = 1;
    return res;
  }
  if (fcm__mat3_det(F) <= 0.0) res.inverted = 1;
  double *d = w->FT, *Kd = w->fe, y[3 * FCM_ELEMENT_MAX_NODES];
  for (int a = 0; a < nn; a++) {
    double xa[3];
    for (int i = 0; i < 3; i++)
      xa[i] = w->X[3 * a + i] - c[i] + (w->ue[3 * a + i] - cu[i]);
    fcm__mat3_tmulv(R, xa, y + 3 * a);
    for (int i = 0; i < 3; i++)
      d[3 * a + i] = y[3 * a + i] - (w->X[3 * a + i] - c[i]);
  }
  packed_matvec(nn, Kp, d, Kd);
  double E = 0.0, m[3] = {0, 0, 0};
  for (int a = 0; a < nn; a++) {
    double t[3];
    cross(y + 3 * a, Kd + 3 * a, t);
    for (int i = 0; i < 3; i++) {
      E += d[3 * a + i] * Kd[3 * a + i];
      m[i] += t[i];
    }
  }
  res.energy = 0.5 * E;
  if (!isfinite(res.energy)) res.nonfinite = 1;
  double z[3];
  solve_spin(&pr, m, z);
  /* the tangent first: the force is written over Kd (w->fe) */
  if (kd->want_tangent) {
    warp_blocks(nn, Kp, R, w->Ke);
    if (kd->corot_exact) add_rotation_terms(nn, Kp, gbar, &pr, y, Kd, z, w->Ke);
    fcm__kernel_symmetrize(nn, w->Ke);
  }
  if (kd->want_force) {
    for (int a = 0; a < nn; a++) {
      double t[3], v[3];
      cross(z, gbar + 3 * a, t);
      for (int i = 0; i < 3; i++)
        v[i] = Kd[3 * a + i] - t[i];
      fcm__mat3_mulv(R, v, w->fe + 3 * a);
    }
  }
  return res;
}
