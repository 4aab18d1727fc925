/* The 7-d single-track (ST) model of a BMW 320i with tire slip, AMYTISS (CAV 2020) section 7,
 * from Althoff et al., "CommonRoad: Vehicle Models", section 5.1: the continuous-time vector field;
 * the integrator (integrator.h) steps it, by default one explicit Euler step of BMW320I_TAU = 0.1 s
 * (the paper's). Valid as C++ and as OpenCL C (double precision); noise is not part of g.
 *
 * State (the paper's x1..x7 are x[0]..x[6]):
 *   x[0], x[1]  position [m]          x[2]  steering angle [rad]     x[3]  heading velocity [m/s]
 *   x[4]        yaw angle [rad]       x[5]  yaw rate [rad/s]         x[6]  slip angle at CoG [rad]
 * Input: u[0] steering velocity [rad/s], u[1] longitudinal acceleration [m/s^2]. No disturbance.
 *
 * Below |x[3]| < 0.1 m/s the kinematic branch (a_i of the paper) is used, above it the dynamic
 * one (b_i). Inputs pass through CommonRoad's steeringConstraints / accelerationConstraints
 * (Sat1, Sat2) with the limits of CommonRoad vehicle 2 (commonroad_vehicle2.h, BMW 320i).
 * The paper's vehicle parameters are used for the dynamics (l_wb 2.5789, m 1093.3, mu 1.0489,
 * l_f 1.156, l_r 1.422, h_cg 0.6137, I_z 1791.6, C_Sf = C_Sr = 20.89, g = 9.81).
 * The saturated inputs are used everywhere, as in CommonRoad. The slip-angle term of b7 follows
 * CommonRoad: -(C_Sr(g l_f + u2 h) + C_Sf(g l_r - u2 h)) x7; the paper prints it with a plus sign,
 * which makes the slip angle unstable and disagrees with the cited source. */
#ifndef AMYTISS_MODEL_BMW320I_H
#define AMYTISS_MODEL_BMW320I_H

/* model_function.h and commonroad_vehicle2.h are put before this header. */

#define BMW320I_TAU 0.1
#define BMW320I_KINEMATIC_SPEED 0.1
#define BMW320I_L_WB 2.5789
#define BMW320I_MASS 1093.3
#define BMW320I_MU 1.0489
#define BMW320I_L_F 1.156
#define BMW320I_L_R 1.422
#define BMW320I_H_CG 0.6137
#define BMW320I_I_Z 1791.6
#define BMW320I_C_SF 20.89
#define BMW320I_C_SR 20.89
#define BMW320I_G 9.81

AMYTISS_MODEL_FUNCTION void amytiss_rate_bmw320i(const double* x, const double* u, const double* w, double* rate) {
  (void)w;
  const double steering_velocity = amytiss_vehicle2_sat_steering(x[2], u[0]);
  const double acceleration = amytiss_vehicle2_sat_acceleration(x[3], u[1]);
  rate[2] = steering_velocity;
  rate[3] = acceleration;
  if (fabs(x[3]) < BMW320I_KINEMATIC_SPEED) {
    rate[0] = x[3] * cos(x[4]);
    rate[1] = x[3] * sin(x[4]);
    rate[4] = x[3] / BMW320I_L_WB * tan(x[2]);
    rate[5] = acceleration / BMW320I_L_WB * tan(x[2]) +
              x[3] / (BMW320I_L_WB * cos(x[2]) * cos(x[2])) * steering_velocity;
    rate[6] = 0.0;
  } else {
    const double front_load = BMW320I_G * BMW320I_L_R - acceleration * BMW320I_H_CG;
    const double rear_load = BMW320I_G * BMW320I_L_F + acceleration * BMW320I_H_CG;
    const double axle_sum = BMW320I_L_R + BMW320I_L_F;
    const double front = BMW320I_C_SF * front_load;
    const double rear = BMW320I_C_SR * rear_load;
    rate[0] = x[3] * cos(x[4] + x[6]);
    rate[1] = x[3] * sin(x[4] + x[6]);
    rate[4] = x[5];
    rate[5] = BMW320I_MU * BMW320I_MASS / (BMW320I_I_Z * axle_sum) *
              (BMW320I_L_F * front * x[2] + (BMW320I_L_R * rear - BMW320I_L_F * front) * x[6] -
               (BMW320I_L_F * BMW320I_L_F * front + BMW320I_L_R * BMW320I_L_R * rear) * x[5] / x[3]);
    rate[6] = BMW320I_MU / (x[3] * axle_sum) *
                  (front * x[2] - (rear + front) * x[6] +
                   (BMW320I_L_R * rear - BMW320I_L_F * front) * x[5] / x[3]) -
              x[5];
  }
}

#endif
