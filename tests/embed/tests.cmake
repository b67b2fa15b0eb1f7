# Embedded (cut-cell) quadrature: exactness per cell on random polyhedra (initial and
# simplified rules, Hex8 and Tet4 cells), global volume and moments of procedural shapes,
# degenerate configurations, surface rules, classification and stabilization, thread
# determinism, errors, allocation failures; the throughput benchmark (label bench).
fcm_add_test(embed_exact_hex_initial tests/embed/exactness.c ARGS hex initial)
fcm_add_test(embed_exact_tet_initial tests/embed/exactness.c ARGS tet initial)
fcm_add_test(embed_exact_hex_simplified tests/embed/exactness.c ARGS hex simplified)
fcm_add_test(embed_exact_tet_simplified tests/embed/exactness.c ARGS tet simplified)
fcm_add_test(embed_exact_hex_simplified_full tests/embed/exactness.c ARGS hex simplified-full
             LABELS slow TIMEOUT 3600)
fcm_add_test(embed_exact_tet_simplified_full tests/embed/exactness.c ARGS tet simplified-full
             LABELS slow TIMEOUT 3600)
fcm_add_test(embed_volume tests/embed/volume.c)
fcm_add_test(embed_degenerate tests/embed/degenerate.c)
fcm_add_test(embed_surface tests/embed/surface.c)
# The boundary area in dropped cells: a face-parallel sliver's face in closed form; dropped and
# kept areas add up to the surface's.
fcm_add_test(embed_dropped_area tests/embed/dropped_area.c)
fcm_add_test(embed_rules tests/embed/rules.c)
fcm_add_test(embed_errors tests/embed/errors.c)
# Simplify only where it pays: the cost model on both sides of a break-even, AUTO = ON with
# many assemblies, = OFF with none or a negligible point cost; its option errors.
fcm_add_test(embed_simplify_auto tests/embed/simplify_auto.c)
fcm_add_test(embed_bench tests/embed/bench.c LABELS bench TIMEOUT 3600)
# Degenerate cuts (catalogue) and the random cut campaign: per-cell volume and first moments
# within 1e-12 h^3 of exact values (2e-12 simplified), positive finite weights, <= M points
# or a counted fallback; the long campaign (label slow) runs 60x more cases, another seed.
fcm_add_test(embed_cut_catalogue tests/embed/cut_campaign.c ARGS catalogue)
fcm_add_test(embed_cut_campaign tests/embed/cut_campaign.c ARGS campaign 1000)
fcm_add_test(embed_cut_campaign_long tests/embed/cut_campaign.c ARGS campaign 60000 7
             LABELS slow TIMEOUT 3600)
fcm_add_test(embed_limits tests/embed/limits.c)
# Embedding diagnostics (volume outside the background by side, ratio, wholly outside is an
# error with both boxes), the progress callback, voxel and level-set bodies embedded.
fcm_add_test(embed_diagnostics tests/embed/diagnostics.c)
fcm_add_test(embed_cut tests/embed/cut.c)
# Rule kinds asked for (fcm_cell_rules_options.kinds): stiffness alone builds no mass points
# and gives the same stiffness rules; the kind not built is FCM_ERR_ARG (accessors, mass
# matrix, momentum); a cut keeps the kinds; bad kind sets rejected.
fcm_add_test(embed_kinds tests/embed/kinds.c)
# Random XFEM cuts (planes and V-shaped cuts through nodes, midpoints and quarter points,
# shifted by 0 .. 1e-6): every cell's volume conserved within 1e-12; the few degenerate
# ones are shifted by fcm_cell_rules_create_cut() (FCM_TEST_VERBOSE=1 prints how many).
fcm_add_test(embed_xfem_random tests/embed/cut.c ARGS campaign 300 1)
fcm_add_test(embed_xfem_random_long tests/embed/cut.c ARGS campaign 20000 11 LABELS slow
             TIMEOUT 3600)
