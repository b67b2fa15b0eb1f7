foreach(el tet4 tet10 hex8 hex20)
  fcm_add_test(fem_patch_${el} tests/fem/patch.c ARGS ${el} LABELS conformance)
  fcm_add_test(fem_assembly_${el} tests/fem/assembly.c ARGS ${el} LABELS conformance)
  fcm_add_test(fem_hyperelastic_${el} tests/fem/hyperelastic.c ARGS ${el} LABELS conformance)
  fcm_add_test(fem_corot_linear_${el} tests/fem/corot_linear.c ARGS ${el} LABELS conformance)
endforeach()
foreach(el tet10 hex20)
  fcm_add_test(fem_cantilever_${el} tests/fem/cantilever.c ARGS ${el})
endforeach()
# with simplified cut-cell rules; Hex20's (M = 165 for the mass) takes long: label slow
foreach(el tet4 tet10 hex8)
  fcm_add_test(fem_embedded_${el} tests/fem/embedded.c ARGS ${el} simplify LABELS conformance)
endforeach()
fcm_add_test(fem_embedded_hex20 tests/fem/embedded.c ARGS hex20 LABELS conformance)
fcm_add_test(fem_embedded_hex20_simplified tests/fem/embedded.c ARGS hex20 simplify LABELS slow)
foreach(el tet4 tet10 hex8 hex20)
  fcm_add_test(fem_locate_${el} tests/fem/locate.c ARGS ${el} LABELS conformance)
endforeach()
fcm_add_test(fem_locate_crowded tests/fem/locate_crowded.c)
# Allocation failures in every allocating fem entry point: FCM_ERR_ALLOC, NULL outputs, no leak.
fcm_add_test(fem_alloc_failure tests/fem/alloc_failure.c)
foreach(el tet4 tet10 hex8 hex20)
  fcm_add_test(fem_workspace_${el} tests/fem/workspace.c ARGS ${el})
endforeach()
foreach(el tet4 tet10 hex8 hex20)
  fcm_add_test(fem_space_eval_${el} tests/fem/space_eval.c ARGS ${el})
endforeach()
# Generalized enrichment after cuts: rigid modes of the separated bodies, mass, gravity.
foreach(el tet4 tet10 hex8 hex20)
  fcm_add_test(fem_xfem_${el} tests/fem/xfem.c ARGS ${el})
endforeach()
fcm_add_test(fem_xfem_dice tests/fem/xfem.c ARGS dice)
fcm_add_test(fem_xfem_constraint tests/fem/xfem.c ARGS constraint)
# Output fields: stress, von Mises, energy density of affine fields (analytic, cut cells
# included), node and surface fields, VTU files at reference positions, cut faces.
foreach(el tet4 tet10 hex8 hex20)
  fcm_add_test(fem_fields_${el} tests/fem/fields.c ARGS ${el})
endforeach()
# Assembly over a local space's rows (the distributed integrator's partial assembly): two
# halves' rows summed equal the full space's matrices, vectors and energy.
fcm_add_test(fem_local_assembly_hex8 tests/fem/local_assembly.c ARGS hex8 6 LABELS unit)
fcm_add_test(fem_local_assembly_hex8_cut tests/fem/local_assembly.c ARGS hex8 6 cut LABELS unit)
fcm_add_test(fem_local_assembly_hex20 tests/fem/local_assembly.c ARGS hex20 6 LABELS unit)
# State transfer across sequences of cuts (random, near cell planes, crossing knives, and
# fixed cases): piece volumes, the field at every point and mass and momenta carried over by
# every cut, with and without the constraint of tiny copies. The long version: 20 sequences
# of 2, 5 and 10 cuts per kind of plane on two bodies (cuts whose pieces lose volume or that
# are refused end their sequence and are counted: `fem_transfer <el> 20 1 1` lists them).
foreach(el tet4 tet10 hex8 hex20)
  fcm_add_test(fem_transfer_${el} tests/fem/transfer.c ARGS ${el})
  fcm_add_test(fem_transfer_long_${el} tests/fem/transfer.c ARGS ${el} 20 1 LABELS slow
               TIMEOUT 3600)
