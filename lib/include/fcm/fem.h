/* fcm — finite element spaces on a background mesh and assembly of linear
 * elasticity: DOF map (3 unknowns per active node), the sparse pattern built
 * once with per-cell scatter offsets, parallel deterministic assembly of
 * stiffness, consistent mass and body force, symmetric Dirichlet elimination.
 * A space is immutable after creation: assembly only reads it and keeps its rules
 * and scratch in an fcm_assembly_workspace, so any number of workspaces (and
 * integrators) may share one space. */
#ifndef FCM_FEM_H
#define FCM_FEM_H

#include "fcm/core.h"
#include "fcm/embed.h"
#include "fcm/geom.h"
#include "fcm/io.h"
#include "fcm/la.h"
#include "fcm/material.h"
#include "fcm/mesh.h"
#include "fcm/quad.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A vector-valued (3 components) Lagrange space on the active cells of a mesh.
 * DOF numbering: node n (if active) owns DOFs 3k, 3k+1, 3k+2 with k its rank
 * among the active nodes (ascending node id), components x, y, z.
 *
 * With cuts (fcm_cell_rules_create_cut()), the space is enriched (generalized XFEM,
 * Ton-That et al. 2024): its *elements* are the material pieces of the active cells,
 * and the pieces incident to a node (its support) are grouped into connected components
 * along the links of the rules; each component gets its own copy of the node's three DOFs,
 * i.e. the node's shape function times the component's indicator function. A node whose
 * support is not separated keeps one copy; a piece that touches no node still moves with
 * the copies of its cell's nodes. A node's copies have consecutive DOFs, numbered node by
 * node (ascending node id), components of a node by their first element; without cuts
 * there is one element per active cell and one copy per active node, as above. */
typedef struct fcm_space fcm_space;

/** Create the space on `mesh` and build the matrix pattern, the per-cell
 * scatter offsets and a cell colouring (no two cells of a colour share a node).
 * @param[in]  ctx         context; must outlive the space
 * @param[in]  mesh        borrowed: must outlive the space and stay unchanged
 * @param[in]  cell_active num_cells flags (copied), or NULL for all cells. A node is
 *                         active when an active cell uses it; inactive nodes get no DOFs.
 * @param[out] space       the new space, NULL on failure
 * @return FCM_OK, FCM_ERR_ARG (NULL, no active cell), FCM_ERR_UNSUPPORTED (more
 * DOFs than 32-bit column indices hold), FCM_ERR_ALLOC. Allocates O(nnz). */
FCM_API fcm_status fcm_space_create(fcm_ctx *ctx, const fcm_mesh *mesh,
                                    const unsigned char *cell_active, fcm_space **space);

/** Create the space of an embedded (FCM) problem (default fcm_space_options): the active cells
 * are those
 * `rules` does not drop; assembly integrates cut cells with their own rules from
 * `rules` (stiffness rule for stiffness, forces and energy; mass rule for mass;
 * stabilization points included) and full cells with the standard rule.
 * @param[in] rules borrowed: must outlive the space; built on `mesh`
 * @return as fcm_space_create(), and FCM_ERR_ARG when `rules` belongs to another mesh. */
FCM_API fcm_status fcm_space_create_embedded(fcm_ctx *ctx, const fcm_mesh *mesh,
                                             const fcm_cell_rules *rules, fcm_space **space);

/** Options of fcm_space_create_embedded_with(). */
typedef struct fcm_space_options {
  double constrain_ratio; /**< Koschier et al. 2017, Sec. 6: a DOF copy whose support (the
                               volume of the pieces that use it) is below this fraction of its
                               node's (the pieces of all the node's elements) is constrained to
                               move with its piece: its elements use the DOFs of the largest
                               copy at another of their nodes instead (exact for translations),
                               and it leaves the system. A fragment the cuts separate
                               completely, all of whose copies are tiny, has no such copy: it
                               stays attached at its nodes (their largest copies; Koschier's
                               "sticking", at most this fraction of the nodes' material).
                               In [0, 0.5), default 1e-9; 0: off. Only copies of enriched
                               nodes (cuts) are affected. */
} fcm_space_options;

/** Defaults as documented on each member. */
FCM_API fcm_space_options fcm_space_options_default(void);

/** fcm_space_create_embedded() with options (NULL: defaults).
 * @return as fcm_space_create_embedded(), and FCM_ERR_ARG for an option out of range. */
FCM_API fcm_status fcm_space_create_embedded_with(fcm_ctx *ctx, const fcm_mesh *mesh,
                                                  const fcm_cell_rules *rules,
                                                  const fcm_space_options *opts, fcm_space **space);

/** Number of DOF copies the options' constraint removed (moved with their piece). */
FCM_API fcm_index fcm_space_num_constrained_copies(const fcm_space *space);

/** Number of local nodes of element `elem` where it uses, in place of a constrained copy,
 * the DOFs of the copy that copy moves with (fcm_space_element_dofs() there may name another
 * node's copy, or another copy of the same node): the field on such an element is not the
 * one its own copies would give, and fcm_space_transfer() sets no value from it there.
 * 0 for an element without (or out of range). No allocation; thread safe. */
