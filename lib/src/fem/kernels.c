/* Element kernels: linear stiffness, consistent mass, body force and hyperelastic energy, force
 * and tangent of one cell. The element matrices are blocked products over all points of the
 * cell (chunks of FCM__KERNEL_QB or FCM__KERNEL_QH points), not one rank-one update per point:
 *   stiffness  H = sum_q w_q det J_q g_q g_q^T     (g_q the 3nn physical gradients at q)
 *   mass       M = sum_q w_q det J_q rho N_q N_q^T
 *   tangent    K_(a,i)(b,k) = sum_(q,J) g_qaJ [w_q det J_q sum_L A_q,iJkL g_qbL]
 * each as register blocks of 4 rows x 16 columns (AVX-512), 4 x 8 (AVX2) or 4 x 4 over the
 * upper triangle (the micro-kernels micro_4x16(), micro_4x8(), micro_4x4()). With FCM_MULTIVERSION
 * on x86-64 with GCC and glibc, the kernels are compiled for x86-64-v4 (AVX-512), x86-64-v3 (AVX2 +
 * FMA) and the baseline, and the loader picks the clone for the CPU (an ifunc): a default build
 * runs the AVX-512 code on a CPU that has it. Compiled with -ffp-contract=fast (sources.cmake), so
 * products and sums fuse where the CPU can; the results then differ between instruction sets at
 * round-off, but on one machine they are the same for every thread count. */
#include "fem/kernels_impl.h"

#include <math.h>
#include <string.h>

#if defined(FCM_MULTIVERSION) && defined(__x86_64__) && defined(__GNUC__) &&                       \
    !defined(__clang__) && __GNUC__ >= 11 && defined(__GLIBC__)
#define FCM_KERNEL_CLONES                                                                          \
  __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#define FCM_KERNEL_CLONES_ON
#else
#define FCM_KERNEL_CLONES
#endif

/* Helpers are inlined into each clone, so they get its instruction set. */
#if defined(__GNUC__) || defined(__clang__)
#define FCM_KERNEL_INLINE static inline __attribute__((always_inline))
#else
#define FCM_KERNEL_INLINE static inline
#endif

/* C (4 rows x 8 columns, row stride ldc) += sum_k A[k lda + i] B[k ldb + j]: the register
 * block of the blocked products with AVX2 (8 registers of accumulators). */
#if defined(__GNUC__) || defined(__clang__)
typedef double fcm_v8d __attribute__((vector_size(64)));

FCM_KERNEL_INLINE void micro_4x8(int nk, const double *A, int lda, const double *B, int ldb,
                                 double *C, int ldc)
{
  fcm_v8d c0 = {0}, c1 = {0}, c2 = {0}, c3 = {0}, b, t;
  for (int k = 0; k < nk; k++) {
    const double *a = A + (size_t)k * lda;
    memcpy(&b, B + (size_t)k * ldb, sizeof b);
    c0 += a[0] * b;
    c1 += a[1] * b;
    c2 += a[2] * b;
    c3 += a[3] * b;
  }
  memcpy(&t, C, sizeof t), t += c0, memcpy(C, &t, sizeof t);
  memcpy(&t, C + ldc, sizeof t), t += c1, memcpy(C + ldc, &t, sizeof t);
  memcpy(&t, C + 2 * ldc, sizeof t), t += c2, memcpy(C + 2 * ldc, &t, sizeof t);
  memcpy(&t, C + 3 * ldc, sizeof t), t += c3, memcpy(C + 3 * ldc, &t, sizeof t);
}

/* The same on 4 x 4 (8 SSE2 registers of accumulators: 4 x 8 would spill the 16 of baseline
 * x86-64). */
typedef double fcm_v4d __attribute__((vector_size(32)));

FCM_KERNEL_INLINE void micro_4x4(int nk, const double *A, int lda, const double *B, int ldb,
                                 double *C, int ldc)
{
  fcm_v4d c0 = {0}, c1 = {0}, c2 = {0}, c3 = {0}, b, t;
  for (int k = 0; k < nk; k++) {
    const double *a = A + (size_t)k * lda;
    memcpy(&b, B + (size_t)k * ldb, sizeof b);
    c0 += a[0] * b;
    c1 += a[1] * b;
    c2 += a[2] * b;
    c3 += a[3] * b;
  }
  memcpy(&t, C, sizeof t), t += c0, memcpy(C, &t, sizeof t);
  memcpy(&t, C + ldc, sizeof t), t += c1, memcpy(C + ldc, &t, sizeof t);
  memcpy(&t, C + 2 * ldc, sizeof t), t += c2, memcpy(C + 2 * ldc, &t, sizeof t);
  memcpy(&t, C + 3 * ldc, sizeof t), t += c3, memcpy(C + 3 * ldc, &t, sizeof t);
}

