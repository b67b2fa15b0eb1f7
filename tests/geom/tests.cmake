# Embedded geometry: convex clipping, AABB tree, procedural shapes (volumes, convergence,
# closed outward boundaries), TetGen and Gmsh readers, errors and allocation failures.
fcm_add_test(geom_clip tests/geom/clip.c)
fcm_add_test(geom_aabb tests/geom/aabb.c)
fcm_add_test(geom_shapes tests/geom/shapes.c)
fcm_add_test(geom_readers tests/geom/readers.c)
fcm_add_test(geom_errors tests/geom/errors.c)
fcm_add_test(geom_reader_limits tests/geom/reader_limits.c)
# Coordinates beyond +-1e100 refused by every reader and array constructor, naming the file,
# the vertex (in the format's numbering) and the value; finite results at the limit.
fcm_add_test(geom_coord_range tests/geom/coord_range.c)
# Allocation failures: geometry from arrays and Gmsh files, AABB tree build and query.
fcm_add_test(geom_alloc_failure tests/geom/alloc_failure.c)
fcm_add_test(geom_boundary_cells tests/geom/boundary_cells.c)
# Triangle surfaces: the unit cube in OBJ, OFF, STL (ASCII, binary) and PLY (ascii, binary)
# round trips; malformed files fail naming file and line or byte offset.
fcm_add_test(geom_surface tests/geom/surface.c)
# Voxel images (NRRD, MetaImage): exact volumes, box merging, round trips, header errors.
fcm_add_test(geom_voxels tests/geom/voxels.c)
# Level-set bodies: O(h^2) sphere volume error, CSG volumes, implicit-tree errors.
fcm_add_test(geom_level_set tests/geom/level_set.c)
# The example image apps/scenes/porous_block.nrrd is what its generator writes.
fcm_add_test(geom_porous_block_image apps/scenes/porous_block.c
             ARGS --check ${PROJECT_SOURCE_DIR}/apps/scenes/porous_block.nrrd)
# Allocation failures of the voxel-image readers, voxel merging and level-set marching.
fcm_add_test(geom_voxel_alloc_failure tests/geom/voxel_alloc.c)
# Surface checks (boundary, non-manifold and inconsistent edges, inward orientation,
# degenerate triangles, self-intersections), hole filling, and tetrahedralization through
# Gmsh: the tets' volume equals the enclosed volume to 1e-12 (cube, icosphere, filled
# open cube and holed sphere); without Gmsh the refusal message.
fcm_add_test(geom_surface_mesh tests/geom/surface_mesh.c)
set_tests_properties(geom_surface_mesh PROPERTIES ENVIRONMENT "OMP_NUM_THREADS=3")
# Allocation failures in the surface checks, reorientation, hole filling and meshing.
fcm_add_test(geom_surface_alloc tests/geom/surface_alloc.c)
# Octree refinement criteria along triangle surfaces (cut surfaces, an embedded boundary).
fcm_add_test(geom_refine tests/geom/refine.c)
