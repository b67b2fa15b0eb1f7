fcm_add_app(fcm-sim apps/fcm-sim.c)
fcm_add_app(fcm-rulegen apps/fcm-rulegen.c)
fcm_add_app(fcm-quadrature apps/fcm-quadrature.c apps/fcm-quadrature-embed.c)
fcm_add_app(fcm-condition apps/fcm-condition.c)
fcm_add_app(fcm-converge apps/fcm-converge.c apps/fcm-converge-study.c apps/fcm-converge-output.c)
# Every program waits passively in OpenMP unless the user says otherwise (apps/app_env.h).
foreach(app fcm-sim fcm-rulegen fcm-quadrature fcm-condition fcm-converge)
  target_sources(${app} PRIVATE apps/app_env.c)
endforeach()