/* The same on 4 x 16 (8 AVX-512 accumulators: two fused multiply-adds per cycle of latency 4
 * need 8 independent sums; on AVX2 this would spill). */
FCM_KERNEL_INLINE void micro_4x16(int nk, const double *A, int lda, const double *B, int ldb,
                                  double *C, int ldc)
{
  fcm_v8d c0 = {0}, c1 = {0}, c2 = {0}, c3 = {0}, d0 = {0}, d1 = {0}, d2 = {0}, d3 = {0}, b, e, t;
  for (int k = 0; k < nk; k++) {
    const double *a = A + (size_t)k * lda;
    memcpy(&b, B + (size_t)k * ldb, sizeof b);
    memcpy(&e, B + (size_t)k * ldb + 8, sizeof e);
    c0 += a[0] * b, d0 += a[0] * e;
    c1 += a[1] * b, d1 += a[1] * e;
    c2 += a[2] * b, d2 += a[2] * e;
    c3 += a[3] * b, d3 += a[3] * e;
  }
#define FCM_ADD_ROW(p, v) (memcpy(&t, (p), sizeof t), t += (v), memcpy((p), &t, sizeof t))
  FCM_ADD_ROW(C, c0), FCM_ADD_ROW(C + 8, d0);
  FCM_ADD_ROW(C + ldc, c1), FCM_ADD_ROW(C + ldc + 8, d1);
  FCM_ADD_ROW(C + 2 * ldc, c2), FCM_ADD_ROW(C + 2 * ldc + 8, d2);
  FCM_ADD_ROW(C + 3 * ldc, c3), FCM_ADD_ROW(C + 3 * ldc + 8, d3);
#undef FCM_ADD_ROW
}
#else
FCM_KERNEL_INLINE void micro_4x4(int nk, const double *A, int lda, const double *B, int ldb,
                                 double *C, int ldc)
{
  double c[4][4] = {{0}};
  for (int k = 0; k < nk; k++)
    for (int i = 0; i < 4; i++)
      for (int j = 0; j < 4; j++)
        c[i][j] += A[(size_t)k * lda + i] * B[(size_t)k * ldb + j];
  for (int i = 0; i < 4; i++)
    for (int j = 0; j < 4; j++)
      C[(size_t)i * ldc + j] += c[i][j];
}

FCM_KERNEL_INLINE void micro_4x8(int nk, const double *A, int lda, const double *B, int ldb,
                                 double *C, int ldc)
{
  micro_4x4(nk, A, lda, B, ldb, C, ldc);
  micro_4x4(nk, A, lda, B + 4, ldb, C + 4, ldc);
}

FCM_KERNEL_INLINE void micro_4x16(int nk, const double *A, int lda, const double *B, int ldb,
                                  double *C, int ldc)
{
  micro_4x8(nk, A, lda, B, ldb, C, ldc);
  micro_4x8(nk, A, lda, B + 8, ldb, C + 8, ldc);
}
#endif

/* The register block's width for the running code: 16 with AVX-512 (32 vector registers), 8
 * with AVX2 (16 of 4 doubles), else 4 (16 of 2 doubles); with the clones, the CPU's level is
 * the clone's. */
#if defined(FCM_KERNEL_CLONES_ON)
#define FCM_KERNEL_NB()                                                                            \
  (__builtin_cpu_supports("x86-64-v4") ? 16 : __builtin_cpu_supports("x86-64-v3") ? 8 : 4)
#elif defined(__AVX512F__)
#define FCM_KERNEL_NB() 16
#elif defined(__AVX2__)
#define FCM_KERNEL_NB() 8
#else
#define FCM_KERNEL_NB() 4
#endif

/* C (4 x nb) += the product of micro_4x4(), micro_4x8() or micro_4x16() (nb = 4, 8, 16). */
FCM_KERNEL_INLINE void micro(int nb, int nk, const double *A, int lda, const double *B, int ldb,
                             double *C, int ldc)
{
  if (nb == 16)
    micro_4x16(nk, A, lda, B, ldb, C, ldc);
  else if (nb == 8)
    micro_4x8(nk, A, lda, B, ldb, C, ldc);
  else
    micro_4x4(nk, A, lda, B, ldb, C, ldc);
}

