/* sim module internals: the integrator object shared by integrator.c (configuration,
 * state, setup), newton.c (steps) and linsolve.c (direct and Krylov solves). */
#ifndef FCM_SIM_IMPL_H
#define FCM_SIM_IMPL_H

#include "core/core_impl.h"
#include "geom/geom_impl.h"
#include "fcm/sim.h"
#include "sim/sim_backend.h"

typedef enum sim_load_kind { SIM_LOAD_GRAVITY = 0, SIM_LOAD_BODY, SIM_LOAD_TRACTION } sim_load_kind;

typedef struct sim_load {
  sim_load_kind kind;
  double accel[3];    /* gravity */
  fcm_field_fn field; /* body force or traction */
  void *field_user;
  fcm_time_fn scale; /* NULL: 1 */
  void *scale_user;
  double *f;   /* assembled load of scale 1 (n), after setup */
  double *blk; /* its element blocks (FCM_CUT_REUSE_BLOCKS, cut_update.c), or NULL */
} sim_load;

typedef struct sim_constraint {
  fcm_motion motion; /* axis normalized */
  fcm_index num_nodes;
  fcm_index *nodes;
} sim_constraint;

/* A boundary constraint (nitsche.c): motion on selected embedded-boundary points. */
typedef struct sim_bcon {
  fcm_boundary_select_fn select; /* NULL: every point */
  void *select_user;
  fcm_motion motion; /* axis normalized */
  fcm_boundary_options opts;
} sim_bcon;

/* The embedded-boundary points of the boundary constraints (setup), grouped by element in
 * ascending element order: element elem[k] has points ptr[k] .. ptr[k+1]. */
typedef struct sim_bpoints {
  fcm_index nelem;       /* elements with points */
  fcm_index *elem, *ptr; /* nelem, nelem + 1 */
  fcm_index *lelem;      /* nelem: local position of elem[k] in the space (fem_impl.h; a full
                            space: elem[k]) */
  fcm_index np;          /* points */
  int *con;              /* np: boundary constraint of the point */
  double *w;             /* np: area weights */
  double *X, *nrm;       /* np x 3: reference position and unit outward normal */
  double *N, *G;         /* np x nn shape values, np x nn x 3 physical gradients */
  double *gamma;         /* num_elems: Nitsche penalty per element (0: no Nitsche points) */
  double *hk;            /* num_elems: cell size h_K (cube root of the volume) */
  double *scratch;       /* per thread: ue, fe (3nn each), Ke ((3nn)^2), Q (9nn) */
  int nthreads;          /* threads the scratch serves (the context's count at setup) */
  int num_colors;        /* the space's colours: no two elements of one share a DOF copy */
  fcm_index *color_ptr;  /* num_colors + 1 offsets into color_k */
  fcm_index *color_k;    /* nelem: indices k (into elem) grouped by colour, ascending within */
  double *eelem;         /* nelem: energy of each element's points (summed in order) */
} sim_bpoints;

/* Contact obstacle kinds (contact.c, contact_obstacle.c). */
typedef enum sim_contact_kind {
  SIM_CONTACT_PLANE = 0, /* the half-space n . (x - p0 - v t) <= 0 (n unit) */
  SIM_CONTACT_SPHERE,    /* the ball |X - c| <= r in the obstacle's frame */
  SIM_CONTACT_BOX,       /* the box lo <= X <= hi in the obstacle's frame */
  SIM_CONTACT_SURFACE,   /* the volume a closed triangle surface encloses, in its frame */
  SIM_CONTACT_BODIES     /* the other bodies and cut pieces of the space (contact_bodies.c) */
} sim_contact_kind;

struct sim_bodies;

/* A contact obstacle. Spheres, boxes and surfaces are given in their own frame, placed at
 * time t by the rigid motion x = o(t) + R(t) X that `motion` prescribes (fcm_motion_eval()). */
typedef struct sim_contact {
  sim_contact_kind kind;
  double point[3], normal[3], velocity[3]; /* plane */
  double center[3], radius;                /* sphere */
  double lo[3], hi[3];                     /* box; surface: its vertices' bounding box */
  fcm_motion motion;                       /* sphere, box, surface */
  int moving;                              /* the motion is not the identity at every t */
  fcm_index nv, nt;                        /* surface: vertices, triangles */
  double *xyz;                             /* surface: nv x 3 */
  fcm_index *tri;                          /* surface: nt x 3 */
  fcm_aabb_tree *tree;                     /* surface: over the triangles */
  fcm_contact_options opts;                /* as given (0: default) */
  double dhat, kappa;                      /* the barrier's threshold and stiffness (setup) */
  const fcm_geometry *geom;                /* bodies: the geometry the space was built on */
  struct sim_bodies *bodies;               /* bodies: the surface and its pairs (setup) */
} sim_contact;

/* An obstacle's placement at one time: world x = o + R X (R row-major). */
typedef struct sim_pose {
  double R[9], o[3];
} sim_pose;

/* The embedded surface's points the contact barrier acts on (setup), grouped by element. */
typedef struct sim_cpoints {
  fcm_index nelem;       /* elements with points */
  fcm_index *elem, *ptr; /* nelem, nelem + 1 */
  fcm_index *lelem;      /* nelem: local position of elem[k] in the space */
  fcm_index np;          /* points */
  double *w, *X, *N;     /* np weights, np x 3 reference positions, np x nn shape values */
  double h;              /* the largest extent of a cell holding points */
  double *scratch;       /* fe (3nn), Ke ((3nn)^2) */
  fcm__idbuf buf;        /* triangle ids of surface-obstacle queries */
  sim_pose *pose;        /* num_contacts: the obstacles' placements at the time evaluated */
  int swallowed;         /* a moving surface obstacle swallowed a point of the substep's start */
  double *lag;           /* np x num_contacts x 7 (friction only): lambda, T (3 x 2) */
  sim_pose *pose0;       /* num_contacts (friction only): the placements at the substep's start */
  double t0, hstep;      /* the substep's start and length (friction) */
  long long relags;      /* friction's normal forces and tangents taken anew (cumulative) */
} sim_cpoints;

