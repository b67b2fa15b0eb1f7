/* fcm — time integration of hyperelastic solids on a space (lib/METHOD.md §8): static Newton with
 * load steps and backward Euler on the incremental potential, Newton with a backtracking
 * line search on the energy, the stopping rule of Longva et al. (2020) §6, optional Rayleigh
 * damping, prescribed motion of node sets and, weakly (Nitsche's method or a penalty), of the
 * embedded-boundary points a selector picks, direct (CHOLMOD -> UMFPACK), Krylov (CG, MINRES)
 * or multigrid solves (fcm/mg.h: the Krylov preconditioner, or cycles alone).
 *
 * Phases: fcm_integrator_create() -> configure (fcm_integrator_add_*, set_state) ->
 * fcm_integrator_setup() (assembles the mass — dynamics only — and the loads, allocates
 * everything, analyzes the matrix) -> fcm_integrator_step() many times -> fcm_integrator_destroy().
 *
 * Backward Euler (unknown u = u_{n+1}, step h, D the damping matrix):
 *   E(u) = 1/2 (u - u^)^T M (u - u^)/h^2 + Psi(u) - f_ext(t_{n+1})^T u
 *          + 1/(2h) (u - u_n)^T D (u - u_n),     u^ = u_n + h v_n,
 *   v_{n+1} = (u_{n+1} - u_n)/h. Its gradient is M v' - f_total (v' = (v_{n+1} - v_n)/h).
 * Boundary constraints (fcm_integrator_add_boundary_constraint()) add their energy Pi_B(u)
 * (fcm_boundary_method) to E(u); it is not part of Psi (fcm_step_info.elastic_energy).
 * Rayleigh damping C = alpha_M M + beta_K K is linearized as D = alpha_M M + beta_K K+(u_n):
 * the tangent at the start of the (sub)step, projected to positive semi-definite and held
 * fixed during the step, so the damping force D v_{n+1} derives from the quadratic term above
 * (the Newton system stays symmetric, the line search sees a true energy, and D >= 0
 * dissipates). Static: E(u) = Psi(u) - f_ext^T u.
 *
 * Newmark (average acceleration), HHT-alpha and generalized-alpha (fcm_time_scheme; Chung and
 * Hulbert 1993) solve the same kind of incremental potential. With a_{n+1} = (u - u~)/(beta h^2),
 * u~ = u_n + h v_n + h^2 (1/2 - beta) a_n, v_{n+1} = v_n + h ((1 - gamma) a_n + gamma a_{n+1}),
 * the balance (1 - alpha_m) M a_{n+1} + alpha_m M a_n + (1 - alpha_f) (f_int(u_{n+1}) +
 * D v_{n+1} - f_ext(t_{n+1})) + alpha_f (f_int(u_n) + D v_n - f_ext(t_n)) = 0, divided by
 * 1 - alpha_f, is the gradient of
 *   E(u) = c/2 |u - u~|_M^2 + Psi(u) - f_ext(t_{n+1})^T u + gamma/(2 beta h) |u - u_d|_D^2
 *          - f_a^T u,   c = (1 - alpha_m)/((1 - alpha_f) beta h^2),
 * u_d = u~ - beta h/gamma (v_n + h (1 - gamma) a_n) and the constant force of the step
 * f_a = (alpha_f (f_ext(t_n) - f_int(u_n) - D v_n) - alpha_m M a_n)/(1 - alpha_f): the
 * internal and damping forces are interpolated (the HHT form), f_int includes the boundary
 * constraints' forces. Newmark: alpha_m = alpha_f = 0, beta = 1/4, gamma = 1/2; HHT (alpha in
 * [-1/3, 0]): alpha_m = 0, alpha_f = -alpha, beta = (1 - alpha)^2/4, gamma = 1/2 - alpha;
 * generalized-alpha (rho_inf in [0, 1]): alpha_m = (2 rho_inf - 1)/(rho_inf + 1), alpha_f =
 * rho_inf/(rho_inf + 1), gamma = 1/2 - alpha_m + alpha_f, beta = (1 - alpha_m + alpha_f)^2/4.
 * The first step computes a_0 from M a_0 = f_ext(t_0) - f_int(u_0) - D v_0 (lib/docs/
 * time_integration.md). */
#ifndef FCM_SIM_H
#define FCM_SIM_H

#include "fcm/core.h"
#include "fcm/fem.h"
#include "fcm/la.h"
#include "fcm/material.h"
#include "fcm/mg.h"
#include "fcm/motion.h"
#include "fcm/solve.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Newton stopping rules (g = gradient of E restricted to the free DOFs, 2-norm). */
typedef enum fcm_newton_tolerance {
  /** ||g|| <= tol ||M a_rep|| (Longva et al. §6: ||M v' - f_total|| <= 1e-5 ||M a_rep||);
   * a_rep is a uniform acceleration of magnitude rep_acceleration (M with free rows).
   * STATIC runs, which have no M, use the equal body force of rho a_rep instead. */
  FCM_NEWTON_TOL_REPRESENTATIVE = 0,
  /** ||g|| <= max(tol R, atol), R = max(||g|| at the start of the Newton solve,
   * ||f_int||, ||f_ext||) at the current iterate (force scale of the balance). */
  FCM_NEWTON_TOL_RELATIVE = 1,
  /** Chosen by the kind at setup: REPRESENTATIVE for BACKWARD_EULER, RELATIVE for STATIC
   * (which has no mass; the force-balance rule needs no extra body-force pass). */
  FCM_NEWTON_TOL_AUTO = 2
} fcm_newton_tolerance;

/** Time scheme of the dynamic kind (FCM_INTEGRATOR_DYNAMIC = FCM_INTEGRATOR_BACKWARD_EULER);
 * the formulas are at the top of this header. All are implicit, solved by the same Newton
 * iteration, and hold for linear and hyperelastic materials. */
typedef enum fcm_time_scheme {
  FCM_SCHEME_BACKWARD_EULER = 0, /**< first order, strongly dissipative (default) */
  /** Newmark's average acceleration (trapezoidal) rule, beta = 1/4, gamma = 1/2: second order,
   * no numerical dissipation (a linear undamped body keeps its energy) */
  FCM_SCHEME_NEWMARK = 1,
  /** Hilber-Hughes-Taylor alpha (fcm_integrator_options.hht_alpha): second order, dissipates
   * the high frequencies the more the more negative alpha is */
  FCM_SCHEME_HHT = 2,
  /** Chung-Hulbert generalized-alpha (fcm_integrator_options.rho_inf): second order, spectral
   * radius rho_inf at infinite frequency (1: none, 0: asymptotic annihilation) */
  FCM_SCHEME_GENERALIZED_ALPHA = 3,
  FCM_SCHEME_COUNT
} fcm_time_scheme;

/** Static name of a scheme ("backward_euler", "newmark", "hht", "generalized_alpha"; "invalid"
 * otherwise), the scene's "time.integrator" words. */
FCM_API const char *fcm_time_scheme_name(fcm_time_scheme scheme);

/** Linear solver of the Newton systems. */
typedef enum fcm_linear_solver {
  FCM_LINEAR_DIRECT = 0, /**< CHOLMOD; on "not positive definite" the PSD-projected tangent
                              (dynamic steps) or UMFPACK (static steps, PSD matrices) */
  FCM_LINEAR_CG = 1,     /**< preconditioned CG (SPD systems) */
  FCM_LINEAR_MINRES = 2, /**< preconditioned MINRES (symmetric, possibly indefinite) */
  /** Cut-aware geometric multigrid cycles as the solver (fcm/mg.h, options `multigrid`):
   * cycles on the Newton matrix itself from d = 0 until ||b - H d|| <= max(krylov_rtol ||b||,
   * krylov_atol), at most krylov_max_iterations cycles. Needs an SPD Newton matrix: static
   * steps, or dynamic ones (M/h^2 + K) with a linear material or a PSD tangent (project_psd).
   * Where it is not SPD the coarsest Cholesky factorization fails, a diagonal is not positive
   * or the cycles do not converge (stalled or diverging): the solve fails softly
   * (FCM_STEP_LINEAR_SOLVER_FAILED, or FCM_STEP_LINEAR_SOLVER_STAGNATED when the cycles
   * stalled: less than 5 % reduction in 20; a warning names the cause) and the step is
   * retried with half the increment, like a failed Krylov solve. Needs a Hex8 or Hex20 box grid
   * (fcm_mg_create()): on another mesh the first step fails with FCM_ERR_UNSUPPORTED. */
  FCM_LINEAR_MULTIGRID = 3
} fcm_linear_solver;