/* C += A^T B on the blocks of rows [0, rows) (in fours) whose nb columns reach the diagonal or
 * beyond, columns up to ld (a multiple of 16): A, B are nk x ld (row stride ld), C is ld x ld.
 * Every entry C[x][y] with x <= y < ld is summed. */
FCM_KERNEL_INLINE void product_upper(int nb, int nk, const double *A, const double *B, int rows,
                                     int ld, double *C)
{
  for (int a0 = 0; a0 < rows; a0 += 4)
    for (int b0 = a0 / nb * nb; b0 < ld; b0 += nb)
      micro(nb, nk, A + a0, ld, B + b0, ld, C + (size_t)a0 * ld + b0, ld);
}

/* Physical gradients g (nn x 3, then zero to ld) from the reference ones dN and the nodal
 * coordinates X; returns det J (not positive: g is not written). */
FCM_KERNEL_INLINE double gradients(int nn, const double *X, const double *dN, double *g)
{
  double J[9] = {0}, Ji[9] = {0};
  for (int a = 0; a < nn; a++)
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        J[3 * i + j] += X[3 * a + i] * dN[3 * a + j];
  const double det = fcm__mat3_inv(J, Ji);
  if (!(det > 0.0)) return det;
  for (int a = 0; a < nn; a++)
    for (int j = 0; j < 3; j++)
      g[3 * a + j] = Ji[j] * dN[3 * a] + Ji[3 + j] * dN[3 * a + 1] + Ji[6 + j] * dN[3 * a + 2];
  return det;
}

double fcm__fem_gradients(int nn, const double *X, const double *dN, double *g)
{
  return gradients(nn, X, dN, g);
}

/* The gradients of points [q0, q0 + nc) of rule r into rows of G (zero padded to ld), their
 * weights w det J into wd and, with WG, the rows times w det J into WG; 0 with res->bad_det set
 * at the first point whose det J is not positive. */
FCM_KERNEL_INLINE int chunk_gradients(const cell_rule *r, int nn, int q0, int nc, const double *X,
                                      int ld, scratch *w, cell_result *res, double *WG)
{
  const int ndof = 3 * nn;
  for (int c = 0; c < nc; c++) {
    double *g = w->G + (size_t)c * ld;
    const double det = gradients(nn, X, r->dN + (size_t)(q0 + c) * nn * 3, g);
    if (!(det > 0.0)) {
      res->bad_det = det;
      return 0;
    }
    for (int k = ndof; k < ld; k++)
      g[k] = 0.0;
    const double wd = r->w[q0 + c] * det;
    w->wd[c] = wd;
    if (WG)
      for (int k = 0; k < ld; k++)
        WG[(size_t)c * ld + k] = wd * g[k];
  }
  return 1;
}

/* Fill the lower node blocks of a symmetric element matrix from the upper ones. */
static void mirror_blocks(int nn, double *Ke)
{
  int ndof = 3 * nn;
  for (int a = 0; a < nn; a++)
    for (int b = 0; b < a; b++)
      for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
          Ke[(size_t)(3 * a + i) * ndof + 3 * b + j] = Ke[(size_t)(3 * b + j) * ndof + 3 * a + i];
}

/* Linear stiffness Ke (3nn x 3nn, row-major). With H = sum_q w_q det J_q g_q g_q^T (upper
 * triangle, row stride ld) the isotropic element matrix is
 * K_(a,i)(b,j) = lambda H_(a,i)(b,j) + mu H_(a,j)(b,i) + mu delta_ij sum_k H_(a,k)(b,k). */
