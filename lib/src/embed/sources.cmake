list(APPEND FCM_SOURCES lib/src/embed/cell_rules.c lib/src/embed/rules_build.c
                        lib/src/embed/classify.c lib/src/embed/cut_cells.c
                        lib/src/embed/auto_policy.c lib/src/embed/distribute.c lib/src/embed/cuts.c
                        lib/src/embed/accessors.c lib/src/embed/diagnostics.c
                        lib/src/embed/intersect.c lib/src/embed/pieces.c lib/src/embed/cut_faces.c
                        lib/src/embed/surface_moments.c lib/src/embed/surface_quad.c
                        lib/src/embed/surface_inside.c lib/src/embed/surface_cells.c
                        lib/src/embed/surface_parts.c lib/src/embed/surface_faces.c
                        lib/src/embed/boxes.c
                        lib/src/embed/piece_locate.c lib/src/embed/classify_coarse.c
                        lib/src/embed/rules_write.c)
