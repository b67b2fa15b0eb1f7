list(APPEND FCM_SOURCES lib/src/mesh/mesh.c lib/src/mesh/mesh_box.c lib/src/mesh/mesh_check.c
                        lib/src/mesh/mesh_gmsh.c lib/src/mesh/mesh_octree.c)