/** Preconditioner of the Krylov solvers. */
typedef enum fcm_preconditioner {
  FCM_PRECOND_NONE = 0,
  FCM_PRECOND_JACOBI = 1,       /**< inverse |diagonal| */
  FCM_PRECOND_BLOCK_JACOBI = 2, /**< inverse nodal 3x3 blocks */
  FCM_PRECOND_SCHWARZ = 3,      /**< additive Schwarz on cut cells with phi < schwarz_theta */
  /** One cycle of the cut-aware geometric multigrid (fcm/mg.h, options `multigrid`) from
   * z = 0, built on the preconditioner's matrix (preconditioner_tangent: the PSD tangent by
   * default, so also for MINRES on an indefinite Newton matrix). The cycle is an SPD
   * operator when pre_smooth = post_smooth (checked at setup), as CG and MINRES need. The
   * hierarchy is built at the first setup and again when the active constrained DOFs change
   * (the eliminated rows define the multigrid's Dirichlet boundary); later setups only
   * recompute the Galerkin matrices (fcm_mg_setup()). Needs a Hex8 or Hex20 box grid
   * (fcm_mg_create()): on another mesh the first step fails with FCM_ERR_UNSUPPORTED. */
  FCM_PRECOND_MULTIGRID = 4
} fcm_preconditioner;

/** The material tangent the Krylov preconditioner (Jacobi, block Jacobi, Schwarz, multigrid)
 * is built from, while the Krylov operator stays the exact Newton matrix base + K(u) (base:
 * the mass and damping terms). Without effect when the Newton matrix has a PSD tangent already
 * (project_psd, a linear material, a projection fallback). Scene key
 * "solver.preconditioner_tangent": "projected", "linear", "exact". */
typedef enum fcm_preconditioner_tangent {
  /** base + the PSD-projected tangent at the iterate (one more tangent assembly per
   * preconditioner setup); the Schwarz blocks of small cut cells are then positive definite
   * instead of indefinite or nearly singular, and the preconditioner is SPD as MINRES
   * requires (default) */
  FCM_PC_TANGENT_PROJECTED = 0,
  FCM_PC_TANGENT_LINEAR = 1, /**< base + the linear-elastic stiffness at rest (assembled once) */
  FCM_PC_TANGENT_EXACT = 2,  /**< the Newton matrix itself */
  FCM_PC_TANGENT_COUNT
} fcm_preconditioner_tangent;

/** A Newton iteration as reported to the monitor. */
typedef struct fcm_newton_event {
  double time;           /**< end time of the (sub)step being solved */
  int iteration;         /**< 0: the initial guess; k: after the k-th update */
  double residual;       /**< ||g|| on the free DOFs */
  double tolerance;      /**< the threshold of the stopping rule */
  double energy;         /**< E(u) of the (sub)step */
  double step_length;    /**< line-search factor of the update (0 at iteration 0) */
  int linear_iterations; /**< Krylov iterations or multigrid cycles (FCM_LINEAR_MULTIGRID)
                              of the update (0: direct or iteration 0) */
  int constraints_met;   /**< 1 when every constrained DOF sits on its prescribed value */
} fcm_newton_event;

/** Monitor callback, called after every Newton iteration (must not call the integrator). */
typedef void (*fcm_newton_monitor_fn)(void *user, const fcm_newton_event *event);

/** What a cut keeps of an integrator (fcm_integrator_options.cut_reuse, flags). */
typedef enum fcm_cut_reuse {
  FCM_CUT_REUSE_BLOCKS = 1,   /**< element mass and load blocks of the elements a cut leaves */
  FCM_CUT_REUSE_ORDERING = 2, /**< CHOLMOD's fill-reducing ordering, extended */
  FCM_CUT_REUSE_STORAGE = 4   /**< the large arrays themselves (a cut spends the old one) */
} fcm_cut_reuse;

/** Options; initialize with fcm_integrator_options_default(). These defaults are also the
 * scene's (the "solver" section of a scene file embeds this struct, fcm/scene.h; the key of
 * each member there is given in brackets). */
typedef struct fcm_integrator_options {
  fcm_integrator_kind kind;            /**< default BACKWARD_EULER (scene: "time.static",
                                            "time.integrator") */
  fcm_time_scheme scheme;              /**< dynamic kind: default FCM_SCHEME_BACKWARD_EULER (scene:
                                            "time.integrator"); STATIC ignores it */
  double hht_alpha;                    /**< FCM_SCHEME_HHT: alpha in [-1/3, 0] (default -0.05;
                                            scene: "time.alpha") */
  double rho_inf;                      /**< FCM_SCHEME_GENERALIZED_ALPHA: spectral radius at
                                            infinite frequency in [0, 1] (default 0.8; scene:
                                            "time.rho_inf") */
  double dt;                           /**< step > 0: time step, or the pseudo-time of a static step
                                            (default 1/60; scene: "time.dt") */
  int load_steps;                      /**< static: increments per step, >= 1 (default 1; scene:
                                            "time.load_steps") */
  int max_halvings;                    /**< retries of a failed (sub)step with half the increment,
                                            0..20 (default 4) */
  int newton_max_iterations;           /**< >= 1 (default 100) ["newton.max_iterations"] */
  fcm_newton_tolerance tolerance_mode; /**< default FCM_NEWTON_TOL_AUTO ["newton.rule"] */
  double newton_tolerance;             /**< tol in (0, 1) (default 1e-5) ["newton.rtol"] */
  double newton_atol;                  /**< RELATIVE mode: absolute floor >= 0 (default 0) */
  double rep_acceleration;  /**< |a_rep| > 0 in m/s^2 (default 9.81); FCM_DEFAULT: the magnitude of
                                 the first gravity load, or 9.81 without gravity. Its direction
                                 is that gravity's, else (1, 1, 1)/sqrt 3
                                 ["newton.representative_acceleration"] */
  int line_search;          /**< 1 (default): backtracking on E; 0: full Newton steps
                                 ["newton.line_search"] */
  double armijo;            /**< sufficient decrease c in (0, 0.5) (default 1e-4) */
  double backtrack;         /**< step factor in (0, 1) (default 0.5) */
  int max_backtracks;       /**< >= 0 (default 20) */
  int project_psd;          /**< 1: PSD-projected element tangents (default 0). Without it,
                                 a non-descent Newton direction is recomputed once with the
                                 projected tangent (counted as a projection fallback)
                                 ["newton.project_psd"] */
  int reuse_factorization;  /**< 1 (default): a dynamic step with the direct solver (the
                                 distributed backend's solver alike) solves a corrector
                                 iteration with the factorization of an earlier iterate or step
                                 (dropped by fcm_integrator_drop_factorization(), a change of
                                 dt, constraints or damping, a failed step), kept while every
                                 iteration solved with it reduces the residual norm by
                                 reuse_contraction or more (modified Newton: iterations without
                                 a tangent assembly or a factorization; the stopping rule is
                                 unchanged); an iteration that falls short, backtracks or meets
                                 a non-descent direction makes the next one factor anew. Unused
                                 under newton_fixed_iterations, whose steps keep the residual
                                 their last iteration reaches: there every iteration of a
                                 nonlinear material factors anew. 0: a new tangent and
                                 factorization every iteration ["newton.reuse_factorization"] */
  double reuse_contraction; /**< in (0, 1) (default 0.25) ["newton.reuse_contraction"] */
  /** Interactive steps (the graphics use; 0, the default, is the accurate rule above): N >= 1
   * makes every (sub)step run N Newton iterations and accept the iterate it reaches whatever
   * its residual (fcm_step_info.reason FCM_STEP_FIXED_ITERATIONS; residual, tolerance and
   * residual_reference report how far from the stopping rule it is, and the monitor sees every
   * iteration). It stops earlier only where the stopping rule already holds (reason
   * FCM_STEP_CONVERGED: a further update would be round-off). A failed line search, a failed
   * linear solve or NaN still fail the (sub)step, which is then halved as usual. The last
   * iteration assembles no tangent for a next one. Combine with multigrid_fixed_cycles for
   * the cost of Dick et al. (2011): 1 iteration of 3 V-cycles. newton_max_iterations and
   * reuse_factorization are then unused. A predictor iteration (prescribed motion) counts as
   * one. In [0, 10^6] ["newton.fixed_iterations"] */
  int newton_fixed_iterations;
  int cut_reuse; /**< what fcm_integrator_create_cut() keeps of this integrator, a sum of
                      fcm_cut_reuse flags (default 0: the new integrator is built from scratch).
                      FCM_CUT_REUSE_BLOCKS: the integrator keeps each element's mass and load
                      blocks (nn (nn + 1) / 2 + 3 nn per load doubles per element; a full serial
                      embedded space only) and after a cut integrates only the elements whose
                      rules the cut changed: the mass matrix and the loads are bit for bit those
                      of a rebuild. FCM_CUT_REUSE_ORDERING: CHOLMOD's analysis after a cut takes
                      the old ordering extended by the new DOFs (no AMD / METIS): a faster
                      analysis, but a factor with more fill than a fresh ordering's
                      (lib/docs/cutting.md). FCM_CUT_REUSE_STORAGE: the new integrator's
                      matrices take the storage of this one's where it is large enough (a
                      large matrix has a quarter more room than it needs), on pages already
                      mapped instead of new ones, whose first touch costs more than the
                      assembly at a few hundred thousand DOFs (a serial integrator only); so do
                      the Galerkin products of its multigrid hierarchy (their scratch and the
                      coarse levels' values, at its first set-up). With
                      this flag the room of the Newton and mass matrices, of the kept element
                      blocks and of the corotated element store is mapped when they are made:
                      a quarter more resident memory for them, no page faults when a cut grows
                      into it. After a successful cut this integrator is spent: it can only be
                      destroyed (its state, time and options still read; stepping, setting it up
                      or cutting it fails with FCM_ERR_ARG). A failed cut gives the storage back
                      (the mass matrix assembled again, the Newton matrix and corotated element
                      matrices at the next step). The results are the same bits. The scene
                      runner sets FCM_CUT_REUSE_BLOCKS | FCM_CUT_REUSE_STORAGE for a scene with
                      cuts [not a scene key] */
  fcm_linear_solver linear_solver;   /**< default FCM_LINEAR_DIRECT ["method"] */
  fcm_direct_method direct_method;   /**< first direct method (default CHOLMOD; UMFPACK: LU only)
                                          ["direct"] */
  fcm_preconditioner preconditioner; /**< Krylov only (default SCHWARZ: Jacobi outside the
                                          blocks of the small cut cells) ["preconditioner"] */
  fcm_preconditioner_tangent preconditioner_tangent; /**< Krylov only: the tangent the
                                          preconditioner is built from (default
                                          FCM_PC_TANGENT_PROJECTED) ["preconditioner_tangent"] */
  double krylov_rtol;                                /**< in [0, 1) (default 1e-8) ["rtol"] */
  double krylov_atol;                                /**< >= 0 (default 0) ["atol"] */
  int krylov_max_iterations;                         /**< >= 1 (default 1000) ["max_iterations"] */
  /** FCM_LINEAR_MULTIGRID only (refused with the other solvers: a direct solve is exact and
   * the Krylov solvers stop at krylov_rtol): K >= 1 makes every solve run exactly K cycles and
   * take their result without a convergence test (krylov_rtol, krylov_atol and
   * krylov_max_iterations unused; a non-finite or diverging result, past 1e3 ||b||, still
   * fails the solve). The first Newton iteration of a (sub)step starts its cycles from the
   * correction the Newton iterations of the previous accepted (sub)step of the same length
   * made to their initial guess (Dick et al. 2011: the last solution as the initial guess of
   * 3 V-cycles with 1 + 1 Gauss-Seidel sweeps), later ones from zero; a change of dt, a
   * failed step, fcm_integrator_set_state() and fcm_integrator_drop_factorization() start
   * cold. 0 (default): cycles until the tolerance. In [0, 1000] ["fixed_cycles"] */
  int multigrid_fixed_cycles;
  int krylov_stagnation_window;  /**< CG and MINRES: stop a solve whose smallest residual dropped
                                      by less than 0.1 % in this many iterations
                                      (fcm_krylov_options.stagnation_window; >= 0, default 50,
                                      0: off). Its iterate is still used when finite and
                                      nonzero; when the Newton iteration then fails, the step's
                                      reason is FCM_STEP_LINEAR_SOLVER_STAGNATED
                                      ["stagnation_window"] */
  double schwarz_theta;          /**< cut cells with volume fraction below it get a block, (0, 1]
                                      (default 0.5) ["schwarz.threshold"] */
  fcm_schwarz_options schwarz;   /**< default fcm_schwarz_options_default() ["schwarz.epsilon",
                                      "schwarz.clamp"] */
  fcm_mg_options multigrid;      /**< FCM_PRECOND_MULTIGRID and FCM_LINEAR_MULTIGRID: the
                                      hierarchy's options (default fcm_mg_options_default(),
                                      ranges as documented there and checked at setup, plus
                                      pre_smooth + post_smooth >= 1, and pre_smooth =
                                      post_smooth for the preconditioner) ["multigrid"] */
  double rayleigh_mass;          /**< alpha_M >= 0 in 1/s (default 0; scene: "damping") */
  double rayleigh_stiffness;     /**< beta_K >= 0 in s (default 0; scene: "damping") */
  fcm_assembly_options assembly; /**< strengths on full cells (default element defaults; scene:
                                      "quadrature") */
  fcm_newton_monitor_fn monitor; /**< NULL (default) or a callback */
  void *monitor_user;
} fcm_integrator_options;

