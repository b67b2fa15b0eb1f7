fcm_add_app(fcm-sim apps/fcm-sim.c)
