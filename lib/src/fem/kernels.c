/* Element kernels: linear stiffness, consistent mass, body force and hyperelastic energy, force
 * and tangent of one cell. The element matrices are blocked products over all points of the
 * cell (chunks of FCM__KERNEL_QB or FCM__KERNEL_QH points), not one rank-one update per point:
 *   stiffness  H = sum_q w_q det J_q g_q g_q^T     (g_q the 3nn physical gradients at q)
 *   mass       M = sum_q w_q det J_q rho N_q N_q^T
 *   tangent    K_(a,i)(b,k) = sum_(q,J) g_qaJ [w_q det J_q sum_L A_q,iJkL g_qbL]
 * each as register blocks of 4 rows x 16 columns (AVX-512), 4 x 8 (AVX2) or 4 x 4 over the
 * upper triangle (the micro-kernels micro_4x16(), micro_4x8(), micro_4x4()). The per-point
 * work runs over the nodes in vectors of 4 on tables by component (the rule's reference
 * gradients dT, the cell's coordinates, the physical gradients: 3 rows of na nodes, zero
 * padded), and the element matrices come out as their upper node blocks (kernels_impl.h). With
 * FCM_MULTIVERSION on x86-64 with GCC and glibc, the kernels are compiled for x86-64-v4 (AVX-512),
 * x86-64-v3 (AVX2 + FMA) and the baseline, and the loader picks the clone for the CPU (an ifunc): a
 * default build runs the AVX-512 code on a CPU that has it. Compiled with -ffp-contract=fast
 * (sources.cmake), so products and sums fuse where the CPU can; the results then differ between
 * instruction sets at round-off, but on one machine they are the same for every thread count. */
#include "fem/kernels_impl.h"

#include "core/multiversion.h"

#include <math.h>
#include <string.h>

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
typedef double fcm_v4d __attribute__((vector_size(32)));

/* p[0..8) = *v, or p[0..8) += *v with add (a row of a register block into C). The vectors go
 * by address: by value they would change the calling convention between instruction sets
 * (clang's -Wpsabi); the functions are inlined either way. */
FCM_KERNEL_INLINE void put8(double *p, const fcm_v8d *v, int add)
{
  fcm_v8d r = *v;
  if (add) {
    fcm_v8d o;
    memcpy(&o, p, sizeof o);
    r += o;
  }
  memcpy(p, &r, sizeof r);
}

/* p[0..4) = *v, or p[0..4) += *v with add. */
FCM_KERNEL_INLINE void put4(double *p, const fcm_v4d *v, int add)
{
  fcm_v4d r = *v;
  if (add) {
    fcm_v4d o;
    memcpy(&o, p, sizeof o);
    r += o;
  }
  memcpy(p, &r, sizeof r);
}

FCM_KERNEL_INLINE void micro_4x8(int nk, const double *A, int lda, const double *B, int ldb,
                                 double *C, int ldc, int add)
{
  fcm_v8d c0 = {0}, c1 = {0}, c2 = {0}, c3 = {0}, b;
  for (int k = 0; k < nk; k++) {
    const double *a = A + (size_t)k * lda;
    memcpy(&b, B + (size_t)k * ldb, sizeof b);
    c0 += a[0] * b;
    c1 += a[1] * b;
    c2 += a[2] * b;
    c3 += a[3] * b;
  }
  put8(C, &c0, add), put8(C + ldc, &c1, add);
  put8(C + 2 * ldc, &c2, add), put8(C + 3 * ldc, &c3, add);
}

/* The same on 4 x 4 (8 SSE2 registers of accumulators: 4 x 8 would spill the 16 of baseline
 * x86-64). */
FCM_KERNEL_INLINE void micro_4x4(int nk, const double *A, int lda, const double *B, int ldb,
                                 double *C, int ldc, int add)
{
  fcm_v4d c0 = {0}, c1 = {0}, c2 = {0}, c3 = {0}, b;
  for (int k = 0; k < nk; k++) {
    const double *a = A + (size_t)k * lda;
    memcpy(&b, B + (size_t)k * ldb, sizeof b);
    c0 += a[0] * b;
    c1 += a[1] * b;
    c2 += a[2] * b;
    c3 += a[3] * b;
  }
  put4(C, &c0, add), put4(C + ldc, &c1, add);
  put4(C + 2 * ldc, &c2, add), put4(C + 3 * ldc, &c3, add);
}

