fcm_add_app(fcm-sim apps/fcm-sim.c apps/cli.c)
fcm_add_app(fcm-rulegen apps/fcm-rulegen.c)
fcm_add_app(fcm-quadrature apps/fcm-quadrature.c apps/fcm-quadrature-embed.c)
fcm_add_app(fcm-condition apps/fcm-condition.c apps/fcm-condition-study.c apps/fcm-condition-output.c
            apps/cli.c)
fcm_add_app(fcm-converge apps/fcm-converge.c apps/fcm-converge-study.c apps/fcm-converge-output.c)