FCM_API int fcm_space_element_constrained(const fcm_space *space, fcm_index elem);

/** The cell rules of an embedded space, or NULL. */
FCM_API const fcm_cell_rules *fcm_space_cell_rules(const fcm_space *space);

/** Whether `cell` carries unknowns (1) or was left out (0, also out of range). */
FCM_API int fcm_space_cell_active(const fcm_space *space, fcm_index cell);

/** Destroy the space; accepts NULL and `*space == NULL`, sets `*space = NULL`. */
FCM_API void fcm_space_destroy(fcm_space **space);

/** Number of DOFs (3 x active nodes). */
FCM_API fcm_index fcm_space_num_dofs(const fcm_space *space);
/** First DOF of a node (its x component), or -1 for an inactive or out-of-range node. */
FCM_API fcm_index fcm_space_node_dof(const fcm_space *space, fcm_index node);
/** Number of copies of `node` (0: inactive or out of range; 1 unless cuts separate its
 * support); their DOFs start at fcm_space_node_dof() and are consecutive. */
FCM_API fcm_index fcm_space_node_copies(const fcm_space *space, fcm_index node);
/** Number of elements: one per active cell, or per material piece where cuts split cells. */
FCM_API fcm_index fcm_space_num_elements(const fcm_space *space);
/** Number of elements of `cell` (0 inactive) and, in *first (may be NULL), the first one. */
FCM_API fcm_index fcm_space_cell_elements(const fcm_space *space, fcm_index cell, fcm_index *first);
/** The cell of element `elem` (-1 out of range). Element k of a cell integrates with the
 * rules of the cell's piece k (fcm_cell_rules_get_piece()). */
FCM_API fcm_index fcm_space_element_cell(const fcm_space *space, fcm_index elem);
/** The first DOF at each of the element's nodes_per_cell nodes (cell node order): the copy
 * the element uses; NULL out of range. Pointer into the space. */
FCM_API const fcm_index *fcm_space_element_dofs(const fcm_space *space, fcm_index elem);
/** Number of colours of the assembly colouring. */
FCM_API int fcm_space_num_colors(const fcm_space *space);
/** The mesh the space was built on. */
FCM_API const fcm_mesh *fcm_space_mesh(const fcm_space *space);

/** Hanging-node constraints of a space on an octree mesh (fcm_mesh_create_octree()): the
 * matrix T (num_dofs x num_free) with u = T u_free for every field of the conforming space.
 * A node hanging on a face or edge of an active cell takes the value of that cell's trace
 * there (its shape functions at the node: Hex8 1/2 on an edge, 1/4 on a face; Hex20 the
 * serendipity face or edge functions), with masters that hang themselves replaced by their
 * own masters (chains at 2:1); every other active DOF is free (its row of T is one 1). The
 * constrained system is T^T K T u_free = T^T f (fcm_csr_create_ptap()); Dirichlet values go on the
 * free DOFs. A node hanging only on inactive cells stays free. After cuts (DOF copies), each copy
 * of a hanging node follows the coarse cell's piece in its own material component (the pieces
 * around the node joined by the rules' links, across faces of any levels): the copies of the
 * masters that piece uses; a copy whose component holds no coarse piece stays free. With
 * copies constrained to move with their piece (fcm_space_options.constrain_ratio), a row is
 * built from the DOFs the coarse piece's element reads (at a constrained slot, those of the
 * copy it follows), and a constrained copy has no row (it left the system).
 * @param[in]  space    any space on any mesh (a mesh without hanging nodes gives T = I)
 * @param[out] free_dof num_dofs entries (may be NULL): the column of each free DOF, -1 for
 *                      a constrained one
 * @param[out] T        the new matrix (FCM_CSR_GENERAL), NULL on failure
 * @return FCM_OK; FCM_ERR_ARG (NULL); FCM_ERR_UNSUPPORTED (a copy whose component joins two
 *         pieces of the coarse cell that use different copies of a master: ambiguous; more
 *         free DOFs than 32-bit columns);
 *         FCM_ERR_ALLOC.
 * Allocates T and O(num_nodes + num_elems x nodes per cell) scratch. Thread safe. */
FCM_API fcm_status fcm_space_hanging_matrix_create(const fcm_space *space, fcm_index *free_dof,
                                                   fcm_csr **T);

/** Carry a field (displacement, velocity: num_dofs of `from`) over a cut: `to` must be the
 * space of rules that extend the rules of `from` by one cut (fcm_cell_rules_create_cut()).
 * Every copy of `to` takes, from one of the elements that use it, the value that element's
 * parent piece had at that node in `from` (the cut only splits pieces and links, so all of
 * them agree), and the field is unchanged at every point of every element of `to`: mass,
 * linear and angular momentum are preserved up to rounding. The exception are the elements
 * with a constrained copy's place (fcm_space_element_constrained(): tiny pieces, below
 * fcm_space_options.constrain_ratio of their nodes' supports): they move with the copy they
 * follow, so their field, and their share of the momenta, may change with the cut.
 * @param[out] x_to num_dofs of `to`.
 * @return FCM_OK, FCM_ERR_ARG (NULL, other mesh, unrelated rules). No allocation. */