/** The defaults listed on each member. */
FCM_API fcm_integrator_options fcm_integrator_options_default(void);

/** Why a step ended (the reason of the last attempt). */
typedef enum fcm_step_reason {
  FCM_STEP_NONE = 0,             /**< no step taken */
  FCM_STEP_CONVERGED,            /**< the stopping rule holds and the constraints are met */
  FCM_STEP_MAX_NEWTON,           /**< newton_max_iterations reached */
  FCM_STEP_LINE_SEARCH_FAILED,   /**< no sufficient decrease in max_backtracks halvings, or
                                      no descent direction */
  FCM_STEP_LINEAR_SOLVER_FAILED, /**< direct: both factorizations failed; Krylov: no usable
                                      iterate */
  FCM_STEP_NONFINITE,            /**< NaN/Inf in a load, the energy, the gradient or a solve */
  /** The linear solver stopped making progress — a Krylov solve stagnated
   * (krylov_stagnation_window) or broke down, or the multigrid cycles stalled — and Newton
   * could not go on with its result (no usable iterate, no descent, no sufficient decrease,
   * or newton_max_iterations with such a solve last): the Newton matrix is singular or
   * nearly so (rigid-body modes no constraint holds, which a static step checks before any
   * solve; a body held at too few points) or, for CG, not positive definite */
  FCM_STEP_LINEAR_SOLVER_STAGNATED,
  /** Accepted by the fixed-iteration rule (fcm_integrator_options.newton_fixed_iterations):
   * the Newton iterations ran out before the stopping rule held; fcm_step_info.residual is
   * above fcm_step_info.tolerance. A success, like FCM_STEP_CONVERGED */
  FCM_STEP_FIXED_ITERATIONS
} fcm_step_reason;

/** Name of a reason ("converged", "max-newton", "line-search-failed",
 * "linear-solver-failed", "nonfinite", "linear-solver-stagnated", "fixed-iterations",
 * "none"), or "unknown". Static string. */
FCM_API const char *fcm_step_reason_name(fcm_step_reason reason);

/** What one fcm_integrator_step() did. Per-step counts cover every attempt of the step;
 * total_* are cumulative since setup. */
typedef struct fcm_step_info {
  fcm_step_reason reason;         /**< CONVERGED or FIXED_ITERATIONS (newton_fixed_iterations)
                                       on success; else the last failure */
  int newton_iterations;          /**< Newton updates (all attempts) */
  int line_search_backtracks;     /**< step-length halvings */
  long long linear_iterations;    /**< Krylov iterations, or multigrid cycles with
                                       FCM_LINEAR_MULTIGRID (0 with the direct solver) */
  long long multigrid_cycles;     /**< multigrid cycles: the preconditioner applications of
                                       CG/MINRES with FCM_PRECOND_MULTIGRID, or the cycles of
                                       FCM_LINEAR_MULTIGRID (0 otherwise) */
  double residual;                /**< final ||g|| of the last attempt */
  double tolerance;               /**< its threshold */
  double residual_reference;      /**< the stopping rule's reference: ||M a_rep|| (or the
                                       equal body force's) for REPRESENTATIVE, R for RELATIVE;
                                       residual / residual_reference is the relative residual
                                       that the rule compares with newton_tolerance */
  double dt;                      /**< length of the last (sub)step: time (dynamics) or
                                       pseudo-time (static) */
  int halvings;                   /**< halvings needed (0: the step went through at once) */
  int substeps;                   /**< accepted (sub)steps (static: load increments) */
  int failed_attempts;            /**< (sub)step attempts that were rejected */
  double time;                    /**< time after the step (unchanged on failure) */
  double kinetic_energy;          /**< 1/2 v^T M v (0 for static) */
  double elastic_energy;          /**< Psi(u) */
  double external_work;           /**< f_ext(t)^T u */
  double total_energy;            /**< kinetic + elastic - external work */
  double load_work;               /**< cumulative work of the external loads (gravity, body
                                       forces, tractions) since the start, in J: the sum over the
                                       accepted (sub)steps of 1/2 (f_ext(t_k) + f_ext(t_{k+1}))^T
                                       (u_{k+1} - u_k) (trapezoidal in time;
                                       fcm_integrator_load_work()) */
  fcm_index inverted_points;      /**< quadrature points of the body (the authentic points:
                                       fictitious stabilization points of cut cells left out)
                                       with J = det F <= 0 at the state the step ended in (0 on
                                       failure); the Cauchy stress of fcm_space_element_stress()
                                       is NaN there. Counted in the step's last energy
                                       assembly, at no extra cost */
  fcm_index inverted_cell;        /**< background cell of the first of them (lowest element,
                                       then rule order), -1 when there is none */
  double inverted_position[3];    /**< that point's reference position X (0 when none) */
  double inverted_det;            /**< J there (<= 0; 0 when none) */
  int tangent_assemblies;         /**< tangent assemblies (Newton and damping matrices) */
  int factorizations;             /**< numeric factorizations or preconditioner setups */
  int direct_fallbacks;           /**< CHOLMOD "not positive definite" -> UMFPACK (static
                                       steps; a dynamic step's exact tangent: projected) */
  int projection_fallbacks;       /**< non-descent directions recomputed with PSD tangents */
  int reused_factorizations;      /**< iterations solved with a kept factorization
                                       (fcm_integrator_options.reuse_factorization) */
  int inexact_solves;             /**< Krylov solves stopped early whose iterate was used */
  long long total_analyses;       /**< symbolic analyses (CHOLMOD and UMFPACK) */
  long long total_factorizations; /**< numeric factorizations / preconditioner setups */
  long long total_direct_fallbacks;
  long long total_multigrid_creations; /**< multigrid hierarchies created, prepared ones
                                            (fcm_integrator_prepare_solver()) included: a
                                            step that only sets up the values creates none */
  double time_assembly;                /**< seconds: energy, force, tangent and damping assembly */
  double time_factor;                  /**< seconds: factorization or preconditioner setup */
  double time_solve;                   /**< seconds: triangular or Krylov solves */
  double time_total;                   /**< seconds of the whole step */
} fcm_step_info;