# cell_mask: unflagged cells classified without points, flagged ones as without a mask (the
# distributed build of fcm/petsc.h); the one-element assembly sums to the space's.
fcm_add_test(embed_cell_mask tests/embed/cell_mask.c)
# the crop of the geometry to what a distributed build reads (fcm__embed_crop_geometry()): a
# build on it with the other cells' classes handed over equals the build on the whole geometry
# bit for bit (classes, fractions, pieces, own rules, surface triangle ids, outside volumes)
fcm_add_test(embed_crop tests/embed/crop.c)
# Cuts near grid planes and body faces: planes tilted 1e-12 .. 1e-5 off grid planes and body
# faces, through nodes, edge midpoints, face centres and body vertices, single and repeated,
# on all four elements and four bodies (tet box, hex box, ring, hollow ball): no error, every
# cell keeps its material to 1e-12, every body on one side of every plane, the number of
# bodies of an independent reference; the catalogue of configurations that once failed; the
# long campaign (label slow) runs 20,000 cases per element.
fcm_add_test(embed_cut_families_catalogue tests/embed/cut_families.c ARGS catalogue)
fcm_add_test(embed_cut_families tests/embed/cut_families.c ARGS campaign 50 1)
fcm_add_test(embed_cut_families_long tests/embed/cut_families.c ARGS campaign 20000 5
             LABELS slow TIMEOUT 7200)
