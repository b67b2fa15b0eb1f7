/* The built-in default scene: a scaled-down twisting hollow cylinder (Longva et al. 2020
 * §6.2) that runs in seconds; apps/scenes/twisting_cylinder.json is the larger version. */
#include "scene/scene_impl.h"

/* Kept below the 4095 characters every C11 compiler must accept in one literal. */
static const char default_json[] =
    "{\n"
    "  \"name\": \"default\",\n"
    "  \"description\": \"Twisting hollow cylinder, scaled down (Longva et al. 2020, 6.2): "
    "one end pushed in by 0.5 m, the other twisted by 1.6 rad, Hex20 FCM\",\n"
    "  \"background\": {\"element\": \"hex20\", \"box\": {\"min\": [-1, -4, -1], "
    "\"max\": [1, 4, 1]}, \"cells\": [2, 8, 2]},\n"
    "  \"geometry\": {\"shape\": \"tube\", \"axis\": \"y\", \"inner_radius\": 0.5, "
    "\"outer_radius\": 0.9, \"length\": 8, \"radial_cells\": 2, \"angular_cells\": 24, "
    "\"axial_cells\": 16},\n"
    "  \"material\": {\"model\": \"snh\", \"young\": 5e6, \"poisson\": 0.48, "
    "\"density\": 1000},\n"
    "  \"quadrature\": {\"stiffness_strength\": 4, \"stabilization\": {\"mode\": \"mass\", "
    "\"alpha\": 1e-8}},\n"
    "  \"solver\": {\"method\": \"direct\", \"direct\": \"cholmod\"},\n"
    "  \"time\": {\"dt\": 0.05, \"duration\": 3},\n"
    "  \"output\": {\"directory\": \"fcm-output\", \"frame_interval\": 2},\n"
    "  \"effects\": [\n"
    "    {\"gravity\": {\"acceleration\": [0, 0, -9.81]}},\n"
    "    {\"motion\": {\"region\": {\"half_space\": {\"point\": [0, -3.99, 0], "
    "\"normal\": [0, -1, 0]}}, \"velocity\": [0, 0.25, 0], \"end\": 2}},\n"
    "    {\"motion\": {\"region\": {\"half_space\": {\"point\": [0, 3.99, 0], "
    "\"normal\": [0, 1, 0]}}, \"rotation\": {\"axis\": [0, 1, 0], \"center\": [0, 4, 0], "
    "\"speed\": 0.8}, \"end\": 2}},\n"
    "    {\"damping\": {\"stiffness\": 0.05}}\n"
    "  ]\n"
    "}\n";

const char *fcm_scene_default_json(void)
{
  return default_json;
}

fcm_status fcm_scene_create_default(fcm_ctx *ctx, fcm_scene **scene)
{
  fcm_status st = FCM_OK;
  FCM_TRY(ctx, fcm_scene_create_from_string(ctx, default_json, "<default>", scene));
cleanup:
  return st;
}