endforeach()
fcm_add_test(fem_threads tests/fem/threads.c)
# Assembly's coloured element blocks (a valid parallel order, results bitwise the same for 1-3
# threads) and the blocked element kernels against the per-point formulas.
foreach(el tet10 hex8 hex20)
  fcm_add_test(fem_block_order_${el} tests/fem/block_order.c ARGS ${el})
endforeach()
# fcm_space_momentum() from the kept element mass blocks equals the sums over the mass-rule
# points (cut cells, stabilization points, XFEM pieces) to 1e-12.
foreach(el tet4 tet10 hex8 hex20)
  fcm_add_test(fem_momentum_${el} tests/fem/momentum.c ARGS ${el})
endforeach()
# The embedded surface of a ball cut once, then twice: with every body moved rigidly, each
# triangle (boundary, split part, cut face) follows one body (edges keep their length), the
# parts cover the boundary's area, each lies on one side of every cut plane. In the sanitizer
# build the hexahedra's runs take about twice the simplices' (near the 600 s timeout): there they
# are labelled slow, outside the default run, which keeps the simplices'.
foreach(el tet4 tet10 hex8 hex20)
  set(labels unit)
  if(FCM_SANITIZE AND el MATCHES "^hex")
    set(labels unit slow)
  endif()
  fcm_add_test(fem_cut_surface_${el} tests/fem/cut_surface.c ARGS ${el} TIMEOUT 600 LABELS ${labels})
endforeach()
# A cut space patched from the space before the cut (graph rows, offsets) equals one built anew,
# every array bit for bit, over three cuts, with and without constrained tiny copies; no piece
# counts as copied from rules the cut's rules do not extend, though their pieces be alike.
foreach(el tet4 tet10 hex8 hex20)
  fcm_add_test(fem_cut_space_${el} tests/fem/cut_space.c ARGS ${el})
endforeach()
# Assembly's blocks of cells coloured by shared mesh nodes: no two blocks of a colour share a
# copy on an octree, a local space and with constrained copies; a cut keeps blocks and colours.
fcm_add_test(fem_block_colors tests/fem/block_colors.c)
# Octree backgrounds: continuity through the hanging-node constraints and patch tests across
# hanging nodes (affine fields; quadratic ones for Hex20).
foreach(el hex8 hex20)
  fcm_add_test(fem_octree_patch_${el} tests/fem/octree_patch.c ARGS ${el} LABELS conformance)
endforeach()
foreach(el hex8 hex20)
  fcm_add_test(fem_octree_embedded_${el} tests/fem/octree_embedded.c ARGS ${el} LABELS conformance)
endforeach()
# Cuts (XFEM) on octrees: copies of hanging nodes per material component, the patch test on
# each side of a through-cut, the sides independent, the cut equal to the uniform grid's.
foreach(el hex8 hex20)
  fcm_add_test(fem_octree_cut_${el} tests/fem/octree_cut.c ARGS ${el} LABELS conformance)
endforeach()
# A cut leaving sliver pieces next to hanging nodes, their tiny copies constrained: the
# hanging-node matrix built from the DOFs the pieces read, the patch test, a dynamic run.
foreach(el hex8 hex20)
  fcm_add_test(fem_octree_sliver_${el} tests/fem/octree_sliver.c ARGS ${el} LABELS conformance)
endforeach()
# Allocation failures in the octree's entry points: mesh, refinement, constraints, PtAP.
fcm_add_test(fem_octree_alloc tests/fem/octree_alloc.c)
# Fields carried onto a refined octree: momentum and kinetic energy kept, hanging values.
foreach(el hex8 hex20)
  fcm_add_test(fem_octree_transfer_${el} tests/fem/octree_transfer.c ARGS ${el})
endforeach()
# The crack-tip field of the cut-tip study (tests/fem/cuttip.h): an exact solution with
# traction-free crack faces, and convergence toward the front, uniform against an octree.
fcm_add_test(fem_octree_cuttip tests/fem/octree_cuttip.c)