/* The time scheme's constants (scheme.c): the generalized-alpha family (backward Euler: kind
 * only). cmass = (1 - am)/((1 - af) beta): the mass term's coefficient times h^2. */
typedef struct sim_scheme {
  fcm_time_scheme kind;
  double am, af, beta, gamma, cmass;
} sim_scheme;

/* Counters and timers of one step (copied into fcm_step_info). */
typedef struct sim_stats {
  int newton_iterations, backtracks, tangent_assemblies, factorizations;
  int direct_fallbacks, projection_fallbacks, inexact_solves, reused_factorizations;
  long long linear_iterations, mg_cycles;
  double time_assembly, time_factor, time_solve;
} sim_stats;

struct fcm_integrator {
  fcm_ctx *ctx;
  const fcm_space *space;
  fcm_assembly_workspace *aws; /* assembly rules and scratch (setup) */
  fcm_material mat;
  fcm_material_params params;     /* project_psd as the options say */
  fcm_material_params params_psd; /* project_psd = 1 (fallback, damping) */
  fcm_integrator_options opts;
  fcm_index n;
  int is_setup;
  int linear; /* constant tangent (linear material) */

  /* configuration */
  sim_load *loads;
  int num_loads;
  sim_constraint *cons;
  int num_cons;
  sim_bcon *bcons; /* boundary constraints (nitsche.c) */
  int num_bcons;
  sim_bpoints bp;
  unsigned char *bcon_on; /* num_bcons: active at bc_time */
  int bcon_active;        /* how many are */
  double bc_time;         /* time their motions are evaluated at */
  int bc_psd_only;        /* 1: their tangent is the PSD penalty part (Newton's retry) */
  sim_contact *contacts;  /* contact obstacles (contact.c) */
  int num_contacts;
  sim_cpoints cp;
  long long contact_filtered;  /* Newton steps the contact filter shortened (cumulative) */
  long long contact_evals;     /* evaluations of the contact terms (cumulative) */
  long long contact_pullbacks; /* substep guesses pulled back in front of an obstacle */
  double contact_dmin_inner;   /* smallest distance at the current step's accepted substeps
                                  before its last (valid when contact_inner_states > 0) */
  int contact_inner_states;
  int newton_resume; /* the Newton solve goes on from u: no predictor, friction lag, pull-back */

  /* state */
  double *u, *v;
  double *a;        /* acceleration (n; scheme.c), valid when a_valid */
  int a_valid;      /* 0: the next step of a scheme other than backward Euler solves for it */
  double load_work; /* cumulative work of the external loads (fcm_step_info.load_work) */
  double t;
  long long steps;
  double *load_prev; /* static: external load of the last accepted step */

  /* constrained DOFs (setup): per entry its DOF, node, component and constraint */
  fcm_index ncon;
  fcm_index *con_dof, *con_node;
  int *con_comp, *con_id;
  unsigned char *is_con; /* n: constrained by an active constraint right now */
  unsigned char *con_on; /* num_cons: constraint active right now */
  long long con_version; /* bumps whenever the active set changes */
  long long rigid_ok;    /* static: con_version + 1 of the active set whose rigid-mode check
                            (rigid.c) passed; 0: none yet */
  double *reaction;      /* num_cons x 6: force and moment of each constraint at the last
                            accepted step (fcm_integrator_reaction()) */
  int reaction_valid;    /* 1 after an accepted step; 0 after setup and set_state */
  fcm_index nact;        /* active constrained DOFs */
  fcm_index *act_dof;    /* nact DOFs (distinct) */
  double *act_val;       /* their prescribed displacements at the substep's end */
  double *act_inc;       /* increments to reach them */
  double *act_diag;      /* the eliminated matrix's diagonal there (the summed
                            tangent's, or 1 where that is not positive: fcm__eliminate_marked's
                            rule), from the last elimination */

  /* hanging-node constraints of an octree space (hanging.c; NULL / 0 without hanging nodes):
   * P (n x n) with u = P u for the continuous fields, the hanging DOFs (rows of P that are not
   * the identity), and Ha, the space-pattern matrix the tangent is assembled into and reduced
   * from into H = P^T Ha P + I_h (H then has the pattern of fcm_csr_create_ptap()); hptap: the
   * Galerkin product's plan (la/ptap.c), made at the first product; hmirror[e]: the position
   * of entry e's transpose in H (above the diagonal, -1 elsewhere) */
  fcm_csr *hP, *Ha;
  struct fcm__ptap *hptap;
  fcm_index *hmirror;
  fcm_index nhang;
  fcm_index *hang;

  /* matrices (space pattern) */
  fcm_csr *M, *H, *D, *H0; /* mass, Newton matrix, damping (or NULL), pristine copy (linear);
                              with a backend M, D, H and H0 are this process's partial ones */
  fcm_csr *Hpc, *K0; /* preconditioner matrix, linear stiffness at rest (created on first use) */
  int h_psd;         /* H holds a PSD tangent (set with H by newton.c) */
  /* CHOLMOD found H, the exact tangent of a dynamic step, not positive definite (linsolve.c):
   * newton.c takes the PSD-projected tangent, SPD with M/h^2, instead of an LU factorization */
  int h_indefinite;
  /* FCM_MATERIAL_COROTATED_LINEAR with the direct solver: 1 once a Newton iteration of this
   * substep on a fresh factorization of the warped tangent reduced the residual by less than
   * half; the tangent is the exact Hessian from then on (newton.c) */
  int corot_exact;
  double *Ma;           /* M a_rep (n) */
  double rep_norm_full; /* ||M a_rep|| over all DOFs */

  /* work vectors (n each) */
  double *u_bak, *v_bak, *lp_bak; /* state at the start of the step */
  double *un;                     /* displacement at the start of the substep */
  double *uhat, *fext, *fend, *fint, *g, *d, *b, *ut, *fint_t, *g_t, *w1, *w2;
  double *fprev; /* external load at the substep's start (the load work) */
  /* schemes other than backward Euler (scheme.c; NULL for it): the acceleration at the step's
   * start, the damping term's centre u_d and the step's constant force f_a (sim.h) */
  double *a_bak, *ud, *fstep;
  sim_scheme sch;

