/* The built-in default scene: the example apps/scenes/twisting_cylinder.json (Longva et al.
 * 2020 §6.2), embedded at configure time (lib/src/scene/sources.cmake). */
#include "scene/scene_impl.h"

#include "scene/default_scene_json.h"

const char *fcm_scene_default_json(void)
{
  return (const char *)fcm__default_scene_json;
}

fcm_status fcm_scene_create_default(fcm_ctx *ctx, fcm_scene **scene)
{
  fcm_status st = FCM_OK;
  FCM_TRY(ctx, fcm_scene_create_from_string(ctx, fcm_scene_default_json(), "<default>", scene));
cleanup:
  return st;
}