/* The same on 4 x 16 (8 AVX-512 accumulators: two fused multiply-adds per cycle of latency 4
 * need 8 independent sums; on AVX2 this would spill). */
FCM_KERNEL_INLINE void micro_4x16(int nk, const double *A, int lda, const double *B, int ldb,
                                  double *C, int ldc, int add)
{
  fcm_v8d c0 = {0}, c1 = {0}, c2 = {0}, c3 = {0}, d0 = {0}, d1 = {0}, d2 = {0}, d3 = {0}, b, e;
  for (int k = 0; k < nk; k++) {
    const double *a = A + (size_t)k * lda;
    memcpy(&b, B + (size_t)k * ldb, sizeof b);
    memcpy(&e, B + (size_t)k * ldb + 8, sizeof e);
    c0 += a[0] * b, d0 += a[0] * e;
    c1 += a[1] * b, d1 += a[1] * e;
    c2 += a[2] * b, d2 += a[2] * e;
    c3 += a[3] * b, d3 += a[3] * e;
  }
  put8(C, &c0, add), put8(C + 8, &d0, add);
  put8(C + ldc, &c1, add), put8(C + ldc + 8, &d1, add);
  put8(C + 2 * ldc, &c2, add), put8(C + 2 * ldc + 8, &d2, add);
  put8(C + 3 * ldc, &c3, add), put8(C + 3 * ldc + 8, &d3, add);
}
#else
FCM_KERNEL_INLINE void micro_4x4(int nk, const double *A, int lda, const double *B, int ldb,
                                 double *C, int ldc, int add)
{
  double c[4][4] = {{0}};
  for (int k = 0; k < nk; k++)
    for (int i = 0; i < 4; i++)
      for (int j = 0; j < 4; j++)
        c[i][j] += A[(size_t)k * lda + i] * B[(size_t)k * ldb + j];
  for (int i = 0; i < 4; i++)
    for (int j = 0; j < 4; j++)
      C[(size_t)i * ldc + j] = add ? C[(size_t)i * ldc + j] + c[i][j] : c[i][j];
}

FCM_KERNEL_INLINE void micro_4x8(int nk, const double *A, int lda, const double *B, int ldb,
                                 double *C, int ldc, int add)
{
  micro_4x4(nk, A, lda, B, ldb, C, ldc, add);
  micro_4x4(nk, A, lda, B + 4, ldb, C + 4, ldc, add);
}

FCM_KERNEL_INLINE void micro_4x16(int nk, const double *A, int lda, const double *B, int ldb,
                                  double *C, int ldc, int add)
{
  micro_4x8(nk, A, lda, B, ldb, C, ldc, add);
  micro_4x8(nk, A, lda, B + 8, ldb, C + 8, ldc, add);
}
#endif

/* The register block's width for the running code: 16 with AVX-512 (32 vector registers), 8
 * with AVX2 (16 of 4 doubles), else 4 (16 of 2 doubles); with the clones, the CPU's level is
 * the clone's. */
#if FCM_MULTIVERSION_ON
#define FCM_KERNEL_NB()                                                                            \
  (__builtin_cpu_supports("x86-64-v4") ? 16 : __builtin_cpu_supports("x86-64-v3") ? 8 : 4)
#elif defined(__AVX512F__)
#define FCM_KERNEL_NB() 16
#elif defined(__AVX2__)
#define FCM_KERNEL_NB() 8
#else
#define FCM_KERNEL_NB() 4
#endif

/* C (4 x nb) = (add: +=) the product of micro_4x4(), micro_4x8() or micro_4x16() (nb = 4, 8,
 * 16). */
FCM_KERNEL_INLINE void micro(int nb, int nk, const double *A, int lda, const double *B, int ldb,
                             double *C, int ldc, int add)
{
  if (nb == 16)
    micro_4x16(nk, A, lda, B, ldb, C, ldc, add);
  else if (nb == 8)
    micro_4x8(nk, A, lda, B, ldb, C, ldc, add);
  else
    micro_4x4(nk, A, lda, B, ldb, C, ldc, add);
}