  /* solvers */
  fcm_direct *chol, *umf, *direct; /* `direct`: the one holding the current factor */
  /* n: the fill-reducing ordering CHOLMOD's analysis takes instead of its own (after a cut:
   * the old system's extended by the new DOFs, cut_update.c); NULL: CHOLMOD's own */
  fcm_index *cut_ordering;
  /* FCM_CUT_REUSE_BLOCKS (cut_update.c): the mass matrix's element blocks (or NULL); during
   * the setup after a cut, the integrator cut from (borrowed) and the element of its space
   * each element integrates as (cut_same, num_elems; -1: integrate) */
  double *blk_mass;
  const fcm_integrator *cut_old;
  fcm_index *cut_same;
  /* FCM_CUT_REUSE_STORAGE: during the setup after a cut, the integrator cut from, whose large
   * arrays the new matrices take (cut_update.c); spent: this integrator gave them to a
   * successful cut (it can only be destroyed) */
  fcm_integrator *cut_give;
  int spent;
  fcm_krylov *krylov;
  fcm_jacobi *jacobi;
  fcm_schwarz *schwarz;
  unsigned char *schwarz_flag; /* num_cells */
  /* multigrid (linsolve.c): built on mg_A (H or Hpc) for the active set key mg_con; mg_r is
   * the residual of FCM_LINEAR_MULTIGRID's cycles (n, setup); mg_applies counts the cycles
   * the Krylov solvers ran as preconditioner applications */
  fcm_mg *mg;
  const fcm_csr *mg_A;
  long long mg_con;
  long long mg_applies;
  long long mg_creations; /* hierarchies created: prepared (pattern) and at set-ups */
  double *mg_r;
  /* multigrid_fixed_cycles: the warm start of the first Newton iteration of a (sub)step.
   * mg_acc sums the updates of the current Newton solve (n); mg_guess is the sum of the last
   * accepted one (n), valid when mg_warm for (sub)steps of length mg_warm_h; mg_iteration is
   * the Newton iteration being solved (0: the first) */
  double *mg_guess, *mg_acc;
  int mg_warm, mg_iteration;
  double mg_warm_h;
  /* the last linear solve stagnated or broke down (linsolve.c; newton.c names it as the
   * failure's reason when Newton cannot go on), and the solver's message */
  int solve_stalled;
  char stall_msg[320];

  /* Newton matrix cache: H holds base(h) + K(u) (state TANGENT, unmodified) or the
   * eliminated system with a valid factor / preconditioner (state SYSTEM, key below). */
  int h_state;
  double key_h;
  long long key_con, key_damp;
  long long damp_version;
  /* A kept factorization (reuse_factorization): the solver's factor of the Newton matrix at
   * an earlier iterate, for the h, constraints and damping of the keys above; kept_ok = 0 once
   * an iteration solved with it fell short of reuse_contraction. */
  int kept, kept_ok;

  fcm_integrator_setup_info setup_info; /* what the setup assembled */

  /* cumulative counters */
  long long total_factorizations, total_fallbacks;

  /* energy parts of the current iterate, and its inverted quadrature points (summed over the
   * processes; fcm__assembly_inverted()) */
  double psi;
  double inverted;

  /* the solver backend (fem/fem_backend.h): the serial one (integrator_backend.c) unless a
   * distributed one is attached */
  fcm__backend backend;
  unsigned char *owned;            /* n: the backend's owned DOFs (a copy of backend.owned) */
  const struct sim_solver *solver; /* the linear solver of the Newton systems (linsolve.c) */

  /* During the setup after a cut (cut_update.c, fcm__sim_cut_prepare_blocks()): per copy, the
   * copy of cut_old's space whose rows of the mass matrix and entries of the loads this
   * integrator's take (-1: summed again; cut_dirty flags those); NULL: every row summed.
   * cut_kept_copies: the copies taken at the last cut. */
  fcm_index *cut_rows;
  unsigned char *cut_dirty;
  fcm_index cut_kept_copies;
  /* during that setup, where blocks are taken in place (cut_update.c): each kept element
   * itself, -1 for the others */
  fcm_index *cut_self;
};

enum { SIM_H_INVALID = 0, SIM_H_TANGENT = 1, SIM_H_SYSTEM = 2 };

/* Static steps: FCM_OK when the active constraints (node and boundary constraints at the
 * current active set) hold the rigid-body modes of every body of the space, else
 * FCM_ERR_SINGULAR naming the first free body (its nodes' bounding box), what holds it and
 * the free modes; t is the step's end time, for the message. Allocates O(elements + DOFs)
 * scratch; collective with a backend (the boundary points' part is summed). (rigid.c) */
fcm_status fcm__sim_check_rigid_modes(fcm_integrator *I, double t);

/* Newton solve of one (sub)step of length h (0: static) from the state u = un, v.
 * Outputs the reason, the final residual, the stopping rule's threshold and its reference;
 * hard errors are returned as status. (newton.c) */
fcm_status fcm__sim_newton(fcm_integrator *I, double h, double t1, fcm_step_reason *reason,
                           double *residual, double *tolerance, double *reference,
                           sim_stats *stats);

/* The linear solver of the Newton systems (I->solver): a distributed backend's when it has
 * a factor of its own, else the serial one linear_solver names; set it up. (linsolve.c) */
typedef struct sim_solver sim_solver;
fcm_status fcm__sim_solver_setup(fcm_integrator *I);

/* Factor (direct) or set up the preconditioner (Krylov) for the eliminated matrix H.
 * Soft failures set *reason and return FCM_OK. (linsolve.c) */
fcm_status fcm__sim_factor(fcm_integrator *I, fcm_step_reason *reason, sim_stats *stats);

/* Solve H d = b with the current factor or preconditioner. Soft failures set *reason
 * (d is then unusable) and return FCM_OK. (linsolve.c) */
fcm_status fcm__sim_solve(fcm_integrator *I, const double *b, double *d, fcm_step_reason *reason,
                          int *iterations, sim_stats *stats);

/* Check the multigrid options when FCM_PRECOND_MULTIGRID (with CG or MINRES) or
 * FCM_LINEAR_MULTIGRID is chosen: FCM_ERR_ARG naming the member and its range. (linsolve.c) */