FCM_API fcm_status fcm_space_transfer(const fcm_space *from, const fcm_space *to,
                                      const double *x_from, double *x_to);

/** Mass, linear momentum and angular momentum (about the origin) of the body, integrated
 * over the authentic quadrature points of the mass rules (the fictitious stabilization
 * points are not the body): m = int rho, p = int rho v, L = int rho x cross v with
 * x = X + u. Exact for the polynomial fields of the space where the mass rules are (cut
 * cells: rules of the mass strength), so a cut, which leaves the field unchanged, leaves
 * all three unchanged up to rounding. u and v (num_dofs) may be NULL (zero); outputs may
 * be NULL. The first call integrates each element's mass block B_ab = int N_a N_b over those
 * points once and the space keeps the blocks (nn (nn + 1) / 2 doubles per element, freed
 * with the space; a cut's new space builds its own); every call then reduces m = rho sum
 * B_ab, p = rho sum B_ab v_b, L = rho sum B_ab x_a cross v_b in O(elements x nn^2), equal
 * to the sums over the points up to rounding and independent of the thread count.
 * @return FCM_OK, FCM_ERR_ARG (NULL space, density < 0, embedded rules built without mass
 * rules), FCM_ERR_ALLOC (the first call). Thread safe: a first call made concurrently
 * builds the blocks once. */
FCM_API fcm_status fcm_space_momentum(const fcm_space *space, double density, const double *u,
                                      const double *v, double *mass, double linear[3],
                                      double angular[3]);

/** Create a symmetric CSR matrix with the space's pattern and zero values.
 * @return FCM_OK, FCM_ERR_ALLOC. Release with fcm_csr_destroy(). */
FCM_API fcm_status fcm_space_matrix_create(const fcm_space *space, fcm_csr **A);

/** The material model of the fictitious stabilization points of cut cells (flag 1 in
 * fcm_cell_rules_get()) in fcm_assemble_hyperelastic(); authentic points always use the
 * exact model. alpha x an indefinite full-cell tangent does not lift the small blocks of
 * cut cells, so by default the fictitious points carry a positive semi-definite tangent. */
typedef enum fcm_fictitious_model {
  /** Exact energy and force of the material (rotation invariant, so the O(alpha)
   * stabilization exerts no torque), PSD-projected tangent (Smith et al. 2019): the
   * tangent differs from the derivative of the force by alpha (K - K_psd) on these
   * points only (default). */
  FCM_FICTITIOUS_PROJECTED = 0,
  /** Linear elasticity about the rest state with the material's (mu, lambda): energy,
   * force and the constant PSD tangent are consistent (a true Hessian), but not
   * rotation invariant (an O(alpha) torque under large rotations). */
  FCM_FICTITIOUS_LINEAR = 1,
  /** The exact model with its exact tangent, which may be indefinite. */
  FCM_FICTITIOUS_EXACT = 2,
  FCM_FICTITIOUS_MODEL_COUNT
} fcm_fictitious_model;

/** DOF blocks of flagged cells, e.g. the blocks of an additive Schwarz preconditioner
 * (fcm_schwarz_create() of fcm/solve.h; the paper's choice: the cut cells with volume
 * fraction below theta = 0.5). Block k holds the DOFs of the k-th element of the flagged
 * cells in ascending element order (one per cell, or one per piece of a cell that cuts
 * split): node order of the cell, components x, y, z (fcm_space_element_dofs()), each copy
 * once (an element that uses one copy at two nodes, a tiny copy constrained to another
 * node's, lists it at the first), so the DOFs of a block are distinct. Call once with block_ptr and
 * block_dofs NULL for the counts, then with buffers of *num_blocks + 1 and *num_dofs entries.
 * @param[in]  space      the space
 * @param[in]  cell_flag  num_cells flags (nonzero: a block); flagged cells must be active
 * @param[out] num_blocks the number of elements of the flagged cells
 * @param[out] num_dofs   the total block size, at most num_blocks x 3 x nodes_per_cell
 * @param[out] block_ptr  NULL, or num_blocks + 1 offsets into block_dofs (block_ptr[0] = 0)
 * @param[out] block_dofs NULL, or num_dofs DOFs (both NULL or both given)
 * @return FCM_OK, FCM_ERR_ARG (NULL, one buffer only, a flagged inactive cell: named).
 * No allocation; thread safe. */
FCM_API fcm_status fcm_space_cell_blocks(const fcm_space *space, const unsigned char *cell_flag,
                                         fcm_index *num_blocks, fcm_index *num_dofs,
                                         fcm_index *block_ptr, fcm_index *block_dofs);

/** Quadrature strengths for assembly on full cells; FCM_DEFAULT selects the default rule of
 * fcm_element_standard_rule(). */