/** A scalar function of time, e.g. the time scaling of a load. */
typedef double (*fcm_time_fn)(void *user, double t);

/** An integrator on a space (opaque). */
typedef struct fcm_integrator fcm_integrator;

/** Create an integrator with zero displacement and velocity at t = 0.
 * @param[in]  ctx   context; must outlive the integrator
 * @param[in]  space borrowed (plain or embedded); must outlive the integrator. Only read:
 *                   the integrator keeps its own assembly workspace, so several
 *                   integrators may share a space
 * @param[in]  mat   the material (copied; validated here)
 * @param[in]  opts  copied; NULL for defaults (validated by fcm_integrator_setup())
 * @param[out] integ the new integrator, NULL on failure
 * @return FCM_OK, FCM_ERR_ARG (NULL, invalid material), FCM_ERR_ALLOC. Allocates O(n). */
FCM_API fcm_status fcm_integrator_create(fcm_ctx *ctx, const fcm_space *space,
                                         const fcm_material *mat,
                                         const fcm_integrator_options *opts,
                                         fcm_integrator **integ);

/** Destroy; accepts NULL and `*integ == NULL`, sets `*integ = NULL`. */
/** Continue a run across a cut (XFEM). `space` is the embedded space of rules that
 * extend the rules of old's space by one cut (fcm_cell_rules_create_cut(), then
 * fcm_space_create_embedded()). The new integrator has old's material, options, loads and
 * constraints (same callbacks and user pointers, node lists copied), is set up (mass and
 * loads assembled on the new space) with its linear solver's structure built for the new
 * pattern (fcm_integrator_prepare_solver(): the direct solver's symbolic analysis, the
 * multigrid hierarchy without values; the step after the cut sets up the values only), and
 * starts from old's time, step count, displacement and velocity carried
 * over by fcm_space_transfer(): every new DOF copy inherits its parent copy's values, so
 * the field, the mass and the linear and angular momentum are unchanged by the cut; the
 * acceleration (when known) likewise, and the load work. A host
 * simulator calls it between steps and then destroys `old` (and old's space and rules).
 * With old's options' cut_reuse (fcm_cut_reuse): FCM_CUT_REUSE_BLOCKS integrates again only
 * the elements whose rules the cut changed (the mass matrix and the loads are the same bits as
 * without it); FCM_CUT_REUSE_ORDERING analyses with old's CHOLMOD ordering extended by the new
 * DOFs beside their parents (no AMD / METIS; more fill than a fresh ordering);
 * FCM_CUT_REUSE_STORAGE gives old's large arrays to the new integrator (on FCM_OK old can then
 * only be destroyed; on failure old has them back and goes on). The DOF
 * numbering is the space's own (fcm_space_create_embedded()), as without them.
 * @return FCM_OK; FCM_ERR_ARG (NULL, old not set up, unrelated space); the errors of
 *         fcm_integrator_setup() and fcm_integrator_prepare_solver(); FCM_ERR_ALLOC.
 *         Allocates. */
FCM_API fcm_status fcm_integrator_create_cut(const fcm_integrator *old, const fcm_space *space,
                                             fcm_integrator **integ);

/** Continue a run on a refined background: `space` is a space (fcm_space_create(), or
 * fcm_space_create_embedded() on rules of the same geometry) on a refinement of old's octree
 * mesh (fcm_mesh_create_refined(): every new cell inside an old one). The new integrator has
 * old's material, options, loads, boundary constraints (Nitsche) and contacts (the same
 * callbacks and user pointers), and old's node constraints mapped onto the new mesh: a node
 * is held by a constraint when the old field at its position depends only on nodes the
 * constraint held (an old held node; a new node on an edge, a face or inside an old cell
 * whose nodes there are all held: the motions are affine in the position, so the old
 * constraint fixed the field there already). It is set up (mass and loads assembled on the
 * new space) and starts from old's time, step count and load work, and its displacement,
 * velocity and (when known) acceleration interpolated at the new nodes. The new space
 * contains the old one (a refined octree with its hanging nodes constrained), so the fields
 * are reproduced exactly: on a plain space (no rules) or rules that integrate the same body
 * exactly, the mass, the linear and angular momentum and the kinetic energy are kept to
 * rounding. Embedded rules are built anew on the finer cells, so an embedded body's
 * quadrature changes; a new node in no active old cell (a cell the old rules dropped below
 * min_fraction whose finer cells hold enough material) takes the old field extrapolated
 * from the nearest old cell, counted in fcm_integrator_setup_info.refine_extrapolated.
 * Not carried: contact state (friction anchors restart, as after a cut), the direct
 * solver's analysis and factorization. A host simulator calls it between steps and then
 * destroys `old` (and old's space, rules and mesh).
 * @return FCM_OK; FCM_ERR_ARG (NULL, old not set up, other element type); FCM_ERR_UNSUPPORTED
 *         (a space with DOF copies, i.e. after a cut: refinement is supported before the first
 *         cut only; a distributed backend); the errors of fcm_space_locate() and
 *         fcm_integrator_setup() (e.g. a held hanging node whose masters are free);
 *         FCM_ERR_ALLOC. Allocates. */
FCM_API fcm_status fcm_integrator_create_refined(const fcm_integrator *old, const fcm_space *space,
                                                 fcm_integrator **integ);

FCM_API void fcm_integrator_destroy(fcm_integrator **integ);

/** Add gravity: body force rho a, times scale(t) when `scale` is given (else 1). Before
 * setup. @return FCM_OK, FCM_ERR_ARG (non-finite a, after setup), FCM_ERR_ALLOC. */
FCM_API fcm_status fcm_integrator_add_gravity(fcm_integrator *integ, const double accel[3],
                                              fcm_time_fn scale, void *scale_user);

/** Add a body force density b(x) (force per volume; fcm_assemble_body_force_field()),
 * times scale(t). `user` must outlive the setup. Before setup. Codes as above. */
FCM_API fcm_status fcm_integrator_add_body_force(fcm_integrator *integ, fcm_field_fn field,
                                                 void *user, fcm_time_fn scale, void *scale_user);

/** Add a surface traction t(x, n) on the embedded boundary (fcm_assemble_surface_traction();
 * the space needs surface rules), times scale(t). Before setup. Codes as above. */
FCM_API fcm_status fcm_integrator_add_traction(fcm_integrator *integ, fcm_field_fn traction,
                                               void *user, fcm_time_fn scale, void *scale_user);

/** Prescribe the motion of `num_nodes` mesh nodes (copied; nodes without DOFs, e.g. of
 * dropped cells, are skipped). A DOF may belong to one constraint only (checked at setup).
 * Before setup. @param[out] id the constraint's index (may be NULL)
 * @return FCM_OK, FCM_ERR_ARG (node out of range, bad motion: the message names the member),
 * FCM_ERR_ALLOC. */
FCM_API fcm_status fcm_integrator_add_constraint(fcm_integrator *integ, fcm_index num_nodes,
                                                 const fcm_index *nodes, const fcm_motion *motion,
                                                 int *id);