fcm_status fcm__sim_multigrid_validate(fcm_ctx *ctx, const fcm_integrator_options *o);

/* Symbolic analyses performed so far (CHOLMOD + UMFPACK). (linsolve.c) */
long long fcm__sim_analyses(const fcm_integrator *I);
/* Multigrid hierarchies the integrator created (prepared ones too). (linsolve.c) */
long long fcm__sim_mg_creations(const fcm_integrator *I);

/* Whether fcm__sim_prepare_solver_cut() makes a structure (the multigrid solver's hierarchy
 * on a serial space without hanging nodes). */
int fcm__sim_structure_wanted(const fcm_integrator *I);

/* fcm_integrator_prepare_solver() of the integrator a cut made from `old` (on the space before
 * the cut): the multigrid hierarchy's structure takes what the cut left from old's hierarchy
 * (fcm__mg_create_pattern_cut(); the same bits), which is only read. Needs only the setup's
 * first stage (fcm__sim_setup_begin()) and reads nothing its value stage writes, so the two
 * may run side by side: the active set is that of old's time (the state the cut transfers),
 * computed here into *con (n entries, the caller's to free; NULL: no structure to prepare),
 * and I->mg_con is left -1 for the caller to set once I's active set is known to be *con.
 * With `beside` (inside a parallel region) level 0's smoothers may be left to a task of the
 * team: fcm__sim_join_solver() after the region's barrier completes them.
 * Adds nothing to I->setup_info.solver_seconds. (linsolve.c) */
fcm_status fcm__sim_prepare_solver_cut(fcm_integrator *I, const fcm_integrator *old, int beside,
                                       unsigned char **con);

/* After fcm__sim_prepare_solver_cut() with `beside`, once the team's barrier is passed: the
 * hierarchy's creation completed (fcm__mg_join()); its error, with the solver's prefix.
 * *seconds: the wall time of the task that ran beside (0: none). (linsolve.c) */
fcm_status fcm__sim_join_solver(fcm_integrator *I, double *seconds);

/* External load at time t: sum_k scale_k(t) f_k into f (n). (integrator.c) */
void fcm__sim_eval_loads(const fcm_integrator *I, double t, double *f);

/* A = M/h^2 + D/h (dynamics, h > 0) or 0 (static): the part of the Newton matrix (and of the
 * preconditioner's matrix) the material tangent is added to; A has the pattern of M.
 * (newton.c) */
/* After a cut (cut_update.c): give I (not set up, direct CHOLMOD, serial) the ordering of old's
 * CHOLMOD analysis extended to I's space (fcm__space_cut_ordering()), so that its analysis
 * skips AMD / METIS. Nothing when old has no CHOLMOD analysis or I another solver or a
 * distributed backend. @return FCM_OK, FCM_ERR_ARG (not a cut pair), FCM_ERR_ALLOC. */
fcm_status fcm__sim_cut_ordering(const fcm_integrator *old, fcm_integrator *I);
/* old's loads, boundary constraints and contacts added to I (not its node constraints: a cut
 * keeps the node numbering, a refinement maps the nodes) */
fcm_status fcm__sim_copy_effects(const fcm_integrator *old, fcm_integrator *I);

/* fcm_assembly_workspace_linear() on I's space of the mass (blocks = &I->blk_mass, old_blocks
 * the cut integrator's) or a load (its blk, the old load's): with FCM_CUT_REUSE_BLOCKS on a
 * full serial embedded space, keeping the element blocks in *blocks (an array of
 * fcm__calloc_large()) and, during the setup after a cut, taking those of the elements the cut
 * left from old_blocks (counted in setup_info.cut_kept_elements). give: where the old
 * integrator gives its storage (I->cut_give), its field holding old_blocks, whose array then
 * becomes *blocks with the kept blocks moved in place where it can (the field left NULL: the
 * old integrator's next cut, after a failed one, integrates every element); else NULL.
 * @return as the assembly. (cut_update.c) */
fcm_status fcm__sim_assemble_kept(fcm_integrator *I, const fcm_linear_form *form, fcm_csr *A,
                                  double *f, double **blocks, const double *old_blocks,
                                  double **give);

/* During the setup after a cut with I->cut_rows: the mass matrix on I's space, its rows of the
 * kept copies (I->cut_rows) old's rows, moved within old's values where I takes them
 * (I->cut_give), else copied from old's; the other rows zero, to be summed by
 * fcm__sim_assemble_kept() (which sums only those while I->cut_rows is set). (cut_update.c) */
fcm_status fcm__sim_cut_mass_matrix(fcm_integrator *I, fcm_csr **M);

/* The same for M a_rep (I->Ma, from I->M and I->w1 = a_rep at every node): the kept copies'
 * entries old's (their rows of M are old's, in the same order), the others M's products; 0
 * (nothing done) without cut rows. (cut_update.c) */
int fcm__sim_cut_rep_force(fcm_integrator *I);

/* The same for load k's vector f (zero on entry): the kept copies' entries old's. */
void fcm__sim_cut_load(const fcm_integrator *I, int k, double *f);

/* After a cut with FCM_CUT_REUSE_STORAGE in old's options (before I's setup): I's setup
 * takes old's large arrays where they are large enough (I->cut_give); else nothing. */
void fcm__sim_cut_give_storage(const fcm_integrator *old, fcm_integrator *I);

/* After a failed cut (I, not set up or not returned): the storage I took back to old, which
 * goes on as before the cut: its mass matrix assembled again (the same bits), its Newton
 * matrix and corotated element matrices built again at its next step (the direct solver's
 * kept factorization, held apart from them, still used). A failure of that assembly leaves
 * old spent (FCM_ERR_ARG on a step). */
void fcm__sim_cut_give_back(fcm_integrator *I, fcm_integrator *old);

/* After a cut with FCM_CUT_REUSE_BLOCKS (before I's setup): the elements of I's space that
 * integrate as elements of old's (I->cut_same), so that the setup keeps their blocks.
 * @return FCM_OK, FCM_ERR_ARG (not a cut pair), FCM_ERR_ALLOC. (cut_update.c) */