/* C = (add: +=) A^T B on its upper triangle: A, B are nk x ld (row stride ld), C is ld x ld,
 * every entry C[x][y] with x <= y < cols summed (some below the diagonal and beyond cols too).
 * Rows [0, cols) in fours; each run of rows from its diagonal on in blocks of nb columns, the
 * rest in the narrowest block of nb / 2^k >= 4 columns that covers it (within ld, a multiple of
 * 16 with cols + 4 <= ld or cols a multiple of 8). */
FCM_KERNEL_INLINE void product_upper(int nb, int nk, const double *A, const double *B, int cols,
                                     int ld, double *C, int add)
{
  for (int a0 = 0; a0 < cols; a0 += 4) {
    int b0 = a0;
    for (; b0 + nb <= cols; b0 += nb)
      micro(nb, nk, A + a0, ld, B + b0, ld, C + (size_t)a0 * ld + b0, ld, add);
    for (int w = nb; b0 < cols; b0 += w) {
      while (w > 4 && (w / 2 >= cols - b0 || b0 + w > ld))
        w /= 2;
      micro(w, nk, A + a0, ld, B + b0, ld, C + (size_t)a0 * ld + b0, ld, add);
    }
  }
}

/* ------------------------------------------------------------------ the per-point work */

/* S[3i + j] = sum_a U[i na + a] V[j na + a] for two tables by component (3 rows of na, a
 * multiple of 4): the Jacobian X^T dN from the coordinates and the reference gradients, or the
 * displacement gradient sum_a u_a g_a^T. */
FCM_KERNEL_INLINE void outer_sum(int na, const double *U, const double *V, double S[9])
{
#if defined(__GNUC__) || defined(__clang__)
  fcm_v4d s0 = {0}, s1 = {0}, s2 = {0}, s3 = {0}, s4 = {0}, s5 = {0}, s6 = {0}, s7 = {0}, s8 = {0};
  for (int a = 0; a < na; a += 4) {
    fcm_v4d u0, u1, u2, v0, v1, v2;
    memcpy(&u0, U + a, sizeof u0), memcpy(&u1, U + na + a, sizeof u1);
    memcpy(&u2, U + 2 * na + a, sizeof u2);
    memcpy(&v0, V + a, sizeof v0), memcpy(&v1, V + na + a, sizeof v1);
    memcpy(&v2, V + 2 * na + a, sizeof v2);
    s0 += u0 * v0, s1 += u0 * v1, s2 += u0 * v2;
    s3 += u1 * v0, s4 += u1 * v1, s5 += u1 * v2;
    s6 += u2 * v0, s7 += u2 * v1, s8 += u2 * v2;
  }
#define FCM_HSUM(v) (((v)[0] + (v)[1]) + ((v)[2] + (v)[3]))
  S[0] = FCM_HSUM(s0), S[1] = FCM_HSUM(s1), S[2] = FCM_HSUM(s2);
  S[3] = FCM_HSUM(s3), S[4] = FCM_HSUM(s4), S[5] = FCM_HSUM(s5);
  S[6] = FCM_HSUM(s6), S[7] = FCM_HSUM(s7), S[8] = FCM_HSUM(s8);
#undef FCM_HSUM
#else
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      double t = 0.0;
      for (int a = 0; a < na; a++)
        t += U[i * na + a] * V[j * na + a];
      S[3 * i + j] = t;
    }
#endif
}

/* out[j na + a] = sum_k C[3k + j] V[k na + a] (add: out += ...) for a table by component V:
 * the physical gradients J^-T dN from the inverse Jacobian (C = J^-1), or the internal force's
 * wd sum_J P_iJ g_Ja (C = wd P^T). */