/** How a boundary constraint imposes its motion on the embedded boundary. */
typedef enum fcm_boundary_method {
  /** Symmetric Nitsche (consistent, optimal convergence): with r = P_c (u - g) the constrained
   * components of the gap to the prescribed displacement g and t = P(F) N the first Piola
   * traction on the reference boundary (outward unit normal N), the energy gains
   * int_Gamma ( -t . r + gamma/2 |r|^2 ) dA. Its gradient is the weak form
   * -int t . P_c dv - int (dP/dF[grad dv] N) . r + gamma int r . dv (consistency, adjoint
   * consistency with the linearized traction, penalty), the Newton matrix its exact Hessian
   * (the term with the third derivative of Psi times r, by central differences of dP/dF;
   * zero for LINEAR and where u = g). For linear elasticity this is classical symmetric
   * Nitsche. gamma per element (cell piece): nitsche_safety times the largest eigenvalue of
   * T v = lambda K v, T = int_Gamma_K |P_c sigma(v) N|^2 (the boundary traction energy of
   * the element's selected points), K the element's linear-elastic stiffness at rest with
   * its stabilization points (so gamma stays bounded, by about 1/alpha, on tiny cut cells);
   * rigid modes (T = K = 0) are left out. safety > 1 makes the energy's Hessian at rest
   * positive definite on the free modes (coercivity constant 1 - 1/safety). Far from rest
   * (strains of order 1) the estimate at rest may no longer bound the energy from below and
   * Newton can fail: raise nitsche_safety (10 to 20) or use the penalty. A Newton matrix made
   * singular there is retried with the penalty part of the boundary terms only, then with
   * halved steps. */
  FCM_BOUNDARY_NITSCHE = 0,
  /** Penalty: energy gamma/2 int_Gamma |r|^2 with gamma = penalty E / h_K (h_K the cube root
   * of the cell's volume). Not consistent: the error is O(h/penalty) in the constraint. */
  FCM_BOUNDARY_PENALTY = 1,
  FCM_BOUNDARY_METHOD_COUNT
} fcm_boundary_method;

/** Static name of a method ("nitsche", "penalty"; "invalid" otherwise). */
FCM_API const char *fcm_boundary_method_name(fcm_boundary_method method);

/** Options of fcm_integrator_add_boundary_constraint(); fcm_boundary_options_default(). */
typedef struct fcm_boundary_options {
  fcm_boundary_method method; /**< default FCM_BOUNDARY_NITSCHE */
  double nitsche_safety;      /**< NITSCHE: gamma = safety x lambda_max, > 1 (default 2) */
  double penalty;             /**< PENALTY: gamma = penalty E / h, > 0 (default 1e3) */
  fcm_field_fn displacement;  /**< NULL (default): the motion's displacement; else the prescribed
                                   displacement g(X) = displacement(user, X, N) at reference
                                   position X with outward normal N (not time dependent: the
                                   motion still gives the components and the active window) */
  void *displacement_user;    /**< passed to displacement; must outlive the integrator */
} fcm_boundary_options;

/** The defaults listed on each member. */
FCM_API fcm_boundary_options fcm_boundary_options_default(void);

/** Selects embedded-boundary points: 1 to constrain the point with reference position X and
 * unit outward normal `normal`, else 0. Called during fcm_integrator_setup() only (serially).
 * fcm_region_select() of fcm/scene.h adapts an fcm_region. */
typedef int (*fcm_boundary_select_fn)(void *user, const double X[3], const double normal[3]);

/** Prescribe `motion` weakly on the embedded-boundary points (the surface rules of the space's
 * cell rules) that `select` picks (NULL: every point): u(X, t) = the motion's displacement
 * (fcm_motion_eval()) on its constrained components, by Nitsche's method or a penalty
 * (`opts`, NULL: defaults; see fcm_boundary_method). No DOF is eliminated: the terms join the
 * energy, the force and the Newton matrix (which stays symmetric, so the direct solver, CG and
 * MINRES all apply), for static and dynamic integrators. A point several boundary
 * constraints select belongs to the first. After `end` the constraint holds (or, with
 * `release`, is dropped). `user` must outlive the setup. Before setup.
 * @param[out] id the boundary constraint's index (may be NULL)
 * @return FCM_OK, FCM_ERR_ARG (NULL integrator or motion; a bad motion or option, named;
 * called after setup), FCM_ERR_ALLOC. The setup fails with FCM_ERR_ARG when the space has no
 * surface rules or the constraint selects no point. */
FCM_API fcm_status fcm_integrator_add_boundary_constraint(fcm_integrator *integ,
                                                          fcm_boundary_select_fn select, void *user,
                                                          const fcm_motion *motion,
                                                          const fcm_boundary_options *opts,
                                                          int *id);

/** The largest penalty gamma (Pa/m) the boundary constraints use in element `elem`
 * (fcm_space_num_elements()): Nitsche's estimate or penalty E / h, after setup; 0 for an
 * element without constrained points or out of range. */
FCM_API double fcm_integrator_boundary_penalty(const fcm_integrator *integ, fcm_index elem);

/** Reaction of boundary constraint `id` at the current state: the force and the moment about
 * the origin that it exerts on the body, force = sum over its points of w (P(F) N - gamma r)
 * (penalty: -w gamma r) and moment = sum of (X + u) x that, with its motion at the current
 * time (zeros when released). At equilibrium the reactions balance the loads. Either output
 * may be NULL. After setup. Allocates nothing.
 * @return FCM_OK, FCM_ERR_ARG (NULL, not set up, id out of range). */
FCM_API fcm_status fcm_integrator_boundary_reaction(const fcm_integrator *integ, int id,
                                                    double force[3], double moment[3]);

/** The boundary constraints' part of the energy alone at displacement u and time t (their
 * motions evaluated at t; released constraints left out): energy, force (added, num_dofs)
 * and Newton matrix (added; the space's pattern, fcm_space_matrix_create(); in a distributed
 * run the integrator's local rows, as fcm_integrator_mass() has them), each may be
 * NULL. Summed over the DOFs of each component the force is minus the total reaction
 * (fcm_integrator_boundary_reaction(): the partition of unity cancels the gradient terms).
 * After setup. Allocates nothing.
 * @return FCM_OK, FCM_ERR_ARG (NULL, not set up, wrong matrix), FCM_ERR_NUMERIC (the
 * material gave NaN/Inf). */
FCM_API fcm_status fcm_integrator_boundary_eval(fcm_integrator *integ, const double *u, double t,
                                                double *energy, double *force, fcm_csr *tangent);

/** Options of fcm_integrator_add_contact_plane(); fcm_contact_options_default(). */
typedef struct fcm_contact_options {
  double distance;  /**< the barrier's threshold d^ (m), > 0; 0 (default): 0.1 h, h the
                         largest extent of a cell holding embedded-surface points */
  double stiffness; /**< the barrier's stiffness kappa (Pa/m), > 0; 0 (default): E / h, E the
                         material's Young modulus */
  double friction;  /**< Coulomb coefficient mu >= 0 (default 0: frictionless); lagged and
                         smoothed as in IPC: each point's normal force and tangent plane from
                         the substep's start, the slip's dissipation potential
                         mu lambda f0(|slip|) smoothed below eps_v h (dynamic schemes only) */
  double friction_velocity; /**< eps_v (m/s) >= 0: slip velocities below it see a friction
                                 force that falls smoothly to 0; 0 (default): 1e-3 m/s */
  int friction_updates;     /**< in [0, 20]: after a substep's Newton solve converged, up to
                                 this many times the lagged normal forces and tangents are taken
                                 anew at the converged state and Newton solves again from it
                                 (fixed-point outer iterations; they stop once the largest
                                 normal force changes by at most 1e-3 of the largest); 0
                                 (default): lagged from the substep's start only. The largest
                                 value over the obstacles applies */
  int self_contact;         /**< 0 (default) or 1, fcm_integrator_add_contact_bodies() only
                                 (the obstacles refuse 1): also keep each body's samples off
                                 its own triangles (self-contact), except the pairs whose
                                 reference distance (the sample to the triangle, both
                                 undeformed) is below 2 d^: a sample always lies on its own and
                                 adjacent triangles, and parts that close in the reference state
                                 are taken to be joined by material. Costs a reference
                                 point-triangle distance per own triangle within d^ of each
                                 sample at each evaluation (lib/docs/contact.md) */
} fcm_contact_options;

/** The defaults listed on each member. */
FCM_API fcm_contact_options fcm_contact_options_default(void);