fcm_status fcm__sim_cut_prepare_blocks(const fcm_integrator *old, fcm_integrator *I);

/* The ordering CHOLMOD's analysis of I takes (n entries copied; before fcm_integrator_setup()),
 * in place of any from a cut. @return FCM_OK, FCM_ERR_ARG (NULL, set up already),
 * FCM_ERR_ALLOC. (cut_update.c) */
fcm_status fcm__integrator_set_ordering(fcm_integrator *I, const fcm_index *perm);

/* The ordering of I's CHOLMOD analysis (n entries). @return FCM_OK, FCM_ERR_ARG (NULL, no
 * CHOLMOD analysis: another solver, or not set up). (cut_update.c) */
fcm_status fcm__integrator_get_ordering(const fcm_integrator *I, fcm_index *perm);

void fcm__sim_set_base(const fcm_integrator *I, double h, fcm_csr *A);

/* Store the reaction of every constraint from the gradient I->g of the accepted iterate
 * (called when a step is accepted). (integrator.c) */
void fcm__sim_store_reactions(fcm_integrator *I);

/* Active constraint set and prescribed values at time t (act_dof, act_val; con_version
 * bumps when the set changes). (integrator.c) */
void fcm__sim_eval_constraints(fcm_integrator *I, double t);

/* Boundary constraints (nitsche.c): points and penalties at setup; free; the energy, force
 * and tangent at x and time I->bc_time added to *energy, force and T (each may be NULL).
 * projected: the tangent keeps only the penalty part (PSD; the PSD fallback, project_psd
 * and the preconditioner). *finite = 0 when the material gives NaN/Inf. */
fcm_status fcm__sim_boundary_setup(fcm_integrator *I);
void fcm__sim_boundary_free(fcm_integrator *I);
/* Evaluate the boundary motions at time t from now on (bc_time, active flags); 1 when the
 * active set changed. */
int fcm__sim_boundary_time(fcm_integrator *I, double t);
fcm_status fcm__sim_boundary_assemble(fcm_integrator *I, const double *x, int projected,
                                      double *energy, double *force, fcm_csr *T, int *finite);

/* Add the symmetric part (Ke + Ke^T) / 2 of the element matrix Ke (3nn x 3nn) of the element
 * at local position le into the values of the pattern (a matrix over the space's rows,
 * fcm__space_matrix_create_rows()). The boundary and contact terms are symmetric, but their
 * entries (i, j) and (j, i) are computed in different orders and differ in the last bits; the
 * matrix's values must be exactly symmetric, since solvers read one triangle or both.
 * (nitsche_assemble.c) */
void fcm__sim_scatter(const fcm_space *s, fcm_index le, const double *Ke, double *vals);
/* FCM_ERR_ARG (named after `who`) unless T (may be NULL) has the space's matrix pattern.
 * (nitsche.c) */
fcm_status fcm__sim_check_pattern(const fcm_integrator *I, const fcm_csr *T, const char *who);

/* Contact obstacles (contact.c). setup: the embedded surface's points and the defaults of
 * the barrier parameters, refusing a start in penetration; free. assemble: the barrier's
 * energy, force and tangent at x and time I->bc_time added to *energy, force and T (each may
 * be NULL); *finite = 0 when a point lies on or behind an obstacle. step_bound: the largest
 * fraction in (0, 1] of the step x + alpha dx keeping every point at positive distance,
 * scaled by the safety factor (1 when nothing limits it). check: FCM_ERR_ARG naming the
 * first point on or behind an obstacle at x and time t. */
fcm_status fcm__sim_contact_setup(fcm_integrator *I);
void fcm__sim_contact_free(fcm_integrator *I);
void fcm__sim_contact_assemble(fcm_integrator *I, const double *x, double *energy, double *force,
                               fcm_csr *T, int *finite);
double fcm__sim_contact_step_bound(fcm_integrator *I, const double *x, const double *dx);
/* A substep's first guess u behind an obstacle: pulled back to un + 0.9 alpha (u - un), alpha
 * the step bound from un (w1 holds u - un afterwards). A moving surface obstacle that
 * swallowed a point of un makes the substep's energies non-finite (cp.swallowed). */
void fcm__sim_contact_pull_back(fcm_integrator *I);
fcm_status fcm__sim_contact_track(fcm_integrator *I);
fcm_status fcm__sim_contact_support(fcm_integrator *I, const double *x, double t,
                                    void (*fn)(void *user, fcm_index elem, const double y[3],
                                               const double g[3]),
                                    void *user);
fcm_status fcm__sim_contact_check(fcm_integrator *I, const double *x, double t);
/* Friction (contact_friction.c). has_friction: an obstacle has mu > 0. lag: each point's
 * normal force and tangent basis from u_n (obstacles at bc_time), the substep's start
 * bc_time - h. friction: the dissipation potential of point p at y (substep start y0), its
 * gradient and Hessian in y (written). */
int fcm__sim_contact_has_friction(const fcm_integrator *I);
fcm_status fcm__sim_contact_lag(fcm_integrator *I, double h);
/* Friction's fixed-point updates per substep (0: none, static, or frictionless) and one update
 * at the current state (*change: the largest normal force's relative change). */
int fcm__sim_contact_updates(const fcm_integrator *I);
fcm_status fcm__sim_contact_relag(fcm_integrator *I, double *change);
/* The smoothed friction potential mu lambda f0(|s|) (ml = mu lambda), s = T^T delta: its value,
 * gradient G and Hessian A (3 x 3) in delta; the work ml f1(|s|) |s| of its force over delta;
 * an orthonormal tangent basis T (3 x 2, column-major) of the plane normal to unit g. */
double fcm__sim_friction_potential(double ml, double eps, const double T[6], const double delta[3],
                                   double G[3], double A[9]);
double fcm__sim_friction_work(double ml, double eps, const double T[6], const double delta[3]);
void fcm__sim_tangent_basis(const double g[3], double T[6]);
double fcm__sim_contact_friction(const fcm_integrator *I, fcm_index p, const double y[3],
                                 const double y0[3], double grad[3], double hess[9]);