FCM_KERNEL_INLINE void combine(int na, const double C[9], const double *V, double *out, int add)
{
  for (int j = 0; j < 3; j++) {
    const double c0 = C[j], c1 = C[3 + j], c2 = C[6 + j];
    double *o = out + (size_t)j * na;
#if defined(__GNUC__) || defined(__clang__)
    for (int a = 0; a < na; a += 4) {
      fcm_v4d v0, v1, v2;
      memcpy(&v0, V + a, sizeof v0), memcpy(&v1, V + na + a, sizeof v1);
      memcpy(&v2, V + 2 * na + a, sizeof v2);
      const fcm_v4d sum = c0 * v0 + c1 * v1 + c2 * v2;
      put4(o + a, &sum, add);
    }
#else
    for (int a = 0; a < na; a++) {
      const double t = c0 * V[a] + c1 * V[na + a] + c2 * V[2 * na + a];
      o[a] = add ? o[a] + t : t;
    }
#endif
  }
}

/* The physical gradients of a point by component, g = J^-T dN (3 x na, zero where dT is), from
 * the cell's coordinates XT and the point's reference gradients dT; returns det J (not
 * positive: g is not written). */
FCM_KERNEL_INLINE double point_gradients(int na, const double *XT, const double *dT, double *g)
{
  double J[9], Ji[9];
  outer_sum(na, XT, dT, J);
  const double det = fcm__mat3_inv(J, Ji);
  if (!(det > 0.0)) return det;
  combine(na, Ji, dT, g, 0);
  return det;
}

/* det J of a point (the mass and body force need no gradients). */
FCM_KERNEL_INLINE double point_det(int na, const double *XT, const double *dT)
{
  double J[9];
  outer_sum(na, XT, dT, J);
  return fcm__mat3_det(J);
}

/* Physical gradients g (nn x 3, node-major) from the reference ones dN and the nodal
 * coordinates X; returns det J (not positive: g is not written). */
static double gradients(int nn, const double *X, const double *dN, double *g)
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

double fcm__kernel_point_gradients(int nn, const double *X, const double *dT, double *g)
{
  const int na = fcm__kernel_na(nn);
  double dN[3 * FCM_ELEMENT_MAX_NODES];
  for (int a = 0; a < nn; a++)
    for (int k = 0; k < 3; k++)
      dN[3 * a + k] = dT[k * na + a];
  return gradients(nn, X, dN, g);
}

/* With the rule's point-minor table (r->dQ): det J and J^-1 (row-major, Ji[k QB + c] entry k
 * of point q0 + c) of points [q0, q0 + nc) (q0 a multiple of 8), 8 points at a time in the
 * vector lanes: J_ij = sum_a X_ai dN_aj, then J^-1 = C^T / det J from the cofactors C (as
 * fcm__mat3_inv()). 0 without the table or vector types: the caller goes point by point. */
FCM_KERNEL_INLINE int chunk_jacobians(const cell_rule *r, int nn, const double *X, int q0, int nc,
                                      double *Ji, double *det)
{
#if defined(__GNUC__) || defined(__clang__)
  if (!r->dQ) return 0;
  const size_t qp = (size_t)r->qp;
  for (int c0 = 0; c0 < nc; c0 += 8) {
    fcm_v8d J[9] = {{0}}, C[9], d0, d1, d2;
    const double *d = r->dQ + q0 + c0;
    for (int a = 0; a < nn; a++, d += 3 * qp) {
      memcpy(&d0, d, sizeof d0), memcpy(&d1, d + qp, sizeof d1), memcpy(&d2, d + 2 * qp, sizeof d2);
      for (int i = 0; i < 3; i++) {
        const double x = X[3 * a + i];
        J[3 * i] += x * d0, J[3 * i + 1] += x * d1, J[3 * i + 2] += x * d2;
      }
    }
    C[0] = J[4] * J[8] - J[5] * J[7], C[1] = J[5] * J[6] - J[3] * J[8];
    C[2] = J[3] * J[7] - J[4] * J[6], C[3] = J[2] * J[7] - J[1] * J[8];
    C[4] = J[0] * J[8] - J[2] * J[6], C[5] = J[1] * J[6] - J[0] * J[7];
    C[6] = J[1] * J[5] - J[2] * J[4], C[7] = J[2] * J[3] - J[0] * J[5];
    C[8] = J[0] * J[4] - J[1] * J[3];
    const fcm_v8d dt = J[0] * C[0] + J[1] * C[1] + J[2] * C[2], s = 1.0 / dt;
    memcpy(det + c0, &dt, sizeof dt);
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) {
        const fcm_v8d v = s * C[3 * j + i];
        memcpy(Ji + (size_t)(3 * i + j) * FCM__KERNEL_QB + c0, &v, sizeof v);
      }
  }
  return 1;
