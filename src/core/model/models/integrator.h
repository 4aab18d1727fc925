/* One time step of length tau of a continuous-time model dx/dt = g(x, u, w), by `substeps` equal
 * sub-steps of explicit Euler or classical Runge-Kutta 4 (docs/configuration.md, `integrator`).
 * Valid as C++ and as OpenCL C (double precision): the C++ evaluation and the generated OpenCL
 * program run this same function.
 *
 * Defined before inclusion:
 *   AMYTISS_INTEGRATOR_CAPACITY       length of the stage arrays, >= the state dimension n
 *   AMYTISS_VECTOR_FIELD(x, u, w, r)  writes g(x, u, w) to r[0..n-1]
 *   AMYTISS_VECTOR_FIELD_CONTEXT      leading parameter declarations that the call needs, each
 *                                     followed by a comma (empty in OpenCL C)
 * One Euler sub-step of the whole length is post = x + tau*g(x, u, w), the built-in models' default. */
#ifndef AMYTISS_INTEGRATOR_H
#define AMYTISS_INTEGRATOR_H

/* AMYTISS_MODEL_FUNCTION comes from model_function.h, which is put before this header. */

#define AMYTISS_INTEGRATOR_EULER 0
#define AMYTISS_INTEGRATOR_RK4 1

AMYTISS_MODEL_FUNCTION void amytiss_integrate(AMYTISS_VECTOR_FIELD_CONTEXT const double* x, const double* u,
                                              const double* w, int n, double tau, int method, int substeps,
                                              double* post) {
  const double h = tau / substeps;
  double state[AMYTISS_INTEGRATOR_CAPACITY], stage[AMYTISS_INTEGRATOR_CAPACITY];
  double k1[AMYTISS_INTEGRATOR_CAPACITY], k2[AMYTISS_INTEGRATOR_CAPACITY];
  double k3[AMYTISS_INTEGRATOR_CAPACITY], k4[AMYTISS_INTEGRATOR_CAPACITY];
  for (int i = 0; i < n; ++i) state[i] = x[i];
  for (int s = 0; s < substeps; ++s) {
    AMYTISS_VECTOR_FIELD(state, u, w, k1);
    if (method == AMYTISS_INTEGRATOR_EULER) {
      for (int i = 0; i < n; ++i) state[i] = state[i] + h * k1[i];
      continue;
    }
    for (int i = 0; i < n; ++i) stage[i] = state[i] + 0.5 * h * k1[i];
    AMYTISS_VECTOR_FIELD(stage, u, w, k2);
    for (int i = 0; i < n; ++i) stage[i] = state[i] + 0.5 * h * k2[i];
    AMYTISS_VECTOR_FIELD(stage, u, w, k3);
    for (int i = 0; i < n; ++i) stage[i] = state[i] + h * k3[i];
    AMYTISS_VECTOR_FIELD(stage, u, w, k4);
    for (int i = 0; i < n; ++i) state[i] = state[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
  }
  for (int i = 0; i < n; ++i) post[i] = state[i];
}

#endif