FCM_KERNEL_CLONES
static cell_result stiffness_kernel(const kernel_data *kd, const cell_rule *r, int nn, scratch *w)
{
  const int ndof = 3 * nn, ld = fcm__kernel_ld(nn), nb = FCM_KERNEL_NB();
  cell_result res = {0.0, 1.0, 0, 0};
  double *H = w->H, *Ke = w->Ke;
  memset(H, 0, sizeof *H * (size_t)ld * ld);
  for (int q0 = 0; q0 < r->nq; q0 += FCM__KERNEL_QB) {
    const int nc = r->nq - q0 < FCM__KERNEL_QB ? r->nq - q0 : FCM__KERNEL_QB;
    if (!chunk_gradients(r, nn, q0, nc, w->X, ld, w, &res, w->WG)) return res;
    product_upper(nb, nc, w->WG, w->G, ndof, ld, H);
  }
  const double l = kd->lambda, m = kd->mu;
  for (int a = 0; a < nn; a++)
    for (int b = a; b < nn; b++) {
      double h[3][3]; /* block (a, b) of H; the diagonal blocks from their upper triangle */
      for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
          const int x = 3 * a + i, y = 3 * b + j;
          h[i][j] = x <= y ? H[(size_t)x * ld + y] : H[(size_t)y * ld + x];
        }
      const double tr = m * (h[0][0] + h[1][1] + h[2][2]);
      for (int i = 0; i < 3; i++) {
        double *row = Ke + (size_t)(3 * a + i) * ndof + 3 * b;
        for (int j = 0; j < 3; j++)
          row[j] = l * h[i][j] + m * h[j][i];
        row[i] += tr;
      }
    }
  mirror_blocks(nn, Ke);
  return res;
}

/* Consistent mass Ke: the scalar matrix M = sum_q w_q det J_q rho N N^T on each component. */
FCM_KERNEL_CLONES
static cell_result mass_kernel(const kernel_data *kd, const cell_rule *r, int nn, scratch *w)
{
  const int ndof = 3 * nn, ld = (nn + 15) / 16 * 16, nb = FCM_KERNEL_NB();
  cell_result res = {0.0, 1.0, 0, 0};
  double *H = w->H, *Ke = w->Ke;
  memset(H, 0, sizeof *H * (size_t)ld * ld);
  memset(Ke, 0, sizeof *Ke * (size_t)ndof * ndof);
  for (int q0 = 0; q0 < r->nq; q0 += FCM__KERNEL_QB) {
    const int nc = r->nq - q0 < FCM__KERNEL_QB ? r->nq - q0 : FCM__KERNEL_QB;
    for (int c = 0; c < nc; c++) {
      const double det = gradients(nn, w->X, r->dN + (size_t)(q0 + c) * nn * 3, w->g);
      if (!(det > 0.0)) {
        res.bad_det = det;
        return res;
      }
      const double rw = r->w[q0 + c] * det * kd->rho, *N = r->N + (size_t)(q0 + c) * nn;
      double *n = w->G + (size_t)c * ld, *wn = w->WG + (size_t)c * ld;
      for (int a = 0; a < ld; a++)
        n[a] = a < nn ? N[a] : 0.0, wn[a] = rw * n[a];
    }
    product_upper(nb, nc, w->WG, w->G, nn, ld, H);
  }
  for (int a = 0; a < nn; a++)
    for (int b = a; b < nn; b++)
      for (int i = 0; i < 3; i++)
        Ke[(size_t)(3 * a + i) * ndof + 3 * b + i] = H[(size_t)a * ld + b];
  mirror_blocks(nn, Ke);
  return res;
}

/* Body force fe (3nn): rho * accel, or the force density field b(X), against N. */
static cell_result body_force_kernel(const kernel_data *kd, const cell_rule *r, int nn, scratch *w)
{
  cell_result res = {0.0, 1.0, 0, 0};
  double *fe = w->fe;
  memset(fe, 0, sizeof *fe * (size_t)(3 * nn));
  for (int q = 0; q < r->nq; q++) {
    const double det = gradients(nn, w->X, r->dN + (size_t)q * nn * 3, w->g);
    if (!(det > 0.0)) {
      res.bad_det = det;
      return res;
    }
    const double wd = r->w[q] * det, *N = r->N + (size_t)q * nn;
    double b[3] = {kd->rho * kd->accel[0], kd->rho * kd->accel[1], kd->rho * kd->accel[2]};
    if (kd->field) {
      double x[3] = {0, 0, 0};
      for (int a = 0; a < nn; a++)
        for (int i = 0; i < 3; i++)
          x[i] += N[a] * w->X[3 * a + i];
      kd->field(kd->field_user, x, NULL, b);
    }
    for (int a = 0; a < nn; a++)
      for (int i = 0; i < 3; i++)
        fe[3 * a + i] += wd * b[i] * N[a];
  }
  return res;
}