#else
  (void)r, (void)nn, (void)X, (void)q0, (void)nc, (void)Ji, (void)det;
  return 0;
#endif
}

/* The gradients by component of points [q0, q0 + nc) of rule r into rows of G (zero padded to
 * ld), their weights w det J into wd and, with WG, the rows times w det J into WG; 0 with
 * res->bad_det set at the first point whose det J is not positive. */
FCM_KERNEL_INLINE int chunk_gradients(const cell_rule *r, int nn, int na, int q0, int nc, int ld,
                                      scratch *w, cell_result *res, double *WG)
{
  double Ji[9 * FCM__KERNEL_QB], dets[FCM__KERNEL_QB];
  const int lanes = chunk_jacobians(r, nn, w->X, q0, nc, Ji, dets);
  for (int c = 0; c < nc; c++) {
    double *g = w->G + (size_t)c * ld;
    const double *dT = r->dT + (size_t)(q0 + c) * 3 * na;
    double det;
    if (lanes) {
      double Jc[9];
      for (int k = 0; k < 9; k++)
        Jc[k] = Ji[k * FCM__KERNEL_QB + c];
      det = dets[c];
      if (det > 0.0) combine(na, Jc, dT, g, 0);
    } else {
      det = point_gradients(na, w->XT, dT, g);
    }
    if (!(det > 0.0)) {
      res->bad_det = det;
      return 0;
    }
    for (int k = 3 * na; k < ld; k++)
      g[k] = 0.0;
    const double wd = r->w[q0 + c] * det;
    w->wd[c] = wd;
    if (WG)
      for (int k = 0; k < ld; k++)
        WG[(size_t)c * ld + k] = wd * g[k];
  }
  return 1;
}

/* ------------------------------------------------------------------ the kernels */

/* Linear stiffness. With H = sum_q w_q det J_q g_q g_q^T over the gradients by component (row
 * and column (i, a) at i na + a; the upper triangle, row stride ld) the isotropic element
 * matrix is K_(a,i)(b,j) = lambda h_ij + mu h_ji + mu delta_ij sum_k h_kk, h_ij = H_(i,a)(j,b);
 * for a <= b every h_ij is in the upper triangle as H_(i,a)(j,b) (i <= j) or H_(j,b)(i,a). */
FCM_MULTIVERSION_CLONES
static cell_result stiffness_kernel(const kernel_data *kd, const cell_rule *r, int nn, scratch *w)
{
  const int na = fcm__kernel_na(nn), ld = fcm__kernel_ld(nn), nb = FCM_KERNEL_NB();
  cell_result res = {0.0, 1.0, 0, 0};
  double *H = w->H, *Kp = w->Ke;
  fcm__kernel_rows(nn, w->X, w->XT);
  if (r->nq == 0) memset(H, 0, sizeof *H * (size_t)ld * ld);
  for (int q0 = 0; q0 < r->nq; q0 += FCM__KERNEL_QB) {
    const int nc = r->nq - q0 < FCM__KERNEL_QB ? r->nq - q0 : FCM__KERNEL_QB;
    if (!chunk_gradients(r, nn, na, q0, nc, ld, w, &res, w->WG)) return res;
    product_upper(nb, nc, w->WG, w->G, 3 * na, ld, H, q0 > 0);
  }
  const double l = kd->lambda, m = kd->mu;
  for (int a = 0; a < nn; a++) {
    const double *H0 = H + (size_t)a * ld, *H1 = H + (size_t)(na + a) * ld;
    const double *H2 = H + (size_t)(2 * na + a) * ld;
    for (int b = a; b < nn; b++, Kp += 9) {
      const double *L0 = H + (size_t)b * ld, *L1 = H + (size_t)(na + b) * ld;
      const double h00 = H0[b], h01 = H0[na + b], h02 = H0[2 * na + b];
      const double h10 = L0[na + a], h11 = H1[na + b], h12 = H1[2 * na + b];
      const double h20 = L0[2 * na + a], h21 = L1[2 * na + a], h22 = H2[2 * na + b];
      const double tr = m * (h00 + h11 + h22);
      Kp[0] = l * h00 + m * h00 + tr, Kp[1] = l * h01 + m * h10, Kp[2] = l * h02 + m * h20;
      Kp[3] = l * h10 + m * h01, Kp[4] = l * h11 + m * h11 + tr, Kp[5] = l * h12 + m * h21;
      Kp[6] = l * h20 + m * h02, Kp[7] = l * h21 + m * h12, Kp[8] = l * h22 + m * h22 + tr;
    }
  }
  return res;
}