/** A rigid half-space obstacle: the body stays on the side n . (x - p(t)) > 0 of the plane
 * through p(t) = point + velocity t with unit normal n = normal / |normal|. The contact acts
 * on the embedded surface's points (the surface rules of the space's cell rules, at their
 * current positions x = X + u(X)) through the smooth log barrier of Li et al. (2020,
 * incremental potential contact): with the distance d = n . (x - p(t)) of a point of area
 * weight w, the energy gains w kappa b(d), b(d) = -(d - d^)^2 ln(d / d^) for 0 < d < d^ and 0
 * beyond (C2 at d^, infinite at 0, convex: its Hessian w kappa b''(d) N_a N_b n (x) n is
 * positive semidefinite). Its gradient and Newton matrix join the incremental potential's, and
 * the line search never crosses into penetration: every Newton step is first shortened to 0.9
 * times the largest fraction that keeps each point at d > 0 (the distance is linear in the
 * step for a plane), then backtracked on the energy; a substep's first guess that penetrates is
 * pulled back the same way from the substep's start. A state on or behind a plane (d <= 0) is
 * refused by the setup and by each step with the point and its distance. Coulomb friction:
 * fcm_contact_options.friction. Contact between bodies: fcm_integrator_add_contact_bodies().
 * Not supported: distributed backends. Before setup.
 * @param[out] id the obstacle's index (may be NULL)
 * @return FCM_OK, FCM_ERR_ARG (NULL integrator or vector; a zero or non-finite normal; a
 * non-finite point or velocity; a negative or non-finite option, named; after setup),
 * FCM_ERR_ALLOC. The setup fails with FCM_ERR_ARG when the space has no surface rules or a
 * point starts on or behind a plane, FCM_ERR_UNSUPPORTED with a distributed backend. */
FCM_API fcm_status fcm_integrator_add_contact_plane(fcm_integrator *integ, const double point[3],
                                                    const double normal[3],
                                                    const double velocity[3],
                                                    const fcm_contact_options *opts, int *id);

/** A rigid solid sphere of `radius` about `center`, static (motion NULL) or moved rigidly by
 * `motion` (fcm_motion_eval(): x(t) = c + R(tau) (X - c) + velocity tau, held after `end`;
 * `components` and `release` are ignored): the body stays outside it. The barrier is that of
 * fcm_integrator_add_contact_plane() with the distance d = |x - c(t)| - radius. Each point's
 * Newton matrix is w kappa b''(d) g g^T with g the distance's gradient: the positive
 * semidefinite part of its exact Hessian w kappa (b'' g g^T + b' H), H the distance's Hessian
 * (fcm_integrator_contact_distance()); the force is exact. The step filter is the exact first
 * parameter where a point's straight path meets the sphere (the obstacle is fixed within a
 * Newton iteration, at the substep's end). A point on or inside the sphere is refused as for
 * planes (the message gives its depth). Before setup.
 * @return FCM_OK, FCM_ERR_ARG (NULL integrator or centre; a radius <= 0 or non-finite; a
 * non-finite motion, end < start, a rotation about a zero axis; a negative or non-finite
 * option, named; after setup), FCM_ERR_ALLOC. */
FCM_API fcm_status fcm_integrator_add_contact_sphere(fcm_integrator *integ, const double center[3],
                                                     double radius, const fcm_motion *motion,
                                                     const fcm_contact_options *opts, int *id);

/** A rigid solid box [lo, hi] (in its own frame, placed by `motion` as for
 * fcm_integrator_add_contact_sphere(), NULL: static): the body stays outside it. The distance
 * is the Euclidean distance to the box (its faces, edges and corners), negative inside.
 * Otherwise as fcm_integrator_add_contact_sphere().
 * @return as fcm_integrator_add_contact_sphere(), FCM_ERR_ARG also for lo[i] >= hi[i]. */
FCM_API fcm_status fcm_integrator_add_contact_box(fcm_integrator *integ, const double lo[3],
                                                  const double hi[3], const fcm_motion *motion,
                                                  const fcm_contact_options *opts, int *id);

/** A rigid solid bounded by a closed triangle surface (coords: num_vertices x 3, tris:
 * num_triangles x 3 0-based, both copied; in its own frame, placed by `motion` as for
 * fcm_integrator_add_contact_sphere(), NULL: static): the body stays outside it. The distance
 * of a point is the point-triangle distance to its closest triangle (face, edge or vertex
 * region), found through an AABB tree over the triangles within the threshold d^, so the cost
 * per point grows with the triangles near it, not with all of them; inside is decided by the
 * parity of a ray's crossings, which needs the surface closed: an open or non-manifold
 * surface is refused, naming its first open edge. The step filter is the exact first crossing
 * of a point's straight path with a triangle. A moving surface that swallows a point within a
 * substep makes that substep fail (it is halved like any non-finite substep). Otherwise as
 * fcm_integrator_add_contact_sphere().
 * @return as fcm_integrator_add_contact_sphere(), FCM_ERR_ARG also for NULL arrays, fewer than
 * 4 vertices or triangles, a vertex id out of range or a non-finite coordinate, a surface not
 * closed or not manifold (naming the first such edge). */
FCM_API fcm_status fcm_integrator_add_contact_surface(fcm_integrator *integ, fcm_index num_vertices,
                                                      const double *coords, fcm_index num_triangles,
                                                      const fcm_index *tris,
                                                      const fcm_motion *motion,
                                                      const fcm_contact_options *opts, int *id);

/** Contact between the separate bodies of the space and between the pieces its cuts make
 * (fcm_space_num_bodies(): elements joined through shared DOF copies). The surface is the
 * embedded surface of `geom` in the space (fcm_embedded_surface_create(): the boundary
 * triangles split by the cuts, and both sides of every cut face), each point moving with the
 * element that holds it. Sample points of each body's surface (the triangles' vertices and
 * three interior points per triangle, weighted by area) are kept away from the triangles of
 * every other body by the barrier of fcm_integrator_add_contact_plane() on the point-triangle
 * distance (exact force on the DOFs of the sample's and the triangle's elements; the Newton
 * matrix holds a block-diagonal bound of the pairs' positive semidefinite part, as the space's
 * pattern does not couple different pieces, and Newton's direction is refined by conjugate
 * gradients on the coupled matrix, preconditioned by its factorization). Broad phase: a
 * bounding-volume hierarchy per body over the deformed triangles, rebuilt at each substep and
 * refitted at each evaluation. The step filter keeps every pair at positive distance (a
 * conservative bound from the points' motions). Self-contact of one body:
 * fcm_contact_options.self_contact (off by default): a body's samples are also kept off its
 * own triangles, but for the pairs within 2 d^ of each other in the reference state (never
 * repelled; parts of a body closer than 2 d^ undeformed do not see each other); the step
 * filter bounds these pairs by the relative motion (a rigid motion of the body never limits a
 * step). A self pair that starts at distance <= 0 (a deformed start) makes the first
 * evaluation non-finite.
 * Pieces that start within d^ of each other (the two sides of a cut) see, instead of the
 * barrier, a penalty w kappa s^2 / 2 on the gap s < 0 below the other piece's closest face (lagged
 * at each substep's start) until the sample is d^ away at a substep's start; from then on the
 * barrier keeps them apart. One per integrator; carried over by
 * fcm_integrator_create_cut() (the surface is split again by the new cuts). Friction
 * (fcm_contact_options.friction > 0, dynamic schemes): each pair within d^ at the substep's
 * start keeps its normal force, closest point and tangent plane (lagged), and the sample's slip
 * relative to that point of the triangle over the substep gets the smoothed Coulomb potential
 * of the obstacles (friction_velocity, friction_updates as there); the pieces that started in
 * contact at a cut (the penalty) have none. Static solves: a piece within d^ of a piece held
 * in all its rigid modes counts as held along the pairs' directions (the static check of the
 * rigid modes), and only the pieces within 1e-9 d^ of each other at the start (the sides of a
 * cut) ignore each other. Before setup; the setup needs surface rules.
 * @param[in] geom borrowed: the geometry the space's rules were built on; must outlive the
 *                 integrator (and the integrators its cuts create)
 * @return FCM_OK, FCM_ERR_ARG (NULL; a second call; self_contact not 0 or 1; the
 * options as for planes), FCM_ERR_ALLOC. */
FCM_API fcm_status fcm_integrator_add_contact_bodies(fcm_integrator *integ,
                                                     const fcm_geometry *geom,
                                                     const fcm_contact_options *opts, int *id);

/** The signed distance of the world point x to obstacle `id` at time t (negative inside or
 * behind it), its gradient (3) and Hessian (9, row-major; may be NULL each): planes are
 * affine (H = 0), spheres give (I - g g^T) / |x - c|, boxes and surfaces the Hessian of the
 * closest face (0), edge ((I - e e^T - g g^T) / d, e the edge's unit direction) or corner
 * ((I - g g^T) / d). A surface's closest triangle is searched without a threshold. Before or
 * after setup. Allocates workspace only.
 * @return FCM_OK, FCM_ERR_ARG (NULL integrator, point or distance; id out of range),
 * FCM_ERR_ALLOC. */
FCM_API fcm_status fcm_integrator_contact_distance(const fcm_integrator *integ, int id,
                                                   const double x[3], double t, double *distance,
                                                   double gradient[3], double hessian[9]);

/** Contact obstacle `id` at the current state and time: the force the obstacle exerts on the
 * body (sum over the points of -w kappa b'(d) g, g the distance's gradient; zero beyond the
 * threshold) and the smallest signed distance of an embedded-surface point to it (either may
 * be NULL; a surface obstacle tests each point's side with a ray); its threshold and stiffness
 * (the defaults resolved) in dhat and kappa (each may be NULL). After setup. Allocates
 * workspace only for surface obstacles.
 * @return FCM_OK, FCM_ERR_ARG (NULL, not set up, id out of range), FCM_ERR_ALLOC. */
