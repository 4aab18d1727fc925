/* The 3-d vehicle (kinematic bicycle) of Reissig, Weber, Rungger, "Feedback refinement relations
 * for the synthesis of symbolic controllers", IEEE TAC 2016, section IX-A, used by AMYTISS's
 * vehicle example. Continuous time:
 *   dx0/dt = u0 cos(alpha + x2) / cos(alpha),  dx1/dt = u0 sin(alpha + x2) / cos(alpha),
 *   dx2/dt = u0 tan(u1),                       alpha = atan(tan(u1) / 2),
 * the continuous-time vector field; the integrator (integrator.h) steps it, by default one explicit
 * Euler step of VEHICLE3D_TAU = 0.3 s (the sampling period of that example in SCOTS and pFaces).
 * Valid as C++ and as OpenCL C (double precision).
 * State: x[0], x[1] position [m], x[2] heading [rad]. Input: u[0] speed [m/s], u[1] steering
 * angle [rad]. No disturbance; noise is not part of f. */
#ifndef AMYTISS_MODEL_VEHICLE3D_H
#define AMYTISS_MODEL_VEHICLE3D_H

/* AMYTISS_MODEL_FUNCTION comes from model_function.h, which is put before this header. */

#define VEHICLE3D_TAU 0.3

AMYTISS_MODEL_FUNCTION void amytiss_rate_vehicle3d(const double* x, const double* u, const double* w, double* rate) {
  (void)w;
  const double alpha = atan(tan(u[1]) / 2.0);
  rate[0] = u[0] * cos(alpha + x[2]) / cos(alpha);
  rate[1] = u[0] * sin(alpha + x[2]) / cos(alpha);
  rate[2] = u[0] * tan(u[1]);
}

#endif