/* Consistent mass: the scalar matrix M = sum_q w_q det J_q rho N N^T on each component. */
FCM_MULTIVERSION_CLONES
static cell_result mass_kernel(const kernel_data *kd, const cell_rule *r, int nn, scratch *w)
{
  const int na = fcm__kernel_na(nn), ld = (nn + 15) / 16 * 16, nb = FCM_KERNEL_NB();
  cell_result res = {0.0, 1.0, 0, 0};
  double *H = w->H, *Kp = w->Ke;
  fcm__kernel_rows(nn, w->X, w->XT);
  if (r->nq == 0) memset(H, 0, sizeof *H * (size_t)ld * ld);
  for (int q0 = 0; q0 < r->nq; q0 += FCM__KERNEL_QB) {
    const int nc = r->nq - q0 < FCM__KERNEL_QB ? r->nq - q0 : FCM__KERNEL_QB;
    for (int c = 0; c < nc; c++) {
      const double det = point_det(na, w->XT, r->dT + (size_t)(q0 + c) * 3 * na);
      if (!(det > 0.0)) {
        res.bad_det = det;
        return res;
      }
      const double rw = r->w[q0 + c] * det * kd->rho, *N = r->N + (size_t)(q0 + c) * nn;
      double *n = w->G + (size_t)c * ld, *wn = w->WG + (size_t)c * ld;
      for (int a = 0; a < ld; a++)
        n[a] = a < nn ? N[a] : 0.0, wn[a] = rw * n[a];
    }
    product_upper(nb, nc, w->WG, w->G, (nn + 3) / 4 * 4, ld, H, q0 > 0);
  }
  for (int a = 0; a < nn; a++)
    for (int b = a; b < nn; b++, Kp += 9) {
      const double h = H[(size_t)a * ld + b];
      Kp[0] = h, Kp[1] = Kp[2] = Kp[3] = 0.0;
      Kp[4] = h, Kp[5] = Kp[6] = Kp[7] = 0.0;
      Kp[8] = h;
    }
  return res;
}

/* Body force fe (3nn): rho * accel, or the force density field b(X), against N. */
static cell_result body_force_kernel(const kernel_data *kd, const cell_rule *r, int nn, scratch *w)
{
  const int na = fcm__kernel_na(nn);
  cell_result res = {0.0, 1.0, 0, 0};
  double *fe = w->fe;
  memset(fe, 0, sizeof *fe * (size_t)(3 * nn));
  fcm__kernel_rows(nn, w->X, w->XT);
  for (int q = 0; q < r->nq; q++) {
    const double det = point_det(na, w->XT, r->dT + (size_t)q * 3 * na);
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
    /* one evaluation: mat_psd differs from mat in the tangent's projection only, so its
     * energy and force are mat's, bit for bit (and the corotated model's one SVD serves all
     * three outputs) */
    fcm__material_eval(&kd->mat_psd, F, psi, P, A);
    return;
  default:
    fcm__material_eval(kd->mat, F, psi, P, A);
    return;
  }
}

/* The material at point c of a chunk (gradients by component g, row c of w->G): energy, force
 * into w->FT (by component) and, with A, the tangent's factors of the point into the chunk's
 * rows of w->WG (g^T) and w->B (w det J A g_b, node-major); 0 with res->nonfinite set when the
 * material returned NaN or infinity. */
