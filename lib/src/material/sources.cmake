list(APPEND FCM_SOURCES lib/src/material/material.c lib/src/material/material_svd.c)
