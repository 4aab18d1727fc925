/* CommonRoad vehicle 2 (BMW 320i; Althoff et al., "CommonRoad: Vehicle Models", parameters_vehicle2):
 * body, input limits and CommonRoad's input constraints, shared by the models bmw320i and
 * bmw320i_ks. Valid as C++ and as OpenCL C (double precision).
 *   steering angle [-1.066, 1.066] rad, steering velocity [-0.4, 0.4] rad/s,
 *   velocity [-13.6, 50.8] m/s, switching velocity 7.319 m/s, |acceleration| <= 11.5 m/s^2,
 *   body 4.508 m x 1.610 m, front axle 1.156 m and rear axle 1.422 m from the centre of gravity. */
#ifndef AMYTISS_MODEL_COMMONROAD_VEHICLE2_H
#define AMYTISS_MODEL_COMMONROAD_VEHICLE2_H

/* AMYTISS_MODEL_FUNCTION comes from model_function.h, which is put before this header. */

#define VEHICLE2_STEERING_MIN (-1.066)
#define VEHICLE2_STEERING_MAX 1.066
#define VEHICLE2_STEERING_V_MIN (-0.4)
#define VEHICLE2_STEERING_V_MAX 0.4
#define VEHICLE2_V_MIN (-13.6)
#define VEHICLE2_V_MAX 50.8
#define VEHICLE2_V_SWITCH 7.319
#define VEHICLE2_A_MAX 11.5
#define VEHICLE2_L_F 1.156
#define VEHICLE2_L_R 1.422

/* Sat1: CommonRoad steeringConstraints. */
AMYTISS_MODEL_FUNCTION double amytiss_vehicle2_sat_steering(double steering_angle, double steering_velocity) {
  if ((steering_angle <= VEHICLE2_STEERING_MIN && steering_velocity <= 0.0) ||
      (steering_angle >= VEHICLE2_STEERING_MAX && steering_velocity >= 0.0))
    return 0.0;
  if (steering_velocity <= VEHICLE2_STEERING_V_MIN) return VEHICLE2_STEERING_V_MIN;
  if (steering_velocity >= VEHICLE2_STEERING_V_MAX) return VEHICLE2_STEERING_V_MAX;
  return steering_velocity;
}

/* Sat2: CommonRoad accelerationConstraints. */
AMYTISS_MODEL_FUNCTION double amytiss_vehicle2_sat_acceleration(double velocity, double acceleration) {
  double positive_limit = VEHICLE2_A_MAX;
  if (velocity > VEHICLE2_V_SWITCH) positive_limit = VEHICLE2_A_MAX * VEHICLE2_V_SWITCH / velocity;
  if ((velocity <= VEHICLE2_V_MIN && acceleration <= 0.0) || (velocity >= VEHICLE2_V_MAX && acceleration >= 0.0))
    return 0.0;
  if (acceleration <= -VEHICLE2_A_MAX) return -VEHICLE2_A_MAX;
  if (acceleration >= positive_limit) return positive_limit;
  return acceleration;
}

#endif