typedef struct fcm_assembly_options {
  int stiffness_strength;          /**< stiffness and body force */
  int mass_strength;               /**< consistent mass */
  fcm_fictitious_model fictitious; /**< model at stabilization points (hyperelastic only) */
} fcm_assembly_options;

/** The rule used on uncut (full) cells of `type` for the integral of `kind`
 * (FCM_RULE_STIFFNESS: gradients times gradients, also body force; FCM_RULE_MASS: shape
 * functions times shape functions).
 * strength FCM_DEFAULT selects the default: for tetrahedra the catalogue rule
 * (fcm_rule_create) of the element's stiffness_strength or mass_strength; for
 * hexahedra the Gauss-Legendre tensor rule with order+1 points per direction
 * (2^3 for Hex8, 3^3 for Hex20), which integrates both the stiffness and the mass
 * of an affine cell exactly and keeps the patch test exact on distorted cells —
 * total-degree rules of the element strengths do neither (the Hex20 stiffness
 * integrand has total degree 6 but degree 4 per direction).
 * strength in [0, FCM_RULE_MAX_STRENGTH] selects the catalogue rule of that strength for
 * either shape.
 * @return FCM_OK, FCM_ERR_ARG (invalid type or kind, strength outside
 * [0, FCM_RULE_MAX_STRENGTH] and not FCM_DEFAULT), FCM_ERR_ALLOC.
 * Allocates *rule; release with fcm_rule_destroy(). Thread safe. */
FCM_API fcm_status fcm_element_standard_rule(fcm_ctx *ctx, fcm_element_type type,
                                             fcm_rule_kind kind, int strength, fcm_rule **rule);

/** Defaults: both strengths FCM_DEFAULT (element defaults), fictitious FCM_FICTITIOUS_PROJECTED. */
FCM_API fcm_assembly_options fcm_assembly_options_default(void);

/** Everything assembly writes besides its outputs: the standard rules of full cells
 * with their tabulated shape functions (built on first use, then kept), per-thread
 * element buffers and per-cell energies. After the first assembly of each integrand,
 * assembling through a workspace allocates nothing. One workspace serves one
 * assembly at a time (not thread safe); several workspaces may share a space. */
typedef struct fcm_assembly_workspace fcm_assembly_workspace;

/** Create a workspace for assembly on `space` with the rule strengths `opts`.
 * @param[in]  space borrowed: must outlive the workspace
 * @param[in]  opts  copied; NULL for fcm_assembly_options_default()
 * @param[out] ws    the new workspace, NULL on failure
 * @return FCM_OK, FCM_ERR_ARG (NULL), FCM_ERR_ALLOC. Allocates per-thread buffers for
 * omp_get_max_threads() threads (assembly uses at most that many) and num_cells doubles. */
FCM_API fcm_status fcm_assembly_workspace_create(const fcm_space *space,
                                                 const fcm_assembly_options *opts,
                                                 fcm_assembly_workspace **ws);

/** Destroy a workspace; accepts NULL and `*ws == NULL`, sets `*ws = NULL`. */
FCM_API void fcm_assembly_workspace_destroy(fcm_assembly_workspace **ws);

/** The linear terms of fcm_assembly_workspace_linear(). */
typedef enum fcm_linear_term {
  FCM_LINEAR_STIFFNESS = 0,        /**< K into A (material) */
  FCM_LINEAR_MASS = 1,             /**< consistent mass rho N_a N_b I into A (material) */
  FCM_LINEAR_BODY_FORCE = 2,       /**< int rho accel N_a into f (material, accel) */
  FCM_LINEAR_BODY_FORCE_FIELD = 3, /**< int b(x) N_a into f (field = b, user) */
  FCM_LINEAR_SURFACE_TRACTION = 4  /**< int_{boundary} t(x, n) N_a into f (field = t, user) */
} fcm_linear_term;

/** A vector field evaluated at a physical point x; `normal` is the unit outward
 * normal for surface fields and NULL for volume fields. Writes value[3]. Called
 * concurrently from several threads. */
typedef void (*fcm_field_fn)(void *user, const double x[3], const double normal[3],
                             double value[3]);

/** One linear term and its data (plain value type; the pointers are borrowed for
 * the call). Members a term does not use are ignored. */
typedef struct fcm_linear_form {
  fcm_linear_term term;
  const fcm_material *material; /**< STIFFNESS, MASS, BODY_FORCE: validated; only E, nu
                                     and the density are used (linear elasticity) */
  const double *accel;          /**< BODY_FORCE: uniform acceleration, 3 entries */
  fcm_field_fn field;           /**< BODY_FORCE_FIELD, SURFACE_TRACTION */
  void *user;                   /**< passed to `field` */
} fcm_linear_form;

/** Defaults: FCM_LINEAR_STIFFNESS, every pointer NULL. */
FCM_API fcm_linear_form fcm_linear_form_default(void);

