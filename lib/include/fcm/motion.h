/* fcm — prescribed motions of node sets (translation and rotation in time, held or released at
 * their end) and the kind of time integration: what a solver of the elasticity problem needs
 * to know of the Dirichlet data and of the time stepping, below the integrators that use them
 * (fcm/sim.h includes this header). */
#ifndef FCM_MOTION_H
#define FCM_MOTION_H

#include "fcm/core.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Integrator kinds. */
typedef enum fcm_integrator_kind {
  FCM_INTEGRATOR_STATIC = 0, /**< equilibrium Psi'(u) = f_ext, load steps, no inertia;
                                  the constraints must hold every body's rigid-body
                                  modes (checked by fcm_integrator_step()) */
  /** Dynamics (inertia): the integrator's options choose the time scheme
   * (fcm_integrator_options.scheme in fcm/sim.h; backward Euler by default) */
  FCM_INTEGRATOR_BACKWARD_EULER = 1,
  FCM_INTEGRATOR_DYNAMIC = 1 /**< the same kind, named for the schemes other than backward Euler */
} fcm_integrator_kind;

/** Prescribed motion of a node set: with tau = clamp(t - start, 0, end - start), a node with
 * reference position X is at x(t) = c + R(axis, angular_speed tau) (X - c) + velocity tau
 * (R: right-handed rotation about the unit axis through the centre c), i.e.
 * u = x(t) - X. After `end` the nodes are held, or free when `release` is set. Only the
 * components with components[i] != 0 are constrained. fcm_motion_default(): fixed (u = 0). */
typedef struct fcm_motion {
  double velocity[3];   /**< translation velocity (default 0) */
  double center[3];     /**< a point of the rotation axis (default 0) */
  double axis[3];       /**< rotation axis, normalized by the integrator (default (0, 0, 1)) */
  double angular_speed; /**< rad/s, sign by the right-hand rule (default 0) */
  double start;         /**< motion starts (default 0) */
  double end;           /**< motion stops, >= start (default HUGE_VAL) */
  int release;          /**< 1: unconstrained after end (default 0: held) */
  int components[3];    /**< constrained components (default all 1) */
} fcm_motion;

/** A fixed motion: all components held at the reference position. */
FCM_API fcm_motion fcm_motion_default(void);

/** Prescribed displacement u (3) and velocity v (3, may be NULL) of the reference point X
 * under `motion` at time t (any axis length; a zero axis means no rotation). Pure. */
FCM_API void fcm_motion_eval(const fcm_motion *motion, const double X[3], double t, double u[3],
                             double v[3]);

/** Whether `motion` constrains its nodes at time t: 1 unless released and t > end. Pure. */
FCM_API int fcm_motion_active(const fcm_motion *motion, double t);

#ifdef __cplusplus
}
#endif
#endif /* FCM_MOTION_H */
