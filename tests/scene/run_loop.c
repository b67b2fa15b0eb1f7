/* fcm_simulation_run(): the loop takes the same steps as fcm_simulation_step() called by hand
 * (the same state, bit for bit), calls the monitor once per step with the step's event, ends
 * with the monitor's status when it returns one (the steps taken so far kept), continues a
 * run stepped by hand from where it stands, does nothing on a finished run and refuses NULL. */
#include "scene_util.h"

/* a free body spinning in one cell (quick) */
static const char spin_json[] =
    "{\"version\": 1, \"name\": \"run_spin\","
    " \"background\": {\"element\": \"hex20\", \"box\": {\"min\": [-1, -1, -1],"
    "   \"max\": [1, 1, 1]}, \"cells\": [1, 1, 1]},"
    " \"geometry\": {\"shape\": \"hemisphere\", \"center\": [0, -0.4, 0], \"radius\": 0.9,"
    "   \"resolution\": 2},"
    " \"material\": {\"model\": \"snh\", \"young\": 1e6, \"poisson\": 0.3, \"density\": 1000},"
    " \"time\": {\"dt\": 0.01, \"steps\": 5},"
    " \"effects\": [{\"initial_velocity\": {\"angular_velocity\": [0, 0, 3]}}]}";

typedef struct monitor_state {
  long long calls, first, num_steps, last_step;
  int bad;           /* an event that does not match the simulation */
  long long stop_at; /* > 0: return FCM_ERR_IO after this step */
  double last_time;
} monitor_state;

static fcm_status monitor(void *user, fcm_simulation *sim, const fcm_simulation_step_event *ev)
{
  monitor_state *m = user;
  m->calls++;
  if (ev->step != fcm_simulation_step_count(sim) || ev->first != m->first ||
      ev->num_steps != fcm_simulation_num_steps(sim) || ev->step != m->last_step + 1 || !ev->info ||
      ev->info->reason != FCM_STEP_CONVERGED || !(ev->wall >= 0.0) ||
      ev->info->time != fcm_integrator_time(fcm_simulation_integrator(sim)))
    m->bad = 1;
  m->last_step = ev->step;
  m->last_time = ev->info ? ev->info->time : -1.0;
  return m->stop_at > 0 && ev->step == m->stop_at ? FCM_ERR_IO : FCM_OK;
}

static fcm_simulation *create(fcm_ctx *ctx, const fcm_scene *scene)
{
  fcm_simulation *sim = NULL;
  TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
  return sim;
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  fcm_scene *scene = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, spin_json, "run_spin", &scene));

  /* by hand */
  fcm_simulation *a = create(ctx, scene);
  while (!fcm_simulation_done(a))
    TEST_OK(ctx, fcm_simulation_step(a, NULL));
  const fcm_index n = fcm_integrator_num_dofs(fcm_simulation_integrator(a));

  /* the loop, with a monitor */
  fcm_simulation *b = create(ctx, scene);
  monitor_state m = {0, 0, 5, 0, 0, 0, 0.0};
  TEST_OK(ctx, fcm_simulation_run(b, monitor, &m));
  TEST_TRUE(m.calls == 5 && !m.bad && m.last_step == 5);
  TEST_TRUE(fcm_simulation_done(b) && fcm_simulation_step_count(b) == 5);
  TEST_TRUE(n == fcm_integrator_num_dofs(fcm_simulation_integrator(b)));
  TEST_TRUE(memcmp(fcm_integrator_displacement(fcm_simulation_integrator(a)),
                   fcm_integrator_displacement(fcm_simulation_integrator(b)),
                   sizeof(double) * (size_t)n) == 0);
  TEST_TRUE(memcmp(fcm_integrator_velocity(fcm_simulation_integrator(a)),
                   fcm_integrator_velocity(fcm_simulation_integrator(b)),
                   sizeof(double) * (size_t)n) == 0);
  TEST_TRUE(m.last_time == fcm_integrator_time(fcm_simulation_integrator(a)));

  /* a finished run: no step, no call */
  m.calls = 0;
  TEST_OK(ctx, fcm_simulation_run(b, monitor, &m));
  TEST_TRUE(m.calls == 0 && fcm_simulation_step_count(b) == 5);
  fcm_simulation_destroy(&b);

  /* the monitor stops the run after step 2; the loop continues a run from where it stands
   * (two steps by hand, then the loop without a monitor, then the rest) */
  fcm_simulation *c = create(ctx, scene);
  monitor_state s = {0, 0, 5, 0, 0, 2, 0.0};
  TEST_TRUE(fcm_simulation_run(c, monitor, &s) == FCM_ERR_IO);
  TEST_TRUE(s.calls == 2 && !s.bad && fcm_simulation_step_count(c) == 2);
  TEST_OK(ctx, fcm_simulation_step(c, NULL));
  monitor_state r = {0, 3, 5, 3, 0, 0, 0.0};
  TEST_OK(ctx, fcm_simulation_run(c, monitor, &r));
  TEST_TRUE(r.calls == 2 && !r.bad && fcm_simulation_done(c));
  TEST_TRUE(memcmp(fcm_integrator_displacement(fcm_simulation_integrator(a)),
                   fcm_integrator_displacement(fcm_simulation_integrator(c)),
                   sizeof(double) * (size_t)n) == 0);
  fcm_simulation_destroy(&c);

  /* without a monitor */
  fcm_simulation *d = create(ctx, scene);
  TEST_OK(ctx, fcm_simulation_run(d, NULL, NULL));
  TEST_TRUE(fcm_simulation_step_count(d) == 5);
  fcm_simulation_destroy(&d);

  TEST_TRUE(fcm_simulation_run(NULL, monitor, &m) == FCM_ERR_ARG);

  fcm_simulation_destroy(&a);
  fcm_scene_destroy(&scene);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