/* The work of point p's friction forces over its slip from y0 to y: sum of mu lambda f1 |s|. */
double fcm__sim_contact_friction_work(const fcm_integrator *I, fcm_index p, const double y[3],
                                      const double y0[3]);
/* Re-add old's obstacle c to I (fcm_integrator_cut()). */
fcm_status fcm__sim_contact_copy(fcm_integrator *I, const sim_contact *c);

/* Obstacle geometry (contact_obstacle.c). pose: the obstacle's placement at t. distance: d,
 * its world gradient g and Hessian H (may be NULL) at the world point y; a surface's closest
 * triangle is searched within `radius` (d = HUGE_VAL beyond). toi: the smallest s in
 * [0, smax] with y + s dy on the obstacle (0 when y is not outside; HUGE_VAL: none; planes,
 * spheres and boxes search every s >= 0). inside: y on or inside the obstacle. surface_setup:
 * the closure check (FCM_ERR_ARG naming obstacle k and the first open edge) and the tree.
 * point_triangle: the closest point q of (a, b, c) to p and its region (0 the face, 1..3 the
 * edges ab, bc, ca with the unit direction e, 4..6 the vertices a, b, c); with _distance the
 * distance, unit gradient and Hessian (may be NULL) of that region. */
void fcm__sim_contact_pose(const sim_contact *c, double t, sim_pose *P);
fcm_status fcm__sim_contact_distance(fcm_ctx *ctx, const sim_contact *c, const sim_pose *P,
                                     const double y[3], double t, double radius, fcm__idbuf *buf,
                                     double *d, double g[3], double *H);
fcm_status fcm__sim_contact_toi(fcm_ctx *ctx, const sim_contact *c, const sim_pose *P,
                                const double y[3], const double dy[3], double t, double smax,
                                fcm__idbuf *buf, double *s);
fcm_status fcm__sim_contact_inside(fcm_ctx *ctx, const sim_contact *c, const sim_pose *P,
                                   const double y[3], double t, fcm__idbuf *buf, int *inside);
fcm_status fcm__sim_contact_surface_setup(fcm_ctx *ctx, int k, sim_contact *c);
/* A search radius about y that holds the surface's closest triangle. */
double fcm__sim_contact_reach(const sim_contact *c, const sim_pose *P, const double y[3]);
/* A bounding-volume hierarchy with one subtree per group (contact_bvh.c). build: over the
 * items k < n with group[k] >= 0 and their boxes (n x 6: lo, hi); refit: the same tree over
 * moved boxes; query: append to buf (not reset) the items of group g whose box meets
 * [lo, hi]. */
typedef struct sim_bvh_node {
  double lo[3], hi[3];
  fcm_index first, count, right; /* a leaf: perm[first, first + count); else the right child */
} sim_bvh_node;
typedef struct sim_bvh {
  sim_bvh_node *node;
  fcm_index nnodes, cap;
  fcm_index *perm, *root, num_groups;
} sim_bvh;
fcm_status fcm__sim_bvh_build(fcm_ctx *ctx, sim_bvh *T, fcm_index n, const fcm_index *group,
                              fcm_index num_groups, const double *boxes);
void fcm__sim_bvh_refit(sim_bvh *T, const double *boxes);
fcm_status fcm__sim_bvh_query(fcm_ctx *ctx, const sim_bvh *T, fcm_index g, const double *boxes,
                              const double lo[3], const double hi[3], fcm__idbuf *buf);
void fcm__sim_bvh_free(fcm_ctx *ctx, sim_bvh *T);

/* Contact between bodies (contact_bodies.c, contact_bodies_solve.c): a sample's blind list
 * holds up to SIM_BLIND bodies. */
#define SIM_BLIND 8

/* A pair within d^ at the Newton matrix's assembly: sample n, triangle t, the distance's
 * gradient g, the closest point's barycentric coordinates beta, w kappa b''(d). */
typedef struct sim_pair {
  fcm_index n, t;
  double g[3], beta[3], c2;
} sim_pair;

/* A pair's lagged friction (contact_bodies_friction.c): sample n, triangle t, the closest
 * point's barycentric coordinates beta, the normal force lambda = w kappa |b'(d)| and the
 * tangent basis T (3 x 2, column-major) at the substep's start. */
typedef struct sim_fpair {
  fcm_index n, t;
  double beta[3], lambda, T[6];
} sim_fpair;

typedef struct sim_bodies {
  fcm_embedded_surface *es;
  fcm_index nv, nt, ns;
  fcm_index *velem;     /* nv: the element holding node v */
  double *vX, *vN;      /* nv x 3 reference positions, nv x nn shape values */
  const fcm_index *tri; /* nt x 3 (the surface's) */
  fcm_index *tbody;     /* nt: the triangle's body, -1 for a triangle without area */
  fcm_index *stri;      /* ns: the sample's triangle */
  double *slam, *sw;    /* ns x 3 barycentric coordinates, ns weights */
  fcm_index *blind;     /* ns x SIM_BLIND: bodies the sample ignores (-1: none) */
  fcm_index *lag_t;     /* ns x SIM_BLIND: their closest triangle at the substep's start */
  double *lag;          /* ns x SIM_BLIND x 6: its closest point's beta and its unit normal */
  int prepared;
  double *y, *dy, *boxes; /* nv x 3, nv x 3, nt x 6 */
  double *Ke;             /* (3 nn)^2 */
  fcm_index num_bodies;
  fcm_index *eptr, *enode; /* num_elems + 1 offsets, nv: the nodes of each element */
  double *vw;              /* nv: a node's weight against the obstacles */
  sim_bvh bvh;
  int built;
  fcm_index *near_ptr, *near; /* num_bodies + 1, num_bodies^2: the bodies near each body */
  sim_pair *pairs;            /* the pairs within d^ at the last Newton matrix's assembly */
  size_t npairs, cap_pairs;
  double *w1, *w2, *w3, *w4; /* n each: the direction's refinement */
  fcm__idbuf buf;
  long long builds;
  int self;             /* self-contact (fcm_contact_options.self_contact) */
  double rho;           /* 2 d^: own triangles closer in the reference state are excluded */
  long long self_tests; /* own-body candidates tested against the exclusion */
  double *y0;           /* nv x 3: the nodes at the substep's start (friction) */
  sim_fpair *fp;        /* the pairs' lagged friction */
  size_t nfp, cap_fp;
} sim_bodies;