# Cut-cell moments from the boundary surface alone against the clipped volume mesh (every
# monomial of degree <= 4, per cell, 1e-12 |K|), Hex8 and Tet4, a box on grid planes; the
# inside test against point-in-tet; an open surface is an error.
fcm_add_test(embed_surface_moments tests/embed/surface_moments.c)
# Surface moments and inside tests on sliver tets (cond(A) up to 1e12, as a cut part's fan
# tets): a closed ball gives every rule (no crossing triangle left out of the candidates).
fcm_add_test(embed_sliver_lines tests/embed/sliver_lines.c)
# A part's surface moments whose fan tets lie clear of the boundary share one line query, and
# clear boxes kept between inside tests answer for points and tet corners in them: the rule of
# every part (a ball's and a hollow ball's cells, whole and halved) the bits of each tet's own
# moment rule, inside tests as with a fresh scratch; the volumes add up to the cells' (1e-12 |K|).
fcm_add_test(embed_clear_tets tests/embed/clear_tets.c)
# The inside test of a cell's columns (the winding number of a clear top or bottom face and the
# cell's own triangles, kept from column to column) and of the shorter half of a line through
# the points on the geometry's own tree, against the whole line on another tree: the same answer
# for every point of Hex8 and Tet4 cells over a ball and a hollow ball with holes, the ball's own
# answer away from its surface, both faces and the fallback exercised.
fcm_add_test(embed_inside_columns tests/embed/inside_columns.c)
# A geometry of its boundary surface alone (volume_mesh = 0): global moments equal the exact
# polyhedron integrals (Hex8, Tet4, Hex20), the volume beyond each side of the grid from the
# surface equals the tets', a cut and the volume path refuse it.
fcm_add_test(embed_surface_only tests/embed/surface_only.c)
# The latency of a cut's rule update on a bunny-like body at the papers' grid sizes, per phase
# (label bench; --model path measures a model instead of the generated body).
fcm_add_test(embed_cut_bench tests/embed/cut_bench.c LABELS bench TIMEOUT 3600)
# A cut keeps what it does not change: a box body cut by two tilted planes, a plane beside it
# and one along a grid plane; every piece exact against the polytope's moments, the result
# against the cut without its shortcuts (pieces, links, cut faces bit for bit; each cell's
# rules those of the reference or, kept, of the rules extended); cuts that change nothing
# integrate nothing and leave every rule bit-identical.
fcm_add_test(embed_cut_keep tests/embed/cut_keep.c)
# The same under FCM_CELL_SIMPLIFY_AUTO (the cut cells finished after all are built): the cells a
# cut keeps are not finished again.
fcm_add_test(embed_cut_keep_auto tests/embed/cut_keep.c ARGS auto)
# The parts' connectivity inside a cell: a part touching another only along an edge stays
# apart, cuts across the cell, as coplanar triangles and on its face; random cuts (near the
# cell's and each other's planes, coplanar neighbours, ending inside): the components equal the
# pairwise face-by-face definition's, numbering included.
fcm_add_test(embed_parts_links tests/embed/parts_links.c)
# The rules file for other codes read back: bitwise the accessors' rules piece by piece (with
# and without a cut), exact volumes and monomials, a closed surface rule (sum w n = 0,
# sum w x.n = 3 V), bad arguments refused leaving no temporary and the old file intact.
fcm_add_test(embed_rules_write tests/embed/rules_write.c)
# Cuts of a body without a volume mesh: a faceted ball given as tets and as its boundary alone,
# cut by a plane, a crack, a V, a crossing plane and a square cutting off a cap; every cell as
# many pieces, matched pieces' monomials up to the rules' strengths within 1e-12 of the
# reference cell, as many components (Hex8, Tet4; the slow one Hex20, Tet10).
fcm_add_test(embed_cut_surface tests/embed/cut_surface.c)
fcm_add_test(embed_cut_surface_quadratic tests/embed/cut_surface.c ARGS quadratic LABELS slow)
# A sheet of many nearly coplanar triangles (warped by 1/275 of a cell) across a ball given as
# tets and as its boundary: no degenerate cell, every cell as many pieces as under the flat
# sheet, piece volumes within the warp's (5e-3 of a cell), the body's volume kept (1e-12).
# About 90 s in a release build; the sanitizer build (Debug, ASan + UBSan) takes about 7 min.
fcm_add_test(embed_cut_warped tests/embed/cut_warped.c TIMEOUT 900)
# A cutting scene on a surface file: no Gmsh phase, the same DOFs and centre of mass (1e-12) as
# the volume path, the largest displacement within 1 %.
fcm_add_test(embed_cut_surface_scene tests/embed/cut_surface_scene.c)
# The fitted rules of a cut's pieces on a body given by its surface alone (a faceted ball cut by
# a plane through its middle, a plane 1e-4 of a cell off a grid plane, a cap, a faceted groove
# making pieces of many parts): every monomial up to the strength as the volume path's (1e-12
# |K_ref|), positive weights, at most M points unless the cell fell back to the volume path,
# every point in the cell, the ball and on its piece's side of every plane; Hex8 and Tet4.
fcm_add_test(embed_cut_fit tests/embed/cut_fit.c)
# Hex8's cut-cell mass rules on the tensor space Q_2 by default (a hollow ball cut by a plane,
# surface and volume paths): every cut piece's Q_2 moments and 8 x 8 mass matrix as a P_6 rule
# unsimplified on its tets (1e-12), positive weights, at most 27 points in the cell and on the
# piece's side; explicit strength 6 gives P_6; rules of P_4 miss the mass matrix (> 1e-8).
fcm_add_test(embed_q2_mass tests/embed/q2_mass.c)
# Hex8's cut-cell stiffness rules on the mass rules' space (stiffness_on_mass_space: Q_2), a
# hollow ball cut by two parallel tilted planes 2e-3 apart (thin slabs on the volume path):
# every cut piece's stiffness tensor (products of the shape functions' gradients) and mass
# matrix as a P_6 rule unsimplified on its tets (1e-12), at most 27 positive points in the cell
# and on the piece's sides, one fit for both kinds; the default P_2 stiffness misses (> 1e-8).
fcm_add_test(embed_q2_stiffness tests/embed/q2_stiffness.c)
# Cut pieces made of boxes of the cell's reference coordinates (a hollow ball in a sheared Hex8
# grid cut along its reference planes, a crack ending inside cells, then a tilted plane), with
# the stiffness on the mass space: the filled pieces' Gauss rules on their boxes and the box
# parts' material moments as one Hex8 cell; every cut piece's stiffness tensor and mass matrix
# as a P_6 rule unsimplified on its tets (1e-12); a weight off by 1e-6 fails the check; the face
# overlaps' material test on parallelograms (one Hex8 prism) answers as on their fan's tets.
fcm_add_test(embed_box_parts tests/embed/box_parts.c)
# What a cut keeps from the rules it extends (a surface body): the whole cells' material
# volumes, the face polygons of region cells no new cut reaches and the copied cells' rules
# give the rules of the same cuts made from stripped rules bit for bit, over five cuts (blades
# along the grid, overlapping regions, a tilted plane); a kept volume off by 1e-3 changes them;
# every kept face polygon of a part the body fills is covered by the prism's moments.
fcm_add_test(embed_cut_reuse tests/embed/cut_reuse.c)
# The face-link shortcut's full-part flag needs the part's depth along the face normal: full
# slabs of the unit cell thinner than 4 prism half-heights are not flagged on the face they
# lie on, thicker ones are; parts not full never are.
fcm_add_test(embed_face_full tests/embed/face_full.c)
# The embedded surface's pieces' finder: points near a cut (on it, off it by more than the
# width, beyond its edges; nothing without cuts), every point two pieces hold near a cut,
# points off the cut in one piece, and the same answers after the finder is released and the
# rules set again.
fcm_add_test(embed_finder tests/embed/finder.c)