/** The one linear assembly: add the term of `form` to A (matrix terms; A from
 * fcm_space_matrix_create() of the workspace's space) or to f (vector terms,
 * num_dofs entries). Cells are processed colour by colour, in parallel within a
 * colour: the result is bitwise independent of the number of threads.
 * @return FCM_OK, FCM_ERR_ARG (NULL, bad material, wrong matrix, non-finite accel,
 * traction without surface rules), FCM_ERR_GEOMETRY (det J <= 0 at a quadrature point:
 * the message names the cell), FCM_ERR_ALLOC (first use of a rule). */
FCM_API fcm_status fcm_assembly_workspace_linear(fcm_assembly_workspace *ws,
                                                 const fcm_linear_form *form, fcm_csr *A,
                                                 double *f);

/** fcm_assemble_hyperelastic() through a workspace (its strengths apply). */
FCM_API fcm_status fcm_assembly_workspace_hyperelastic(fcm_assembly_workspace *ws,
                                                       const fcm_material_params *mat,
                                                       const double *u, double *energy,
                                                       double *force, fcm_csr *tangent);

/** Add the linear elastic stiffness K to A (A must come from
 * fcm_space_matrix_create() of this space): fcm_assembly_workspace_linear() with
 * FCM_LINEAR_STIFFNESS through a workspace made for this call. `mat` is validated
 * (fcm_material_validate()); its model is not used: the stiffness, mass and body force
 * here are those of linear elasticity with the material's E, nu and density. Bitwise
 * independent of the number of threads; the values added are exactly symmetric (entry (i, j)
 * equals entry (j, i) bit for bit). @return FCM_OK, FCM_ERR_ARG (bad material, wrong matrix),
 * FCM_ERR_GEOMETRY (det J <= 0 at a quadrature point: the message names the cell),
 * FCM_ERR_ALLOC. Allocates a workspace; for repeated assembly keep one. */
FCM_API fcm_status fcm_assemble_stiffness(const fcm_space *space, const fcm_material *mat,
                                          const fcm_assembly_options *opts, fcm_csr *A);

/** Add the consistent mass matrix (rho N_a N_b I) to A. Status codes as above; an embedded
 * space whose cell rules were built without mass rules (fcm_cell_rules_options.kinds) is
 * FCM_ERR_ARG saying so (likewise the stiffness and force integrals without stiffness rules). */
FCM_API fcm_status fcm_assemble_mass(const fcm_space *space, const fcm_material *mat,
                                     const fcm_assembly_options *opts, fcm_csr *A);

/** Add the body force of a uniform acceleration `accel` (e.g. gravity),
 * f_a += integral of rho accel N_a, to f (num_dofs entries). Status codes as above. */
FCM_API fcm_status fcm_assemble_body_force(const fcm_space *space, const fcm_material *mat,
                                           const double accel[3], const fcm_assembly_options *opts,
                                           double *f);

/** Add the load of a body force density b(x) (force per volume), f_a += int b N_a.
 * @return as fcm_assemble_body_force(). */
FCM_API fcm_status fcm_assemble_body_force_field(const fcm_space *space, fcm_field_fn field,
                                                 void *user, const fcm_assembly_options *opts,
                                                 double *f);

/** Add the load of a surface traction t(x, n) on the embedded boundary,
 * f_a += int_{boundary} t N_a, with the surface rules of the space's cell rules.
 * @return FCM_OK, FCM_ERR_ARG (NULL, no surface rules: build the rules with
 * surface_strength >= 0), FCM_ERR_ALLOC. */
FCM_API fcm_status fcm_assemble_surface_traction(const fcm_space *space, fcm_field_fn traction,
                                                 void *user, double *f);

/** Hyperelastic energy, internal force and tangent at the displacement u:
 * E = sum over points of w det J Psi(F), F = I + grad u; force_i = dE/du_i (added
 * to `force`); tangent = d^2E/du^2 (added to `tangent`, space pattern), except at the
 * fictitious stabilization points of cut cells, whose model is opts->fictitious (default: exact
 * energy and force, PSD-projected tangent).
 * @param[in]  mat     from fcm_material_setup() (its project_psd is honoured)
 * @param[in]  u       num_dofs displacements
 * @param[out] energy  may be NULL; @param[in,out] force may be NULL; tangent may be NULL
 * @return FCM_OK, FCM_ERR_ARG, FCM_ERR_NUMERIC (the material gave NaN/Inf: the
 * message names the cell), FCM_ERR_GEOMETRY, FCM_ERR_ALLOC. Deterministic for any
 * number of threads (energy summed per cell in cell order); the tangent's values are exactly
 * symmetric, as the stiffness's. */
FCM_API fcm_status fcm_assemble_hyperelastic(const fcm_space *space, const fcm_material_params *mat,
                                             const double *u, const fcm_assembly_options *opts,
                                             double *energy, double *force, fcm_csr *tangent);

/** Impose u[dofs[k]] = values[k] on the symmetric system A u = b by elimination
 * that keeps A symmetric: b_i -= A_ic g_c for free rows, row and column c are
 * zeroed except the diagonal (kept, or 1 if it is not positive), b_c = A_cc g_c.
 * @param[in] dofs    ncon distinct DOF indices in [0, num_dofs)
 * @param[in] values  ncon prescribed values, or NULL for zeros
 * @return FCM_OK, FCM_ERR_ARG (index out of range, duplicate, non-square A), FCM_ERR_ALLOC.
 * Allocates O(num_dofs) workspace. */
