# Background meshes: creation and adjacency, box generators, Gmsh reader (valid and
# malformed files), Jacobian validation and the convexity query.
fcm_add_test(mesh_create tests/mesh/create.c)
fcm_add_test(mesh_box tests/mesh/box.c)
fcm_add_test(mesh_box_alloc tests/mesh/box_alloc.c)
fcm_add_test(mesh_gmsh tests/mesh/gmsh.c)
fcm_add_test(mesh_gmsh_errors tests/mesh/gmsh_errors.c)
fcm_add_test(mesh_validate tests/mesh/validate.c)
fcm_add_test(mesh_view tests/mesh/view.c)
# Octree backgrounds: refinement criteria, 2:1 balance, volumes, boundary, hanging nodes.
foreach(el hex8 hex20)
  fcm_add_test(mesh_octree_${el} tests/mesh/octree.c ARGS ${el})
endforeach()
