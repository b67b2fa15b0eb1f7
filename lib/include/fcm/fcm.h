/* fcm — finite cell method for embedded deformable solids. Umbrella header. */
#ifndef FCM_FCM_H
#define FCM_FCM_H

#include "fcm/core.h"
#include "fcm/dense.h"
#include "fcm/element.h"
#include "fcm/embed.h"
#include "fcm/fem.h"
#include "fcm/geom.h"
#include "fcm/la.h"
#include "fcm/material.h"
#include "fcm/io.h"
#include "fcm/mesh.h"
#include "fcm/mg.h"
#include "fcm/quad.h"
#include "fcm/rulegen.h"
#include "fcm/sim.h"
#include "fcm/scene.h"
#include "fcm/simulation.h"
#include "fcm/solve.h"
#include "fcm/surface.h"
#include "fcm/simplify.h"
#include "fcm/version.h"
#include "fcm/voxels.h"
#include "fcm/levelset.h"

#endif /* FCM_FCM_H */