FCM_API fcm_status fcm_space_apply_dirichlet(const fcm_space *space, fcm_index ncon,
                                             const fcm_index *dofs, const double *values,
                                             fcm_csr *A, double *b);

/** Interpolate a displacement field given per DOF at reference point `xi` of
 * `cell`: u = sum_a N_a(xi) u_a (inactive cells and cells split into several pieces:
 * FCM_ERR_ARG; use fcm_space_element_eval()). No allocation. */
FCM_API fcm_status fcm_space_eval(const fcm_space *space, fcm_index cell, const double xi[3],
                                  const double *u, double value[3]);

/** The element of `cell` that a point at reference coordinates xi belongs to: the cell's
 * element when it has one; in a cell that cuts split, the piece with the nearest authentic
 * quadrature point (exact away from the cut faces, a guess within a point spacing of them:
 * for display, e.g. of surface vertices). -1 for a cell out of range or without elements.
 * No allocation; thread safe. */
FCM_API fcm_index fcm_space_point_element(const fcm_space *space, fcm_index cell,
                                          const double xi[3]);

/** Number of separate bodies: connected components of the elements, two elements being
 * connected when they share a DOF copy (a node whose support component holds both). One
 * for an uncut body; -1 when the scratch cannot be allocated. Allocates (and frees). */
FCM_API fcm_index fcm_space_num_bodies(const fcm_space *space);

/** As fcm_space_eval() on element `elem` (its copies). @return FCM_OK, FCM_ERR_ARG. */
FCM_API fcm_status fcm_space_element_eval(const fcm_space *space, fcm_index elem,
                                          const double xi[3], const double *u, double value[3]);

/** Locate physical points: for each X[i] the lowest-numbered active cell containing it
 * (tolerance 1e-10 in reference coordinates) and its reference coordinates xi. A point in
 * no active cell (an embedded surface vertex in a dropped cell, or outside the mesh) gets
 * the active cell with the nearest bounding-box centre and xi outside the reference
 * element: the field there is the polynomial extrapolation of that cell.
 * @param[out] cell n cells; @param[out] xi n x 3; @param[out] extrapolated n flags or NULL
 * @return FCM_OK, FCM_ERR_ARG, FCM_ERR_GEOMETRY (no active cell, degenerate cell),
 * FCM_ERR_ALLOC. Allocates a search tree per call (do it once, then interpolate often). */
FCM_API fcm_status fcm_space_locate(const fcm_space *space, fcm_index n, const double *X,
                                    fcm_index *cell, double *xi, int *extrapolated);

/** values[3i..3i+3) = sum_a N_a(xi_i) u_a in cell[i] (from fcm_space_locate()).
 * @return FCM_OK, FCM_ERR_ARG (an inactive or out-of-range cell). No allocation. */
FCM_API fcm_status fcm_space_interpolate(const fcm_space *space, fcm_index n, const fcm_index *cell,
                                         const double *xi, const double *u, double *values);

/** Carry a field (displacement, velocity: num_dofs of `from`) onto the space `to` of a
 * refined background (fcm_mesh_create_refined()): each DOF of `to` takes the field of
 * `from` at its node (fcm_space_locate(), fcm_space_interpolate()). When every field of
 * `from` lies in `to` — a refinement of the same octree, hanging nodes constrained — the
 * field is reproduced exactly, so mass, momentum and kinetic energy are kept to rounding;
 * the hanging nodes of `to` get the values their constraints give.
 * @param[out] u_to num_dofs of `to`
 * @return FCM_OK; FCM_ERR_ARG (NULL, other element types, a node of `to` in no active cell of
 *         `from`: not a refinement); FCM_ERR_UNSUPPORTED (DOF copies: spaces after cuts);
 *         the errors of fcm_space_locate(); FCM_ERR_ALLOC. Allocates O(nodes). */
FCM_API fcm_status fcm_space_transfer_refined(const fcm_space *from, const fcm_space *to,
                                              const double *u, double *u_to);

/* ---------------------------------------------------------------- fields and output
 * What a host writes out of a solution u (num_dofs): node and surface-point fields, stress,
 * VTU files. Output convention: every file holds the points at their REFERENCE positions
 * with a point array `displacement`; ParaView's "Warp By Vector" with it shows the deformed
 * body. Stresses: 6 components in VTK's symmetric-tensor order xx, yy, zz, xy, yz, xz. */

/** Number of stress components and their order (VTK's symmetric-tensor order, so ParaView
 * labels the components correctly). */
enum {
  FCM_STRESS_XX = 0,
  FCM_STRESS_YY,
  FCM_STRESS_ZZ,
  FCM_STRESS_XY,
  FCM_STRESS_YZ,
  FCM_STRESS_XZ,
  FCM_STRESS_COMPONENTS
};

