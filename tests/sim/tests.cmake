foreach(el hex8 tet10)
  fcm_add_test(sim_static_linear_${el} tests/sim/static_linear.c ARGS ${el})
  fcm_add_test(sim_static_snh_${el} tests/sim/static_snh.c ARGS ${el})
  fcm_add_test(sim_momentum_${el} tests/sim/momentum.c ARGS ${el})
  fcm_add_test(sim_energy_${el} tests/sim/energy.c ARGS ${el})
  fcm_add_test(sim_constraints_${el} tests/sim/constraints.c ARGS ${el})
endforeach()
fcm_add_test(sim_failure tests/sim/failure.c ARGS hex8)
foreach(el hex8 tet10)
  fcm_add_test(sim_solvers_${el} tests/sim/solvers.c ARGS ${el})
endforeach()
fcm_add_test(sim_projected_tangent tests/sim/projected_tangent.c)
foreach(el hex8 tet10)
  fcm_add_test(sim_krylov_${el} tests/sim/krylov.c ARGS ${el})
endforeach()
fcm_add_test(sim_alloc_failure tests/sim/alloc_failure.c)
# Allocation failures with a body-force field, a traction, and the energy query.
fcm_add_test(sim_alloc_effects tests/sim/alloc_effects.c)
# MINRES + Schwarz on the unprojected Newton systems of the example scenes converges
# and agrees with the direct solve: two quick scenes, one step, by default; every scene, ten
# steps, under slow (each scene's rules are built twice).
fcm_add_test(sim_minres_scenes tests/sim/minres_scenes.c
             ARGS ${PROJECT_SOURCE_DIR}/apps/scenes 1 slingshot.json spinning_body.json)
fcm_add_test(sim_minres_scenes_long tests/sim/minres_scenes.c LABELS slow
             ARGS ${PROJECT_SOURCE_DIR}/apps/scenes 10 TIMEOUT 3600)
# The preconditioner's tangent (projected, linear, exact): each converges to the
# direct solution on a hard twist of a Hex20 tube; the option is parsed and validated.
fcm_add_test(sim_minres_pc_tangent tests/sim/minres_pc_tangent.c)
# Numerically singular systems are refused by the direct path with the cause;
# stabilized systems with tiny cut cells are not.
fcm_add_test(sim_singular tests/sim/singular.c)
# Steps after the first allocate nothing through the context (direct
# CHOLMOD with one symbolic analysis, MINRES + Schwarz, CG + Jacobi, CG + block Jacobi).
foreach(solver direct minres-schwarz cg-jacobi cg-block minres-mg cg-mg mg mg-interactive)
  fcm_add_test(sim_step_alloc_${solver} tests/sim/step_alloc.c ARGS ${solver})
endforeach()
fcm_add_test(sim_step_alloc_direct_tet10 tests/sim/step_alloc.c ARGS direct tet10)
fcm_add_test(sim_step_alloc_static tests/sim/step_alloc.c ARGS minres-schwarz hex8 static)
# Cutting between steps (host calls): mass and momenta unchanged at the cut, the halves separate.
foreach(el tet4 tet10 hex8 hex20)
  fcm_add_test(sim_cut_${el} tests/sim/cut.c ARGS ${el})
endforeach()
# A cut that keeps element blocks and CHOLMOD's ordering (cut_reuse) equals a rebuild bit for bit
# (mass, load, state after steps) through a plane, a partial rectangle and a plane across both.
foreach(el tet4 tet10 hex8 hex20)
  fcm_add_test(sim_cut_update_${el} tests/sim/cut_update.c ARGS ${el})
endforeach()
# A cut builds the multigrid solver's hierarchy (and the direct solver's analysis) itself: the
# step after it sets up values only, with the bits of an integrator built from scratch.
foreach(el hex8 hex20)
  fcm_add_test(sim_cut_prepare_${el} tests/sim/cut_prepare.c ARGS ${el})
endforeach()
# The element-corotated linear model in the integrator: steps converge, a cut keeps the element
# stiffness matrices of the elements it leaves and equals a rebuild bit for bit.
foreach(el tet4 hex8 hex20)
  fcm_add_test(sim_corot_linear_${el} tests/sim/corot_linear.c ARGS ${el})
endforeach()
# A cut's integrator on the old one's storage (FCM_CUT_REUSE_STORAGE) equals one on new storage
# bit for bit (mass, load, state after steps; Hex8, corotated linear, multigrid); the giver spent.
fcm_add_test(sim_cut_storage tests/sim/cut_storage.c)
# A cut space in the pattern storage of the space before it, with the integrator's storage taken:
# the bits of a cut onto a new space; a failed cut gives the columns back before the old
# integrator assembles its mass matrix again.
fcm_add_test(sim_cut_take tests/sim/cut_take.c)
# Reactions of constraints: minus the assembled weight and its moment in equilibrium (an
# embedded beam clamped by a half-space of background nodes), change of momentum minus the
# weight in dynamics; two constraints add up.
foreach(el hex8 tet4)
  fcm_add_test(sim_reaction_${el} tests/sim/reaction.c ARGS ${el})
