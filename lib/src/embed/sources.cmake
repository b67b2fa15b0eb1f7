list(APPEND FCM_SOURCES lib/src/embed/cell_rules.c lib/src/embed/diagnostics.c
                        lib/src/embed/intersect.c lib/src/embed/pieces.c)