/* The material at a fictitious stabilization point (lib/METHOD.md §7): the exact
 * model's tangent times alpha is indefinite and does not lift the small blocks of cut
 * cells, so these points carry a positive semi-definite tangent. PROJECTED keeps the
 * exact energy and force (rotation invariant) and projects the tangent: the Newton
 * matrix then differs from the true Hessian by alpha (K - K_psd) on these points only,
 * the residual and hence the solution stay exact. LINEAR uses linear elasticity at rest
 * for all three, a consistent energy but an O(alpha) torque under rotations. */
FCM_KERNEL_INLINE void fictitious_eval(const kernel_data *kd, const double F[9], double *psi,
                                       double P[9], double *A)
{
  switch (kd->fictitious) {
  case FCM_FICTITIOUS_LINEAR:
    fcm__material_linear(kd->mat->mu, kd->mat->lambda, F, psi, P, A);
    return;
  case FCM_FICTITIOUS_PROJECTED:
    fcm__material_eval(kd->mat, F, psi, P, NULL);
    if (A) fcm__material_eval(&kd->mat_psd, F, NULL, NULL, A);
    return;
  default:
    fcm__material_eval(kd->mat, F, psi, P, A);
    return;
  }
}

/* The material at point c of a chunk (gradients g): energy, force into fe and, with A, the
 * tangent's factors of the point into the chunk's rows of w->WG (g^T) and w->B
 * (w det J A g_b); 0 with res->nonfinite set when the material returned NaN or infinity. */