endforeach()
# Dirichlet conditions on the embedded boundary (Nitsche, penalty).
fcm_add_test(sim_nitsche_patch_hex8 tests/sim/nitsche.c ARGS patch hex8)
fcm_add_test(sim_nitsche_patch_tet4 tests/sim/nitsche.c ARGS patch tet4)
fcm_add_test(sim_nitsche_tangent tests/sim/nitsche.c ARGS tangent)
fcm_add_test(sim_nitsche_penalty tests/sim/nitsche.c ARGS penalty)
fcm_add_test(sim_nitsche_solvers tests/sim/nitsche.c ARGS solvers)
fcm_add_test(sim_nitsche_errors tests/sim/nitsche.c ARGS errors)
fcm_add_test(sim_nitsche_rigid tests/sim/nitsche.c ARGS rigid)
# Inverted quadrature points (J = det F <= 0) counted in the step info against an independent
# count of a prescribed fold; none for a spinning free body.
foreach(el hex8 tet10)
  fcm_add_test(sim_inversion_${el} tests/sim/inversion.c ARGS ${el})
endforeach()
# Static steps refuse bodies the constraints leave free (no constraint, one or two fixed
# nodes, partial supports, a cut half, a boundary constraint in one component, a released
# region) before any solve with every solver; held bodies and dynamic runs solve; a
# stagnating Krylov solve is the step's reason.
fcm_add_test(sim_rigid_modes tests/sim/rigid_modes.c)
# Modified Newton on a kept factorization: the same states as full Newton with far fewer
# factorizations; the contraction rule; static steps, the fixed-iteration rule and Krylov solvers
# never reuse.
foreach(el hex8 tet10)
  fcm_add_test(sim_reuse_${el} tests/sim/reuse.c ARGS ${el})
endforeach()
# Interactive steps: the fixed-iteration rule runs exactly N Newton iterations and reports the
# residual it reached; fixed multigrid cycles warm-started from the previous step beat cold
# ones against the direct solution; fixed cycles without the multigrid solver are refused.
fcm_add_test(sim_interactive tests/sim/interactive.c)
# The integrators on octree backgrounds: the static patch test across hanging nodes, momentum
# under gravity, an unrefined octree against the uniform grid.
foreach(el hex8 hex20)
  fcm_add_test(sim_octree_${el} tests/sim/octree.c ARGS ${el})
endforeach()
# Refinement during a run: mass, momentum and kinetic energy kept, the fields reproduced at the
# old nodes, the held face's new nodes held, bad input refused.
foreach(el hex8 hex20)
  fcm_add_test(sim_octree_refine_${el} tests/sim/octree_refine.c ARGS ${el})
endforeach()
# The time schemes (backward Euler, Newmark, HHT, generalized-alpha) on a linear cantilever:
# fitted temporal orders, Newmark's energy over 1000 steps, the contraction per step at
# infinite frequency against rho_inf, option errors.
fcm_add_test(sim_schemes tests/sim/schemes.c)
# Contact with rigid planes: the log barrier's force and Newton matrix against central
# differences; a start in penetration and bad options refused; a moving floor hits a ball
# and throws it at a speed in [V, 2 V]; a ball dropped on a floor
# never crosses it, comes to rest on it with the reaction m g (backward Euler), bounces
# (Newmark); every Newton iterate stays in front of the floor and the step's smallest distance
# covers its substeps; a block held in a cup of planes reaches static equilibrium (reaction =
# load).
fcm_add_test(sim_contact_gradient tests/sim/contact.c ARGS gradient)
fcm_add_test(sim_contact_errors tests/sim/contact.c ARGS errors)
fcm_add_test(sim_contact_push tests/sim/contact.c ARGS push)
fcm_add_test(sim_contact_drop_be tests/sim/contact.c ARGS drop backward_euler)
fcm_add_test(sim_contact_drop_newmark tests/sim/contact.c ARGS drop newmark)
fcm_add_test(sim_contact_iterates tests/sim/contact.c ARGS iterates)
fcm_add_test(sim_contact_static tests/sim/contact.c ARGS static)
# Spheres, boxes and closed triangle surfaces as contact obstacles: the point-triangle distance
# in each region and every kind's distance against differences, the barrier's force against
# differences, balls dropped onto and pushed by each kind, and the refusals.
fcm_add_test(sim_contact_triangle tests/sim/contact_obstacles.c ARGS triangle)
fcm_add_test(sim_contact_distance tests/sim/contact_obstacles.c ARGS distance)
fcm_add_test(sim_contact_obstacle_errors tests/sim/contact_obstacles.c ARGS errors)
foreach(kind sphere box surface)
  fcm_add_test(sim_contact_force_${kind} tests/sim/contact_obstacles.c ARGS force ${kind})
  fcm_add_test(sim_contact_drop_${kind} tests/sim/contact_obstacles.c ARGS drop ${kind})
  fcm_add_test(sim_contact_push_${kind} tests/sim/contact_obstacles.c ARGS push ${kind})