/* Contact between bodies and cut pieces (contact_bodies.c), the obstacle kind
 * SIM_CONTACT_BODIES: setup builds the embedded surface of the space (c->bodies); free releases
 * it. prepare: at a substep's start (state un), the sample points that started within d^ of
 * another piece become blind to it until they are d^ away (cut faces start in contact).
 * assemble / step_bound as the obstacles' (the tangent a block-diagonal bound of the pairs'
 * Hessians, the step bound conservative). stats: pairs within d^, the smallest distance, the
 * barrier energy at x. */
fcm_status fcm__sim_bodies_setup(fcm_integrator *I, sim_contact *c);
void fcm__sim_bodies_free(fcm_ctx *ctx, sim_contact *c);
fcm_status fcm__sim_bodies_prepare(fcm_integrator *I, sim_contact *c, const double *x);
void fcm__sim_bodies_assemble(fcm_integrator *I, sim_contact *c, const double *x, double *energy,
                              double *force, fcm_csr *T, int *finite);
double fcm__sim_bodies_step_bound(fcm_integrator *I, sim_contact *c, const double *x,
                                  const double *dx);
fcm_status fcm__sim_bodies_stats(const fcm_integrator *I, const sim_contact *c, const double *x,
                                 long long *pairs, double *min_distance, double *energy);
/* The largest depth of a sample inside another body at x (a ray's parity, then the distance
 * to that body's nearest triangle; 0: none) and where (may be NULL). */
fcm_status fcm__sim_bodies_depth(const fcm_integrator *I, const sim_contact *c, const double *x,
                                 double *depth, double where[3]);
/* The surface nodes of the contact between bodies that lie in element e (0 without it): their
 * count and, where the arrays are given, their obstacle weights (the area of the cut-face
 * triangles about them; 1e-3 of their area elsewhere, where the surface rules act already),
 * reference positions and shape values. */
fcm_index fcm__sim_bodies_element_nodes(const fcm_integrator *I, fcm_index e, double *w, double *X,
                                        double *N);
/* Newton's direction d (H d = b solved by the factorization of the Newton matrix H, which
 * holds a block-diagonal bound of the pairs' coupling) refined by preconditioned conjugate
 * gradients on the coupled matrix (H + C - C_bd, the recorded pairs), preconditioned by H's
 * solve; nothing without pairs or on an octree mesh. */
fcm_status fcm__sim_bodies_refine(fcm_integrator *I, const double *b, double *d,
                                  fcm_step_reason *reason, int *its, sim_stats *stats);
/* Helpers shared with contact_bodies_depth.c: the nodes' positions X + u at x (motion: the
 * motion u only); the triangles' boxes (swept over y + s dy, s in [0, 2], when dy is given)
 * and the tree built again or refitted to them; sample n's position at node positions y; the
 * distance of p to triangle t at node positions y, its unit gradient and the closest point's
 * barycentric coordinates. */
void fcm__sim_bodies_positions(const fcm_space *s, const sim_bodies *B, const double *x, int motion,
                               double *out);
fcm_status fcm__sim_bodies_boxes(fcm_ctx *ctx, sim_bodies *B, const double *y, const double *dy,
                                 int rebuild, double pad);
void fcm__sim_bodies_sample(const sim_bodies *B, fcm_index n, const double *y, double p[3]);
double fcm__sim_bodies_distance(const sim_bodies *B, const double p[3], fcm_index t,
                                const double *y, double g[3], double beta[3]);
/* The triangles sample n sees (its own with self-contact; not the bodies it ignores, unless
 * all) whose boxes meet [lo, hi], into B->buf; whether triangle t is a target of sample n. */
fcm_status fcm__sim_bodies_candidates(fcm_ctx *ctx, sim_bodies *B, fcm_index n, const double lo[3],
                                      const double hi[3], int all);
int fcm__sim_bodies_target(sim_bodies *B, fcm_index n, fcm_index t);
/* Sample n's point p in B->y and the candidates within r of it, into B->buf. */
fcm_status fcm__sim_bodies_near(fcm_ctx *ctx, sim_bodies *B, fcm_index n, double r, int all,
                                double p[3]);
/* Friction between bodies (contact_bodies_friction.c). lag: at x, each pair within d^ keeps its
 * normal force, closest point and tangent basis (start: x is the substep's start, whose node
 * positions the slip counts from; change, may be NULL: the relative change of the sum of the
 * normal forces). slip: pair q's sample motion since the substep's start relative to its
 * triangle's closest point, at the node positions B->y. work: the friction forces' work over
 * the slip at x. */
fcm_status fcm__sim_bodies_friction_lag(fcm_integrator *I, sim_contact *c, const double *x,
                                        int start, double *change);
void fcm__sim_bodies_slip(const sim_bodies *B, const sim_fpair *q, double delta[3]);
double fcm__sim_bodies_friction_work(const fcm_integrator *I, const sim_contact *c,
                                     const double *x);
/* Whether the pair (sample n, triangle t of its own body) is excluded from self-contact: its
 * reference distance below B->rho (counted in self_tests). */
int fcm__sim_bodies_excluded(sim_bodies *B, fcm_index n, fcm_index t);
/* Self-contact at x: the own-body pairs within d^ (pairs), and the largest depth of an interior
 * sample inside its own body (depth, where: may be NULL), computed with or without the option
 * (contact_bodies_depth.c). */
fcm_status fcm__sim_bodies_self_stats(const fcm_integrator *I, const sim_contact *c,
                                      const double *x, long long *pairs, double *depth,
                                      double where[3]);
long long fcm__sim_bodies_self_tests(const sim_contact *c);
/* The distance below which a sample ignores another body from the first substep on: d^, or
 * 1e-9 d^ in a static solve (only the sides of a cut). */