FCM_KERNEL_INLINE int hyperelastic_point(const kernel_data *kd, const cell_rule *r, int nn, int q,
                                         int c, int ld, scratch *w, cell_result *res)
{
  const int na = fcm__kernel_na(nn);
  const double *g = w->G + (size_t)c * ld, wd = w->wd[c];
  double F[9], psi = 0.0, P[9], A[81], C[9];
  outer_sum(na, w->UT, g, F);
  F[0] += 1.0, F[4] += 1.0, F[8] += 1.0;
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
  for (int i = 0; i < 3; i++) /* f_(a,i) += wd sum_J P_iJ g_Ja */
    for (int J = 0; J < 3; J++)
      C[3 * J + i] = wd * P[3 * i + J];
  combine(na, C, g, w->FT, 1);
  if (!kd->want_tangent) return 1;
  const size_t bi = (size_t)3 * FCM__KERNEL_QH * ld; /* B's stride between components i */
  for (int J = 0; J < 3; J++) {
    const double *gJ = g + (size_t)J * na;
    /* row (c, J) of the left factor: g_aJ (its first na entries are read) */
    memcpy(w->WG + (size_t)(3 * c + J) * ld, gJ, sizeof *gJ * (size_t)na);
    for (int i = 0; i < 3; i++) { /* B_i[(c, J)][(b, k)] = wd sum_L A_iJkL g_bL */
      double *row = w->B + i * bi + (size_t)(3 * c + J) * ld;
      const double *Am = A + 9 * (3 * i + J);
      for (int k = 0; k < 3; k++) {
        const double a0 = wd * Am[3 * k], a1 = wd * Am[3 * k + 1], a2 = wd * Am[3 * k + 2];
        for (int b = 0; b < nn; b++)
          row[3 * b + k] = a0 * g[b] + a1 * g[na + b] + a2 * g[2 * na + b];
      }
      for (int k = 3 * nn; k < ld; k++)
        row[k] = 0.0;
    }
  }
  return 1;
}

/* Hyperelastic energy, internal force fe and (want_tangent) tangent at the displacement
 * w->ue: F = I + sum_a u_a (x) g_a; f_(a,i) = sum_q wd P_iJ g_aJ and
 * K_(a,i)(b,k) = sum_q wd g_aJ A_iJkL g_bL with A = dP/dF, summed per chunk of points as
 * K_i[a][(b, k)] += sum_(c,J) g_caJ B_i[(c, J)][(b, k)] (row (a, i) of K, stride 3 ld in H). */
FCM_MULTIVERSION_CLONES
static cell_result hyperelastic_kernel(const kernel_data *kd, const cell_rule *r, int nn,
                                       scratch *w)
{
  const int ld = fcm__kernel_ld(nn), na = fcm__kernel_na(nn), nb = FCM_KERNEL_NB();
  cell_result res = {0.0, 1.0, 0, 0};
  double *H = w->H, *Kp = w->Ke;
  fcm__kernel_rows(nn, w->X, w->XT);
  fcm__kernel_rows(nn, w->ue, w->UT);
  if (kd->want_tangent && r->nq == 0) memset(H, 0, sizeof *H * (size_t)ld * ld);
  memset(w->FT, 0, sizeof *w->FT * (size_t)(3 * na));
  for (int q0 = 0; q0 < r->nq; q0 += FCM__KERNEL_QH) {
    const int nc = r->nq - q0 < FCM__KERNEL_QH ? r->nq - q0 : FCM__KERNEL_QH;
    if (!chunk_gradients(r, nn, na, q0, nc, ld, w, &res, NULL)) return res;
    for (int c = 0; c < nc; c++)
      if (!hyperelastic_point(kd, r, nn, q0 + c, c, ld, w, &res)) return res;
    if (!kd->want_tangent) continue;
    for (int i = 0; i < 3; i++) {
      const double *Bi = w->B + (size_t)i * 3 * FCM__KERNEL_QH * ld;
      for (int a0 = 0; a0 < na; a0 += 4)
        for (int b0 = 3 * a0 / nb * nb; b0 < ld; b0 += nb)
          micro(nb, 3 * nc, w->WG + a0, ld, Bi + b0, ld, H + (size_t)(3 * a0 + i) * ld + b0, 3 * ld,
                q0 > 0);
    }
  }
  for (int a = 0; a < nn; a++)
    for (int i = 0; i < 3; i++)
      w->fe[3 * a + i] = w->FT[i * na + a];
  if (!kd->want_tangent) return res;
  for (int a = 0; a < nn; a++) /* the upper node blocks a <= b */
    for (int b = a; b < nn; b++, Kp += 9)
      for (int i = 0; i < 3; i++)
        memcpy(Kp + 3 * i, H + (size_t)(3 * a + i) * ld + 3 * b, sizeof *Kp * 3);
  return res;
}