endforeach()
# Lagged, smoothed Coulomb friction: its force and Newton matrix against differences with the
# lagged quantities fixed (a moving plane, a translating and rotating box); a block on a floor
# under tilted gravity sticks with mu > tan theta and slides at g (sin theta - mu cos theta)
# with mu < tan theta.
fcm_add_test(sim_contact_friction_fd tests/sim/contact_friction.c ARGS fd)
fcm_add_test(sim_contact_friction_stick tests/sim/contact_friction.c ARGS incline 0.6)
fcm_add_test(sim_contact_friction_slide tests/sim/contact_friction.c ARGS incline 0.2)
fcm_add_test(sim_contact_friction_stick_updates tests/sim/contact_friction.c ARGS incline 0.6 3)
fcm_add_test(sim_contact_friction_slide_updates tests/sim/contact_friction.c ARGS incline 0.2 3)
# Contact between bodies and cut pieces: the barrier's force against differences, the step
# bound, a box dropped onto another, bad input and zero work without the key, and the dice
# (36 sticks landing on a floor without passing through each other or the floor).
fcm_add_test(sim_contact_bodies_fd tests/sim/contact_bodies.c ARGS fd)
fcm_add_test(sim_contact_bodies_stack tests/sim/contact_bodies.c ARGS stack)
fcm_add_test(sim_contact_bodies_errors tests/sim/contact_bodies.c ARGS errors)
fcm_add_test(sim_contact_bodies_dice tests/sim/contact_bodies.c ARGS dice
             ${PROJECT_SOURCE_DIR}/apps/scenes)
fcm_add_test(sim_contact_bodies_rest tests/sim/contact_bodies.c ARGS rest
             ${PROJECT_SOURCE_DIR}/apps/scenes)
# Self-contact of one body: a C-shaped body whose loaded arm folds onto the other (kept out
# with the option, passing through without it), the force against differences, bad input.
fcm_add_test(sim_contact_self_fd tests/sim/contact_self.c ARGS fd)
fcm_add_test(sim_contact_self_fold tests/sim/contact_self.c ARGS fold)
fcm_add_test(sim_contact_self_errors tests/sim/contact_self.c ARGS errors)
# Friction between bodies: a block pulled sideways on a plate sticks below mu g and slides with
# the acceleration a_x - mu g above; the friction force against differences.
fcm_add_test(sim_contact_bodies_friction_stick tests/sim/contact_bodies_friction.c ARGS stick)
fcm_add_test(sim_contact_bodies_friction_slide tests/sim/contact_bodies_friction.c ARGS slide)
# Static contact between bodies: the plate holds the block's vertical translation (the clamp
# carries both weights); beyond the threshold the step is refused.
fcm_add_test(sim_contact_bodies_static tests/sim/contact_bodies_friction.c ARGS static)
# A scene's cut makes its integrator and output surface on two threads: the run equals the run
# on one thread bit for bit (state after every step, output surface, counters) over three cuts.
foreach(el tet4 tet10 hex8 hex20)
  fcm_add_test(sim_cut_overlap_${el} tests/sim/cut_overlap.c ARGS ${el})
endforeach()
# The same run on one thread and on two, the BLAS with two threads of its own: the same bits
# (the cut cells' rules use one BLAS thread inside their loops whatever the run's count;
# Hex20's mass fits are large enough for a threaded BLAS product to round differently).
fcm_add_test(sim_cut_threads_hex20 tests/sim/cut_overlap.c ARGS hex20 threads)
# With the multigrid solver the cut's solver structure is made beside the integrator's values
# and the surface: the same bits, the hierarchy that of the state's active set; a cut failing
# at an allocation (in turn or side by side) leaves the run going on with its integrator.
foreach(el hex8 hex20)
  fcm_add_test(sim_cut_overlap_multigrid_${el} tests/sim/cut_overlap.c ARGS ${el} multigrid)
endforeach()
fcm_add_test(sim_cut_overlap_fail_hex8 tests/sim/cut_overlap.c ARGS hex8 fail)
# Without an output surface the values and the structure go side by side all the same.
fcm_add_test(sim_cut_overlap_nosurface_hex8 tests/sim/cut_overlap.c ARGS hex8 nosurface)
# The integrator of a cut onto a patched space takes the mass rows and load entries the cut
# leaves from the old integrator (moved within its storage, or copied) and equals one built from
# scratch bit for bit, over three cuts; a failed cut leaves the old one going on.
foreach(el tet4 tet10 hex8 hex20)
  fcm_add_test(sim_cut_rows_${el} tests/sim/cut_rows.c ARGS ${el})
endforeach()
# The corotated store over five cuts: taken while its slots last, a new store when a cut's
# elements outnumber them; the same bits as a chain that copies it at every cut.
fcm_add_test(sim_cut_corot_store tests/sim/cut_corot_store.c)