FCM_API fcm_status fcm_integrator_contact_info(const fcm_integrator *integ, int id, double force[3],
                                               double *min_distance, double *dhat, double *kappa);

/** The contact obstacles' state, for logs and summaries (fcm_integrator_contact_stats()). */
typedef struct fcm_contact_stats {
  long long evaluations;       /**< evaluations of the contact terms since setup (energy, force
                                    or Newton matrix: each Newton iterate and line-search trial);
                                    0 without obstacles */
  long long active_points;     /**< point-obstacle pairs closer than the threshold d^ now */
  double min_distance;         /**< the smallest signed distance of a surface point to an
                                    obstacle now (HUGE_VAL without obstacles) */
  double barrier_energy;       /**< sum of w kappa b(d) now (J) */
  double friction_dissipation; /**< the work of the friction forces over the last substep's slip
                                    (J, >= 0; 0 without friction) */
  long long body_pairs;        /**< sample-triangle pairs between bodies closer than d^ now
                                    (also in active_points); 0 without contact between bodies */
  long long tree_builds;       /**< search-tree builds and refits over the deformed surface for
                                    contact between bodies since setup; 0 without it */
  double body_depth;           /**< the largest depth of a surface sample inside another body
                                    now (m; a ray's parity, then the distance to that body's
                                    nearest triangle); 0 when none is, or without it */
  long long friction_updates;  /**< the friction's normal forces and tangents taken anew at a
                                    converged state since setup
                                    (fcm_contact_options.friction_updates) */
  long long self_pairs;        /**< sample-triangle pairs of one body closer than d^ now (also
                                    in body_pairs); 0 without self-contact */
  long long self_tests;        /**< own-body sample-triangle candidates tested against the
                                    reference exclusion since setup; 0 without self-contact */
  double self_depth;           /**< the largest depth of a sample inside its own body now (m,
                                    also in body_depth; the three interior samples of each
                                    triangle, moved off it by 1e-7 of the body's size, by a
                                    ray's parity against the body's triangles, then the distance
                                    to its nearest triangle not excluded); 0 without
                                    self-contact */
  double step_min_distance;    /**< the smallest signed distance over every state the last
                                    step accepted: the end of each of its substeps (load steps,
                                    halved substeps) and the current state (<= min_distance;
                                    HUGE_VAL without obstacles). The Newton iterates inside a
                                    substep are not states: the step filter keeps each of them
                                    at d > 0 by construction */
} fcm_contact_stats;

/** The contact obstacles' state at the current displacement and time. Before setup, or
 * without obstacles: the evaluation count (0) and no contact. Allocates workspace only.
 * @return FCM_OK, FCM_ERR_ARG (NULL), FCM_ERR_ALLOC. */
FCM_API fcm_status fcm_integrator_contact_stats(const fcm_integrator *integ,
                                                fcm_contact_stats *stats);

/** How often the contact filter acted since setup: the Newton steps it shortened before the
 * line search (*filtered) and the substeps whose first guess it pulled back in front of an
 * obstacle (*pullbacks); either may be NULL; zeros without obstacles.
 * @return FCM_OK, FCM_ERR_ARG (NULL integrator). */
FCM_API fcm_status fcm_integrator_contact_counters(const fcm_integrator *integ, long long *filtered,
                                                   long long *pullbacks);

/** The contact obstacles' part of the energy alone at displacement u and time t: energy,
 * force (added, num_dofs) and Newton matrix (added; the space's pattern,
 * fcm_space_matrix_create()), each may be NULL. After setup. Allocates nothing.
 * @return FCM_OK, FCM_ERR_ARG (NULL, not set up, wrong matrix; a point on or behind an
 * obstacle, named with its distance). */
FCM_API fcm_status fcm_integrator_contact_eval(fcm_integrator *integ, const double *u, double t,
                                               double *energy, double *force, fcm_csr *tangent);

/** Validate the options, build the constrained DOF list, gather the boundary constraints'
 * points and estimate their penalties, assemble the mass matrix (BACKWARD_EULER only) and the
 * loads, allocate every work array and solver, and run the symbolic analysis (direct).
 * Constrained DOFs get their prescribed velocity at the current time. On an octree mesh
 * (fcm_mesh_create_octree()) the hanging DOFs follow their masters (u = T u_free,
 * fcm_space_hanging_matrix_create()): each Newton system is solved in the constrained space,
 * T^T H T with the gradient T^T g; a constraint may hold a hanging node only together with its
 * masters (the node then follows them).
 * @return FCM_OK, FCM_ERR_ARG (option out of range: named; DOF constrained twice; zero
 * representative force: set the density or use the relative rule; a boundary constraint on a
 * space without surface rules, or selecting no point), FCM_ERR_NUMERIC (a Nitsche penalty that
 * cannot be estimated: a cell stiffness singular beyond rigid modes, the cell named),
 * FCM_ERR_UNSUPPORTED (hanging nodes with the multigrid solver or preconditioner, block
 * Jacobi, Schwarz or a distributed backend; a constraint holding a hanging node but not its
 * masters), errors of the assembly and of the solvers, FCM_ERR_ALLOC.
 * Allocates; a second call is FCM_ERR_ARG. */
FCM_API fcm_status fcm_integrator_setup(fcm_integrator *integ);

/** Build the linear solver's structure for the current matrix pattern and active
 * constraints, before the step that needs it: with FCM_LINEAR_MULTIGRID (serial, no hanging
 * nodes) the hierarchy without matrix values (cells, copies, prolongations, Galerkin plans and
 * coarse patterns, smoother orders, block smoothers' blocks, the coarsest symbolic analysis),
 * so that the next step only sets up its values, as a step with an unchanged active set does;
 * the direct solver's analysis is made by fcm_integrator_setup() already. Nothing for the
 * other solvers, nor when the structure is there. fcm_integrator_create_cut() calls it (a
 * cut's solver phase, timed in fcm_integrator_setup_info.solver_seconds). When the step's
 * active set or eliminated rows differ from the prepared ones, the step builds the hierarchy
 * again (from this one); results do not depend on whether this was called.
 * @return FCM_OK, FCM_ERR_ARG (NULL, not set up), errors of the hierarchy's creation
 * (FCM_ERR_UNSUPPORTED: not a Hex8 or Hex20 box grid), FCM_ERR_ALLOC. Allocates. */
FCM_API fcm_status fcm_integrator_prepare_solver(fcm_integrator *integ);

/** Advance by one step of options.dt (static: solve the equilibrium at t + dt, ramping the
 * loads from those of the last accepted step — zero before the first — in load_steps
 * increments). A failed (sub)step is retried from its start with half the increment, at
 * most max_halvings times. On failure the state (u, v, t, step count) stays at the last
 * accepted step. Allocation through the context happens in the setup and on first use only:
 * the assembly workspace, work vectors and the direct solver's symbolic analysis come from
 * the setup; the tabulated standard rule of an integrand the setup did not assemble, the
 * Jacobi/Schwarz preconditioner and the UMFPACK fallback are made the first time they are
 * needed; the multigrid hierarchy then (unless fcm_integrator_prepare_solver() built it for
 * the same active set) and again whenever the active constrained DOFs change. Later steps
 * allocate nothing through the context (test sim_step_alloc_*); CHOLMOD's and UMFPACK's
 * numeric factorizations allocate internally (SuiteSparse's malloc).
 * STATIC: before the first solve, and again whenever the active set of constraints changes
 * (a release), the active constraints must hold the six rigid-body modes of every body of the
 * space (fcm_space_num_bodies(): cuts separate bodies); a body is held by its constrained
 * DOFs and its points of active boundary constraints, in their components, when the rigid
 * motions that vanish there are only the zero motion (the rank of the modes restricted to
 * them is 6; e.g. three non-collinear nodes in all components). Else the step is refused
 * with FCM_ERR_SINGULAR before anything is solved or factored, the message naming the first
 * free body (index, box of its nodes), what holds it and the free modes. This allocates
 * O(elements + DOFs) scratch through the context. Dynamic steps are not checked (the mass
 * holds every mode).
 * @param[out] info may be NULL
 * @return FCM_OK; FCM_ERR_NOT_CONVERGED (info->reason says why; the message gives the time,
 * the residual and the tolerance); FCM_ERR_SINGULAR (STATIC: a free body, as above; a
 * direct solver that finds the Newton matrix singular); FCM_ERR_NUMERIC (NaN/Inf in a load,
 * or the last attempt met NaN/Inf); FCM_ERR_ARG (not set up); FCM_ERR_ALLOC and other hard
 * errors. */
FCM_API fcm_status fcm_integrator_step(fcm_integrator *integ, fcm_step_info *info);