void fcm__kernel_symmetrize(int nn, double *Kp)
{
  for (int a = 0; a < nn; a++) {
    const double k01 = 0.5 * (Kp[1] + Kp[3]), k02 = 0.5 * (Kp[2] + Kp[6]);
    const double k12 = 0.5 * (Kp[5] + Kp[7]);
    Kp[1] = Kp[3] = k01, Kp[2] = Kp[6] = k02, Kp[5] = Kp[7] = k12;
    Kp += 9 * (nn - a); /* past blocks (a, a..nn) to (a + 1, a + 1) */
  }
}

cell_result fcm__cell_kernel(const kernel_data *kd, const cell_rule *r, int nn, scratch *w)
{
  cell_result res;
  switch (kd->kind) {
  case KERNEL_STIFFNESS:
    memset(w->fe, 0, sizeof *w->fe * (size_t)(3 * nn));
    res = stiffness_kernel(kd, r, nn, w);
    break;
  case KERNEL_MASS:
    memset(w->fe, 0, sizeof *w->fe * (size_t)(3 * nn));
    return mass_kernel(kd, r, nn, w);
  case KERNEL_BODY_FORCE:
    return body_force_kernel(kd, r, nn, w);
  default:
    res = hyperelastic_kernel(kd, r, nn, w);
    if (!kd->want_tangent) return res;
  }
  fcm__kernel_symmetrize(nn, w->Ke);
  return res;
}

void fcm__kernel_unpack(int nn, const double *Kp, double *Ke)
{
  const size_t ndof = 3 * (size_t)nn;
  for (int a = 0; a < nn; a++)
    for (int b = a; b < nn; b++, Kp += 9)
      for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
          Ke[(3 * a + i) * ndof + 3 * b + j] = Ke[(3 * b + j) * ndof + 3 * a + i] = Kp[3 * i + j];
}

/* Rows of WG: QB (linear kernels) or 3 QH (the hyperelastic kernel's left factor). */
enum { WG_ROWS = FCM__KERNEL_QB > 3 * FCM__KERNEL_QH ? FCM__KERNEL_QB : 3 * FCM__KERNEL_QH };

size_t fcm__kernel_scratch_size(int nn, size_t mq)
{
  const size_t ndof = 3 * (size_t)nn, ld = (size_t)fcm__kernel_ld(nn);
  const size_t na = (size_t)fcm__kernel_na(nn);
  return 3 * (size_t)nn + 2 * ndof + 3 * (size_t)nn + 3 * 3 * na + ld * ld + ndof * ndof + mq * nn +
         mq * 3 * na + FCM__KERNEL_QB * ld + WG_ROWS * ld + FCM__KERNEL_QB +
         9 * FCM__KERNEL_QH * ld;
}

void fcm__kernel_scratch_init(int nn, size_t mq, double *p, scratch *w)
{
  const size_t ndof = 3 * (size_t)nn, ld = (size_t)fcm__kernel_ld(nn);
  const size_t na = (size_t)fcm__kernel_na(nn);
  w->X = p, p += 3 * nn;
  w->ue = p, p += ndof;
  w->fe = p, p += ndof;
  w->g = p, p += 3 * nn;
  w->XT = p, p += 3 * na;
  w->UT = p, p += 3 * na;
  w->FT = p, p += 3 * na;
  w->H = p, p += ld * ld;
  w->Ke = p, p += ndof * ndof;
  w->Nb = p, p += mq * nn;
  w->dTb = p, p += mq * 3 * na;
  w->G = p, p += FCM__KERNEL_QB * ld;
  w->WG = p, p += WG_ROWS * ld;
  w->wd = p, p += FCM__KERNEL_QB;
  w->B = p;
}
