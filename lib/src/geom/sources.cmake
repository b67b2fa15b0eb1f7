list(APPEND FCM_SOURCES lib/src/geom/aabb.c lib/src/geom/clip.c lib/src/geom/geometry.c
                        lib/src/geom/shapes.c lib/src/geom/surface.c lib/src/geom/surface_check.c
                        lib/src/geom/gmsh_adapter.c lib/src/geom/surface_read.c
                        lib/src/geom/surface_shapes.c lib/src/geom/tetgen.c
                        lib/src/geom/voxels.c lib/src/geom/voxel_read.c
                        lib/src/geom/levelset.c lib/src/geom/refine.c)
