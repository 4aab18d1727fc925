/* The 5-d kinematic single-track (KS) model of a BMW 320i: Althoff et al., "CommonRoad: Vehicle
 * Models", section 4 (vehicleDynamics_KS), with CommonRoad vehicle 2 (commonroad_vehicle2.h). The
 * continuous-time vector field; the integrator (integrator.h, default one Euler step of
 * BMW320I_KS_TAU) makes it a discrete-time map. CommonRoad uses this model at low speed, where the
 * single-track model with tire slip (bmw320i.h) is stiff. Valid as C++ and as OpenCL C.
 *
 * State: x[0], x[1] position of the rear axle's centre [m]; x[2] steering angle [rad];
 *        x[3] velocity [m/s]; x[4] yaw angle [rad].
 * Input: u[0] steering velocity [rad/s], u[1] longitudinal acceleration [m/s^2], saturated by
 *        CommonRoad's constraints. No disturbance; noise is not part of g.
 *   dx0/dt = x3 cos(x4), dx1/dt = x3 sin(x4), dx2/dt = Sat1(x2, u0), dx3/dt = Sat2(x3, u1),
 *   dx4/dt = x3 / l_wb tan(x2), l_wb = l_f + l_r = 2.578 m. */
#ifndef AMYTISS_MODEL_BMW320I_KS_H
#define AMYTISS_MODEL_BMW320I_KS_H

/* model_function.h and commonroad_vehicle2.h are put before this header. */

#define BMW320I_KS_TAU 0.1
#define BMW320I_KS_L_WB (VEHICLE2_L_F + VEHICLE2_L_R)

AMYTISS_MODEL_FUNCTION void amytiss_rate_bmw320i_ks(const double* x, const double* u, const double* w, double* rate) {
  (void)w;
  rate[0] = x[3] * cos(x[4]);
  rate[1] = x[3] * sin(x[4]);
  rate[2] = amytiss_vehicle2_sat_steering(x[2], u[0]);
  rate[3] = amytiss_vehicle2_sat_acceleration(x[3], u[1]);
  rate[4] = x[3] / BMW320I_KS_L_WB * tan(x[2]);
}

#endif
