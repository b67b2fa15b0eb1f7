/* The scene the checkpoint fuzz target restores into, shared with the seed writer (a
 * checkpoint only restores into a simulation of the same scene): two Hex8 cells, no embedded
 * geometry (building cut-cell rules would dominate the run time), static, fixed on one
 * side, under gravity, 4 steps: a new simulation per accepted checkpoint stays cheap. */
#ifndef FCM_FUZZ_CKPT_SCENE_H
#define FCM_FUZZ_CKPT_SCENE_H

static const char fuzz_ckpt_scene_json[] =
    "{\"version\": 1, \"name\": \"fuzz_ckpt\","
    " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0],"
    "   \"max\": [1, 1, 1]}, \"cells\": [2, 1, 1]},"
    " \"material\": {\"model\": \"snh\", \"young\": 1e5, \"poisson\": 0.3, \"density\": 1000},"
    " \"time\": {\"static\": true, \"steps\": 4, \"dt\": 1},"
    " \"effects\": [{\"gravity\": {}},"
    "  {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, 0, 0], \"normal\": [-1, 0, "
    "0]}}}}]}";

#endif
