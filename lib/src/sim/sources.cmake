list(APPEND FCM_SOURCES lib/src/sim/integrator.c lib/src/sim/state.c lib/src/sim/integrator_backend.c
     lib/src/sim/newton.c lib/src/sim/step.c lib/src/sim/linsolve.c lib/src/sim/nitsche.c
     lib/src/sim/nitsche_assemble.c lib/src/sim/rigid.c
     lib/src/sim/cut_update.c lib/src/sim/refine.c lib/src/sim/hanging.c lib/src/sim/scheme.c lib/src/sim/contact.c
     lib/src/sim/contact_obstacle.c lib/src/sim/contact_friction.c
     lib/src/sim/contact_bodies.c lib/src/sim/contact_bvh.c
     lib/src/sim/contact_bodies_solve.c lib/src/sim/contact_bodies_depth.c
     lib/src/sim/contact_bodies_friction.c)
