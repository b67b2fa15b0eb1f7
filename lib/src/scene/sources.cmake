list(APPEND FCM_SOURCES lib/src/scene/json_adapter.c lib/src/scene/schema.c
                        lib/src/scene/effects.c lib/src/scene/scene.c
                        lib/src/scene/default_scene.c
                        lib/src/scene/run.c)