FCM_KERNEL_INLINE int hyperelastic_point(const kernel_data *kd, const cell_rule *r, int nn, int q,
                                         int c, int ld, scratch *w, cell_result *res)
{
  const double *g = w->G + (size_t)c * ld, wd = w->wd[c];
  double F[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, psi = 0.0, P[9], A[81];
  for (int a = 0; a < nn; a++)
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        F[3 * i + j] += w->ue[3 * a + i] * g[3 * a + j];
  if (r->fict && r->fict[q]) {
    fictitious_eval(kd, F, &psi, P, kd->want_tangent ? A : NULL);
  } else {
    /* an inverted point of the body: counted, the material still evaluates it (the
     * Stable Neo-Hookean and corotated models are defined there) */
    res->inverted += !(fcm__mat3_det(F) > 0.0);
    fcm__material_eval(kd->mat, F, &psi, P, kd->want_tangent ? A : NULL);
  }
  int finite = isfinite(psi);
  for (int k = 0; k < 9; k++)
    finite &= isfinite(P[k]);
  if (!finite) {
    res->nonfinite = 1;
    return 0;
  }
  res->energy += wd * psi;
  for (int a = 0; a < nn; a++) {
    const double *ga = g + 3 * a;
    for (int i = 0; i < 3; i++)
      w->fe[3 * a + i] += wd * (P[3 * i] * ga[0] + P[3 * i + 1] * ga[1] + P[3 * i + 2] * ga[2]);
  }
  if (!kd->want_tangent) return 1;
  const size_t bi = (size_t)3 * FCM__KERNEL_QH * ld; /* B's stride between components i */
  for (int J = 0; J < 3; J++) {
    double *gt = w->WG + (size_t)(3 * c + J) * ld; /* row (c, J) of the left factor: g_aJ */
    for (int a = 0; a < ld; a++)
      gt[a] = a < nn ? g[3 * a + J] : 0.0;
    for (int i = 0; i < 3; i++) { /* B_i[(c, J)][(b, k)] = wd sum_L A_iJkL g_bL */
      double *row = w->B + i * bi + (size_t)(3 * c + J) * ld;
      const double *Am = A + 9 * (3 * i + J);
      for (int b = 0; b < nn; b++) {
        const double *gb = g + 3 * b;
        for (int k = 0; k < 3; k++)
          row[3 * b + k] = wd * (Am[3 * k] * gb[0] + Am[3 * k + 1] * gb[1] + Am[3 * k + 2] * gb[2]);
      }
      for (int k = 3 * nn; k < ld; k++)
        row[k] = 0.0;
    }
  }
  return 1;
}

/* Hyperelastic energy, internal force fe and (want_tangent) tangent Ke at the displacement
 * w->ue: F = I + sum_a u_a (x) g_a; f_(a,i) = sum_q wd P_iJ g_aJ and
 * K_(a,i)(b,k) = sum_q wd g_aJ A_iJkL g_bL with A = dP/dF, summed per chunk of points as
 * K_i[a][(b, k)] += sum_(c,J) g_caJ B_i[(c, J)][(b, k)] (row (a, i) of K, stride 3 ld in H). */
FCM_KERNEL_CLONES
static cell_result hyperelastic_kernel(const kernel_data *kd, const cell_rule *r, int nn,
                                       scratch *w)
{
  const int ndof = 3 * nn, ld = fcm__kernel_ld(nn), na = (nn + 3) / 4 * 4;
  const int nb = FCM_KERNEL_NB();
  cell_result res = {0.0, 1.0, 0, 0};
  double *H = w->H, *Ke = w->Ke;
  if (kd->want_tangent) memset(H, 0, sizeof *H * (size_t)ld * ld);
  memset(w->fe, 0, sizeof *w->fe * (size_t)ndof);
  for (int q0 = 0; q0 < r->nq; q0 += FCM__KERNEL_QH) {
    const int nc = r->nq - q0 < FCM__KERNEL_QH ? r->nq - q0 : FCM__KERNEL_QH;
    if (!chunk_gradients(r, nn, q0, nc, w->X, ld, w, &res, NULL)) return res;
    for (int c = 0; c < nc; c++)
      if (!hyperelastic_point(kd, r, nn, q0 + c, c, ld, w, &res)) return res;
    if (!kd->want_tangent) continue;
    for (int i = 0; i < 3; i++) {
      const double *Bi = w->B + (size_t)i * 3 * FCM__KERNEL_QH * ld;
      for (int a0 = 0; a0 < na; a0 += 4)
        for (int b0 = 3 * a0 / nb * nb; b0 < ld; b0 += nb)
          micro(nb, 3 * nc, w->WG + a0, ld, Bi + b0, ld, H + (size_t)(3 * a0 + i) * ld + b0,
                3 * ld);
    }
  }
  if (!kd->want_tangent) return res;
  for (int a = 0; a < nn; a++) /* the upper node blocks a <= b */
    for (int x = 3 * a; x < 3 * a + 3; x++)
      memcpy(Ke + (size_t)x * ndof + 3 * a, H + (size_t)x * ld + 3 * a,
             sizeof *Ke * (size_t)(ndof - 3 * a));
  mirror_blocks(nn, Ke);
  return res;
}

cell_result fcm__cell_kernel(const kernel_data *kd, const cell_rule *r, int nn, scratch *w)
{
  switch (kd->kind) {
  case KERNEL_STIFFNESS:
    memset(w->fe, 0, sizeof *w->fe * (size_t)(3 * nn));
    return stiffness_kernel(kd, r, nn, w);
  case KERNEL_MASS:
    memset(w->fe, 0, sizeof *w->fe * (size_t)(3 * nn));
    return mass_kernel(kd, r, nn, w);
  case KERNEL_BODY_FORCE:
    return body_force_kernel(kd, r, nn, w);
  default:
    return hyperelastic_kernel(kd, r, nn, w);
  }
}

/* Rows of WG: QB (linear kernels) or 3 QH (the hyperelastic kernel's left factor). */
enum { WG_ROWS = FCM__KERNEL_QB > 3 * FCM__KERNEL_QH ? FCM__KERNEL_QB : 3 * FCM__KERNEL_QH };

size_t fcm__kernel_scratch_size(int nn, size_t mq)
{
  const size_t ndof = 3 * (size_t)nn, ld = (size_t)fcm__kernel_ld(nn);
  return 3 * (size_t)nn + 2 * ndof + 3 * (size_t)nn + ld * ld + ndof * ndof + mq * nn * 4 +
         FCM__KERNEL_QB * ld + WG_ROWS * ld + FCM__KERNEL_QB + 9 * FCM__KERNEL_QH * ld;
}

void fcm__kernel_scratch_init(int nn, size_t mq, double *p, scratch *w)
{
  const size_t ndof = 3 * (size_t)nn, ld = (size_t)fcm__kernel_ld(nn);
  w->X = p, p += 3 * nn;
  w->ue = p, p += ndof;
  w->fe = p, p += ndof;
  w->g = p, p += 3 * nn;
  w->H = p, p += ld * ld;
  w->Ke = p, p += ndof * ndof;
  w->Nb = p, p += mq * nn;
  w->dNb = p, p += mq * nn * 3;
  w->G = p, p += FCM__KERNEL_QB * ld;
  w->WG = p, p += WG_ROWS * ld;
  w->wd = p, p += FCM__KERNEL_QB;
  w->B = p;
}
