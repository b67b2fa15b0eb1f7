fcm_add_app(fcm-sim apps/fcm-sim.c)
fcm_add_app(fcm-rulegen apps/fcm-rulegen.c)
fcm_add_app(fcm-quadrature apps/fcm-quadrature.c apps/fcm-quadrature-embed.c)
fcm_add_app(fcm-condition apps/fcm-condition.c)
