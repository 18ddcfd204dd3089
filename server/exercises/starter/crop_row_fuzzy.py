"""Keep the crop rover 0.4 m from the crop row on its LEFT with a fuzzy controller.

001_8d7ab1b8a58c0603.txt sections 2, 2.2 and 2.3.

1. Lateral distance (section 2, Figures 5-7). `scan` is a sensor_msgs/LaserScan of 429 beams;
   beam i has the LiDAR angle a = angle_min + i * angle_increment. Angle 0 points to the robot's
   REAR, the left side is (0, pi), the right side (-pi, 0): the beam's direction in the robot
   frame is pi - a. A beam with no return reads 0.0. Average the lateral part (r sin a) of the
   valid beams between two thresholds around a = pi/2 (the robot's left) to get l_x, then
   l = l_x cos|e_psi| with e_psi = psi_d - psi (`psi` is the IMU yaw [rad]; psi_d the row's
   heading, e.g. the yaw at the start). Plants stand 0.2 m apart: some beams pass between them.
2. Fuzzy controller (section 2.2), with skfuzzy (`import skfuzzy as fuzz`, `from skfuzzy import
   control as ctrl`): input l over 0..0.8 m with sets LLL, LL, L, C (peak at 0.4 m), R, RR, RRR;
   output u over -100..100 with sets TRR, TR, Z, TL, TLL; the rules LLL->TRR, LL->TR, L->TR,
   C->Z, R->TL, RR->TL, RRR->TLL; centroid defuzzification. Choose the membership functions so
   that, as published, l = 0.15 m gives u = 72.87, 0.2 -> 56.37, 0.35 -> 36.71, 0.4 -> about 0,
   0.5 -> -33.63, 0.6 -> -54.79, 0.7 -> -82.82 and 0.8 -> -83.24. Build the controller once,
   not in every step.
3. Row ends (section 2.3): when the number of beams reflected in your window drops, the row is
   over; turn into the next lane and follow its row.

Return {"u": value}: the control word -100..100; negative steers LEFT, positive RIGHT. The rover
cruises at 0.15 m/s and turns at -u / 100 * 1.2 rad/s.
"""

import math

RATE_HZ = 10  # [Hz]
SUBSCRIBE = ["scan", "psi"]

WINDOW_LOW_RAD = math.pi / 2 - 0.3  # [rad] TODO: choose the window's thresholds
WINDOW_HIGH_RAD = math.pi / 2 + 0.3  # [rad]

psi_d = None  # [rad] the row's heading, set from the first yaw reading


def lateral_distance(ranges, angle_min, angle_increment, psi, psi_d):
    """l [m] to the left row, or None if no beam of the window returned."""
    # TODO: select the beams between WINDOW_LOW_RAD and WINDOW_HIGH_RAD with a return,
    # average r * sin(a), multiply by cos(abs(psi_d - psi)).
    return None


def control_action(l_m):
    """The fuzzy control word u for a lateral distance l_m [m]."""
    # TODO: build the skfuzzy ControlSystem (once) and compute u for l_m.
    return 0.0


def step(obs):
    global psi_d
    if obs.scan is None or obs.psi is None:
        return {"u": 0.0}
    if psi_d is None:
        psi_d = obs.psi.data
    scan = obs.scan
    l_m = lateral_distance(scan.ranges, scan.angle_min, scan.angle_increment, obs.psi.data, psi_d)
    if l_m is None:
        # TODO: a gap in the row, or the row's end (section 2.3): turn into the next path.
        # Until then, stop here rather than drive off the field.
        return {"cmd_vel": (0.0, 0.0)}
    return {"u": control_action(l_m)}