double fcm__sim_bodies_blind_start(const fcm_integrator *I, const sim_contact *c);
/* Each pair of a sample and a triangle of another body within d^ at x that the barrier holds
 * (not ignored): fn with an element of each side, the sample's position ya, the closest point
 * yb and the unit direction g from yb to ya (the static check of the rigid modes, rigid.c). */
fcm_status fcm__sim_bodies_support(const fcm_integrator *I, const sim_contact *c, const double *x,
                                   void (*fn)(void *user, fcm_index elem_a, const double ya[3],
                                              fcm_index elem_b, const double yb[3],
                                              const double g[3]),
                                   void *user);
/* The sample points and (in *triangles, may be NULL) the triangles of the surface. */
fcm_index fcm__sim_bodies_samples(const sim_contact *c, fcm_index *triangles);
/* The search trees built so far (each evaluation, step bound and stats builds one). */
long long fcm__sim_bodies_builds(const sim_contact *c);
int fcm__sim_point_triangle(const double p[3], const double a[3], const double b[3],
                            const double c[3], double q[3], double e[3]);
void fcm__sim_point_triangle_distance(const double p[3], const double a[3], const double b[3],
                                      const double c[3], double *d, double g[3], double *H,
                                      int *region);

/* Time schemes (scheme.c). Options: FCM_ERR_ARG naming the member and its range. */
fcm_status fcm__sim_scheme_validate(fcm_ctx *ctx, const fcm_integrator_options *o);
/* The constants of the options' scheme (static and backward Euler: the kind alone). */
sim_scheme fcm__sim_scheme_constants(const fcm_integrator_options *o);
/* Set-up: the scheme's work vectors (a_bak, ud, fstep). */
fcm_status fcm__sim_scheme_setup(fcm_integrator *I);
/* The coefficient of M in the Newton matrix and the length h_d the damping matrix is divided by,
 * for a (sub)step h > 0: backward Euler 1/h^2 and h; the others cmass/h^2 and beta h/gamma. */
double fcm__sim_mass_coeff(const fcm_integrator *I, double h);
double fcm__sim_damp_length(const fcm_integrator *I, double h);
/* Newton's start of a dynamic substep from u_n = un: the inertia centre uhat, the damping centre
 * (ud; backward Euler: un) and the initial guess into u (free DOFs; un on the constrained). */
void fcm__sim_scheme_predict(fcm_integrator *I, double h);
/* Before a substep's constraints move to its end: f_int(u_n) (with the boundary constraints'
 * force at their current time) into fstep, when alpha_f != 0. *reason = NONFINITE when it is not
 * finite. */
fcm_status fcm__sim_scheme_force(fcm_integrator *I, fcm_step_reason *reason, sim_stats *stats);
/* After the damping matrix of the substep is set: the step's constant force f_a into fstep (from
 * f_int(u_n) there, fprev, D v and M a). */
fcm_status fcm__sim_scheme_begin(fcm_integrator *I);
/* The state update of a converged substep of length h: v (and a) from u, un. */
void fcm__sim_scheme_update(fcm_integrator *I, double h);
/* Before a step of a scheme that needs it: a = M^-1 (f_ext(t) - f_int(u) - D v) with the
 * active constrained DOFs at zero, solved by the Newton systems' solver; a failed solve is an
 * error naming the cause. */
fcm_status fcm__sim_initial_acceleration(fcm_integrator *I, sim_stats *stats);

/* newton.c, for scheme.c: the internal force at x with the boundary constraints' (summed over a
 * backend's processes; *finite = 0 on NaN/Inf); the damping matrix at un (*reason NONFINITE);
 * the symmetric elimination of the active constraints on H with the increments w1 (b lifted
 * when predictor). */
fcm_status fcm__sim_internal_force(fcm_integrator *I, const double *x, double *fint, int *finite,
                                   sim_stats *stats);
fcm_status fcm__sim_update_damping(fcm_integrator *I, fcm_step_reason *reason, sim_stats *stats);
fcm_status fcm__sim_eliminate(fcm_integrator *I, int predictor);

/* Give a new integrator the serial backend (its owned flags: every DOF). (integrator_backend.c) */
fcm_status fcm__sim_serial_backend(fcm_integrator *I);

/* With a backend (fem/fem_backend.h): agree on st and sum the partial quantities over the
 * processes: the ns scalars and the vector vec (n; may be NULL). No matrix is ever summed
 * (the mass, damping and Newton matrices stay partial). Without one: returns st.
 * (integrator.c) */
fcm_status fcm__sim_reduce(fcm_integrator *I, fcm_status st, double *scalars, int ns, double *vec);

/* Hanging-node constraints (hanging.c). setup: P and the hanging DOFs when the space's mesh has
 * hanging nodes, refusing what cannot apply them (a distributed backend, multigrid, the block
 * Jacobi and Schwarz preconditioners) with FCM_ERR_UNSUPPORTED. constraints: owner (n: the
 * constraint + 1 holding each DOF, 0 none; build_constraints()) loses its hanging DOFs, which
 * follow their masters; FCM_ERR_UNSUPPORTED when a master is not held by the same constraint.
 * storage: Ha (if not yet) and a matrix *A of H's pattern. fill: x = P x (the hanging entries
 * from their masters). reduce: g = P^T g (zero on the hanging DOFs). matrix: H = P^T Ha P +
 * I_h. Nothing of these allocates but setup and storage. */
fcm_status fcm__sim_hanging_setup(fcm_integrator *I);
void fcm__sim_hanging_destroy(fcm_integrator *I);
fcm_status fcm__sim_hanging_constraints(fcm_integrator *I, int *owner);
fcm_status fcm__sim_hanging_storage(fcm_integrator *I, fcm_csr **A);
void fcm__sim_hanging_fill(const fcm_integrator *I, double *x);
void fcm__sim_hanging_reduce(const fcm_integrator *I, double *g);
fcm_status fcm__sim_hanging_matrix(fcm_integrator *I);

/* The matrix the Newton matrix's tangent is assembled into: H, or Ha with hanging nodes. */
static inline fcm_csr *fcm__sim_tangent_target(const fcm_integrator *I)
{
  return I->hP ? I->Ha : I->H;
}

#endif /* FCM_SIM_IMPL_H */