/** Number of DOFs (the length of u and v). */
FCM_API fcm_index fcm_integrator_num_dofs(const fcm_integrator *integ);
/** Current time and number of accepted steps. */
FCM_API double fcm_integrator_time(const fcm_integrator *integ);
FCM_API long long fcm_integrator_step_count(const fcm_integrator *integ);
/** Borrowed views of the current displacement and velocity (num_dofs entries, valid until
 * the next call that changes the state). */
FCM_API const double *fcm_integrator_displacement(const fcm_integrator *integ);
FCM_API const double *fcm_integrator_velocity(const fcm_integrator *integ);
/** Number of constrained DOFs (after setup; 0 before). */
FCM_API fcm_index fcm_integrator_num_constrained(const fcm_integrator *integ);

/** Number of constraints added (fcm_integrator_add_constraint() ids are 0 .. n-1). */
FCM_API int fcm_integrator_num_constraints(const fcm_integrator *integ);

/** Reaction of constraint `id` at the last accepted step: the force the constraint exerts on
 * the body, i.e. the residual it absorbs, summed over its constrained DOFs (every copy, the
 * constrained components only): R = f_int(u) - f_ext + M (v_{n+1} - v_n)/h + D v_{n+1}
 * (the gradient of the step's energy; static: f_int - f_ext). In equilibrium the reactions
 * of all constraints add up to minus the external load (a body under gravity clamped: minus
 * its weight). Moment about the origin: sum of (X_a + u_a) x R_a over the constrained nodes
 * at their current positions. A released constraint reports zeros. Either output may be NULL.
 * @return FCM_OK, FCM_ERR_ARG (NULL, id out of range, no step accepted since the setup or
 * the last fcm_integrator_set_state()). No allocation. */
FCM_API fcm_status fcm_integrator_reaction(const fcm_integrator *integ, int id, double force[3],
                                           double moment[3]);

/** Forget the factorization kept for later iterations (fcm_integrator_options.
 * reuse_factorization): the next Newton iteration assembles and factors anew. A host that
 * saves the state to resume from it calls this when it saves, so that the run that goes on
 * and the one resumed later take the same iterations (fcm_simulation_write_checkpoint()
 * does). With a distributed backend every process must call it at the same point between
 * steps (their Newton iterations must agree, or the collective solves deadlock), not only
 * the one that writes. Accepts NULL. */
FCM_API void fcm_integrator_drop_factorization(fcm_integrator *integ);

/** Copy the state out (checkpoint): u, v (num_dofs each, either may be NULL), t, steps
 * (may be NULL). */
FCM_API void fcm_integrator_get_state(const fcm_integrator *integ, double *u, double *v, double *t,
                                      long long *steps);

/** Replace the state (resume, initial conditions): u and v copied (either may be NULL to
 * keep it), time t and step count. Invalidates cached tangents and forgets the acceleration
 * (fcm_integrator_set_acceleration()); the load work stays; for static integrators the
 * load of the last accepted step becomes f_ext(t) (zero when steps == 0).
 * @return FCM_OK, FCM_ERR_ARG (non-finite entry: named), errors of the load evaluation. */
FCM_API fcm_status fcm_integrator_set_state(fcm_integrator *integ, const double *u, const double *v,
                                            double t, long long steps);

/** The acceleration of the state (num_dofs values into `a`, may be NULL): that of the last
 * accepted step of Newmark, HHT or generalized-alpha, or the initial one their first step
 * computed. @return 1 when it is known, 0 when not (backward Euler keeps none; before the first
 * step and after fcm_integrator_set_state() without fcm_integrator_set_acceleration(); `a` is
 * then zeroed). */
FCM_API int fcm_integrator_get_acceleration(const fcm_integrator *integ, double *a);

/** Replace the acceleration of the state (resume): `a` (num_dofs values, copied), or NULL to
 * have the next step of a scheme that needs it solve M a = f_ext - f_int(u) - D v at the
 * current time (with the linear solver of the Newton systems, the active constrained DOFs at
 * zero acceleration). Call after fcm_integrator_set_state(), which forgets it.
 * @return FCM_OK, FCM_ERR_ARG (NULL integrator, non-finite entry: named). No allocation. */
FCM_API fcm_status fcm_integrator_set_acceleration(fcm_integrator *integ, const double *a);

/** Cumulative work of the external loads (fcm_step_info.load_work; 0 at creation). */
FCM_API double fcm_integrator_load_work(const fcm_integrator *integ);

/** Replace the cumulative load work (resume). @return FCM_OK, FCM_ERR_ARG (NULL, not
 * finite). */
FCM_API fcm_status fcm_integrator_set_load_work(fcm_integrator *integ, double work);

/** Set a rigid initial velocity v = v0 + omega x (X + u - c) at every node (v0, omega, c:
 * 3 each; NULL means zero); forgets the acceleration (the next step solves for it). @return FCM_OK,
 * FCM_ERR_ARG (non-finite). */
FCM_API fcm_status fcm_integrator_set_rigid_velocity(fcm_integrator *integ, const double v0[3],
                                                     const double omega[3], const double c[3]);

/** Energies of the current state: kinetic 1/2 v^T M v (0 for static), elastic Psi(u) and
 * external work f_ext(t)^T u; any output may be NULL. After setup. Assembles Psi.
 * @return FCM_OK, FCM_ERR_ARG (not set up), FCM_ERR_NUMERIC, errors of the assembly. */
FCM_API fcm_status fcm_integrator_energy(fcm_integrator *integ, double *kinetic, double *elastic,
                                         double *external_work);

/** Linear momentum p = sum over nodes of (M v)_a and angular momentum about the origin
 * L = sum (X_a + u_a) x (M v)_a (exact for the interpolated fields with the consistent
 * mass); zero for STATIC integrators. Either output may be NULL. After setup. Collective in a
 * distributed run (the partial mass matrix's parts are summed). @return FCM_OK,
 * FCM_ERR_ARG. */
FCM_API fcm_status fcm_integrator_momentum(fcm_integrator *integ, double linear[3],
                                           double angular[3]);

/** The mass matrix (borrowed): after the setup of a BACKWARD_EULER integrator; NULL before
 * and for STATIC integrators, which never assemble it. In a distributed run
 * (fcm_petsc_simulation_create()) this process's partial mass matrix over its local rows
 * only: (3 x the DOF copies of its own and ghost cells) rows by num_dofs columns, its own
 * cells' part, whose rows are no DOF numbers (the row-to-DOF map is internal); use
 * fcm_integrator_momentum() / fcm_integrator_energy() / fcm_simulation_center_of_mass() for
 * its products there. */
FCM_API const fcm_csr *fcm_integrator_mass(const fcm_integrator *integ);

/** The multigrid hierarchy of FCM_PRECOND_MULTIGRID or FCM_LINEAR_MULTIGRID (borrowed; for
 * fcm_mg_num_levels() and fcm_mg_get_level_info()): NULL before the first preconditioner
 * setup or solve and without multigrid; after fcm_integrator_prepare_solver() the structure
 * whose values the next step sets up (no cycle before that). Valid until the next
 * fcm_integrator_step() (which may build it again) or the integrator's destruction. */
FCM_API const fcm_mg *fcm_integrator_multigrid(const fcm_integrator *integ);

/** What fcm_integrator_setup() assembled (all 0 before the setup). */
typedef struct fcm_integrator_setup_info {
  int mass_assemblies;         /**< 1 for BACKWARD_EULER; 0 for STATIC (no inertia, no M) */
  int body_force_assemblies;   /**< one per gravity or body-force load */
  int traction_assemblies;     /**< one per surface traction load */
  int scale_assemblies;        /**< 1 when a STATIC run with the REPRESENTATIVE rule had to assemble
                                    the body force of rho a_rep for its force scale (no gravity load
                                    equal to a_rep to reuse); else 0 */
  fcm_index boundary_points;   /**< embedded-boundary points the boundary constraints hold */
  double boundary_penalty_max; /**< largest gamma h_K / E over the elements (dimensionless;
                                    0 without boundary constraints) */
  fcm_index cut_kept_elements; /**< after a cut with FCM_CUT_REUSE_BLOCKS: the elements whose
                                    mass and load blocks were kept (not integrated again);
                                    else 0 */
  fcm_index refine_extrapolated; /**< after fcm_integrator_create_refined(): the new DOF nodes
                                      in no active cell of the old space, whose state was
                                      extrapolated from the nearest old cell; else 0 */
  double solver_seconds; /**< wall seconds building the linear solver's structure, which needs
                              no matrix value: the symbolic analysis of the direct solver (in
                              the setup) and the multigrid hierarchy prepared by
                              fcm_integrator_prepare_solver() (fcm_integrator_create_cut()
                              calls it) */
} fcm_integrator_setup_info;

/** Copy the setup counts out (zeros for NULL). */
FCM_API void fcm_integrator_get_setup_info(const fcm_integrator *integ,
                                           fcm_integrator_setup_info *info);

#ifdef __cplusplus
}
#endif
#endif /* FCM_SIM_H */