/** A DOF vector (num_dofs, e.g. u or v) as one 3-vector per background node:
 * node_field[3a .. 3a+3) for node a of the mesh; inactive nodes get 0. A node that cuts
 * gave several copies gets the copy of the largest support (the volume of the pieces that
 * use it; ties: the lowest copy), i.e. the part of the body most of its cells hold.
 * @param[in] dofs num_dofs values; @param[out] node_field 3 x num_nodes of the mesh
 * @return FCM_OK, FCM_ERR_ARG (NULL), FCM_ERR_ALLOC (only with copies: O(num_dofs) scratch).
 * Thread safe. */
FCM_API fcm_status fcm_space_node_field(const fcm_space *space, const double *dofs,
                                        double *node_field);

/** Stress of the material at reference point xi of element `elem` for the displacement u:
 * F = I + grad u, Cauchy stress sigma = P F^T / J (P = dPsi/dF of fcm_material_eval(); the
 * LINEAR model's small-strain stress P itself), von Mises stress
 * sqrt(3/2 s:s) with s the deviator of sigma, and the strain energy density
 * Psi(F) - Psi(I) per unit reference volume. Where J <= 0 (an inverted point) sigma and
 * von Mises are NaN. Any output may be NULL. At a physical point X: fcm_space_locate() gives
 * its cell and xi, fcm_space_point_element() the element (the piece, in a cell cuts split).
 * @param[in] mat validated (fcm_material_validate())
 * @return FCM_OK, FCM_ERR_ARG (NULL space or u, element out of range, bad material). No
 * allocation; thread safe. */
FCM_API fcm_status fcm_space_element_stress(const fcm_space *space, const fcm_material *mat,
                                            fcm_index elem, const double xi[3], const double *u,
                                            double stress[6], double *von_mises,
                                            double *energy_density);

/** Per background cell, the volume averages over the body's part of the cell of the
 * stress, von Mises stress and strain energy density of fcm_space_element_stress():
 * (integral of f) / (volume) over the authentic points of the stiffness rules of every
 * element (piece) of the cell (cut cells: their own rules, without stabilization points;
 * uncut cells: the standard stiffness rule). An affine u gives the exact constant. Inactive
 * cells get 0. Any output may be NULL.
 * @param[out] stress 6 x num_cells; von_mises, energy_density num_cells each
 * @return FCM_OK, FCM_ERR_ARG (NULL, bad material), FCM_ERR_ALLOC (the standard rule).
 * Parallel over cells (OpenMP); deterministic. */
FCM_API fcm_status fcm_space_cell_stress(const fcm_space *space, const fcm_material *mat,
                                         const double *u, double *stress, double *von_mises,
                                         double *energy_density);

/** A refinement indicator for static runs: eta[c] = sqrt(|c|) x the largest jump, over the
 * nodes of cell c and the six components, of the cell-averaged stress
 * (fcm_space_cell_stress()) between the active cells sharing that node. On a cut space the
 * averages are per element (each piece of a split cell apart) and the jumps between the
 * elements sharing a DOF copy: the jump across a cut, which the enrichment resolves, counts
 * nothing. Zero for a constant
 * stress (an affine u), about h^(5/2) |grad sigma| where the stress varies smoothly, large at
 * concentrations and singularities. Mark the cells with eta above a fraction of its largest
 * value and refine them (fcm_mesh_create_refined()). Inactive cells get 0.
 * @param[out] eta num_cells entries
 * @return FCM_OK, FCM_ERR_ARG (NULL, bad material), FCM_ERR_ALLOC. Allocates O(cells + nodes)
 * scratch. Deterministic. */
FCM_API fcm_status fcm_space_stress_jumps(const fcm_space *space, const fcm_material *mat,
                                          const double *u, double *eta);

/** The largest |u| over the body's quadrature points (the authentic points of the stiffness
 * rules of every element; the fictitious part of cut cells and inactive nodes do not count).
 * @return FCM_OK, FCM_ERR_ARG (NULL), FCM_ERR_ALLOC (the standard rule). */
FCM_API fcm_status fcm_space_max_displacement(const fcm_space *space, const double *u,
                                              double *max_norm);

/** Write the background mesh of the space as a VTU file (atomically), points at their
 * reference positions: point arrays `displacement` (fcm_space_node_field() of u; zero when u
 * is NULL) and `velocity` (only when v is given); cell arrays `active` (Int32 0/1),
 * `volume_fraction` (of the embedded rules; 1 without) and, when mat is given, the cell
 * averages of fcm_space_cell_stress(): `stress` (6), `von_mises`, `strain_energy_density`.
 * @return FCM_OK, FCM_ERR_ARG, FCM_ERR_IO (naming the path), FCM_ERR_ALLOC. Allocates
 * scratch for the fields. */
FCM_API fcm_status fcm_space_write_vtu(const fcm_space *space, const fcm_material *mat,
                                       const double *u, const double *v, const char *path);

/** The embedded surface of a body located in a space, for output: the boundary triangles of
 * the geometry (vertices compacted) and, when the space's rules carry cuts, each piece's
 * side of the cut faces (three points per triangle, flagged, each moving with its piece's
 * element, so both sides of a cut show the opening). Points are held at their reference
 * positions X; the cell and reference coordinates of each boundary vertex are found once.
 * After cuts, every point moves with the piece whose material holds it (the cut cells'
 * parts are made again from the geometry, as the rules' build made them), and a boundary
 * triangle that a cut crosses, or with a vertex on a cut, is replaced by its parts: the
 * triangle clipped by the cells it meets and by the parts of their pieces, exactly as the
 * pieces split the material, each part moving with its piece (a triangle partly outside the
 * mesh, whose parts would not cover it, stays whole). Triangles no cut reaches keep their
 * vertices and order, so the surface of an uncut body is the same as without cuts. */
typedef struct fcm_embedded_surface fcm_embedded_surface;

/** Locate the boundary vertices of `geom` in `space` (fcm_space_locate(): a vertex in no
 * active cell follows the nearest active cell's extrapolated field).
 * @param[in] space borrowed: must outlive the object (or be replaced by set_space)
 * @param[in] geom  borrowed: must outlive the object; the geometry the space's rules were
 *                  built on (a space with cuts splits the boundary by its cells)
 * @return FCM_OK, FCM_ERR_ARG (NULL, a geometry without boundary triangles), the errors of
 * fcm_space_locate(), FCM_ERR_ALLOC. Allocates. */
FCM_API fcm_status fcm_embedded_surface_create(const fcm_space *space, const fcm_geometry *geom,
                                               fcm_embedded_surface **surface);

/** Destroy; accepts NULL and `*surface == NULL`, sets `*surface = NULL`. */
FCM_API void fcm_embedded_surface_destroy(fcm_embedded_surface **surface);

/** Move to another space on the same mesh (after a cut: fcm_space_create_embedded() of the
 * new rules; the old space may be destroyed before): the element of every vertex is chosen
 * again, the triangles the cuts cross split again from the geometry's boundary (a later cut
 * splits the parts of earlier ones) and the cut faces rebuilt.
 * After a failure the surface is unusable (some vertices' elements may be stale) until a
 * later call succeeds: set it again or destroy it.
 * @return FCM_OK, FCM_ERR_ARG (NULL, other mesh), FCM_ERR_ALLOC, FCM_ERR_INTERNAL (a part
 * exceeding the clipping capacity). */
FCM_API fcm_status fcm_embedded_surface_set_space(fcm_embedded_surface *surface,
                                                  const fcm_space *space);

/** Points (boundary vertices first, then those of the split triangles' parts, then the
 * cut-face points) and triangles (the boundary triangles no cut splits, in their order, then
 * the parts, then the cut faces); borrowed views valid until the next set_space or destroy:
 * reference positions (3 x num_points), triangles (3 x num_triangles point indices,
 * outward), flags (num_points; 1 on a cut face). num_split_triangles: the boundary triangles
 * replaced by their parts. */
FCM_API fcm_index fcm_embedded_surface_num_points(const fcm_embedded_surface *surface);
FCM_API fcm_index fcm_embedded_surface_num_triangles(const fcm_embedded_surface *surface);
FCM_API const double *fcm_embedded_surface_points(const fcm_embedded_surface *surface);
FCM_API const fcm_index *fcm_embedded_surface_triangles(const fcm_embedded_surface *surface);
FCM_API const int32_t *fcm_embedded_surface_cut_flags(const fcm_embedded_surface *surface);
FCM_API fcm_index fcm_embedded_surface_num_split_triangles(const fcm_embedded_surface *surface);

/** The field u (num_dofs of the space) at the points: displacement (3 x num_points) and the
 * deformed positions X + u (3 x num_points); either output may be NULL.
 * @return FCM_OK, FCM_ERR_ARG (NULL surface or u). No allocation; thread safe. */
FCM_API fcm_status fcm_embedded_surface_eval(const fcm_embedded_surface *surface, const double *u,
                                             double *displacement, double *deformed);

/** fcm_space_element_stress() at every point (outputs 6 x num_points, num_points,
 * num_points; any may be NULL). @return as fcm_space_element_stress(). No allocation. */
FCM_API fcm_status fcm_embedded_surface_stress(const fcm_embedded_surface *surface,
                                               const fcm_material *mat, const double *u,
                                               double *stress, double *von_mises,
                                               double *energy_density);

/** Write the surface as a VTU file of triangles (atomically), points at their reference
 * positions: point arrays `displacement`, `cut_face` (Int32 0/1) and, when mat is given,
 * `stress` (6), `von_mises`, `strain_energy_density` at the points.
 * @param[in] u num_dofs; NULL: zero
 * @return FCM_OK, FCM_ERR_ARG, FCM_ERR_IO (naming the path), FCM_ERR_ALLOC. Allocates
 * scratch for the fields. */
FCM_API fcm_status fcm_embedded_surface_write_vtu(const fcm_embedded_surface *surface,
                                                  const fcm_material *mat, const double *u,
                                                  const char *path);

#ifdef __cplusplus
}
#endif
#endif /* FCM_FEM_H */
