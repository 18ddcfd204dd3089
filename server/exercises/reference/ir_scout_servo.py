"""Servo node of the IR scout's obstacle avoidance (002_3fcfeb7b4c14107a.txt section II-E,
Fig. 3 and Fig. 6; node `servo` of the ROS graph in Fig. 8). Reference solution of the
`ir_scout_avoidance` exercise (not shown to students).

The paper's flow chart (Fig. 3): while driving, point the IR ranger 90 -> 45 -> 90 -> 135
degrees over and over and read `distance_detect` at each angle. When a reading is under 15 cm,
publish `dist_detect` (the dc_motor node stops the robot), look right (0 degrees) and left
(180 degrees), and publish the two distances on `dist_detect_right` and `dist_detect_left` for
the compare_distance node. Then look ahead again and wait until the dc_motor node says on
`forward` that the robot drives again (Fig. 8), and resume the sweep.

Topics: `distance_detect` (std_msgs/Float32, cm) and `forward` (std_msgs/String, "move") in;
`servo_angle` (std_msgs/Int16, degrees, to the robot), `dist_detect` (std_msgs/Int16, the
distance that stopped the robot [cm]), `dist_detect_right` and `dist_detect_left`
(std_msgs/Int16, cm, the type section II-E gives) out.

Assumptions (not in the paper):
- A hobby servo reports nothing back, so the node waits for it by time: the travel at
  SERVO_SLEW_DEG_S (an SG90 does 60 degrees in 0.12 s: a 90 degree swing takes ~0.2 s), then
  trusts only a reading that arrives one sensor period (40 ms at 25 Hz) after that, so the
  ranger measured where the servo points.
- One reading per angle, as the paper's servo node prints one per check (Fig. 12).
- A reading under 15 cm at any sweep angle (45, 90 or 135 degrees) stops the robot: Fig. 12
  shows "Check 45 degree / Obstacle detected".
"""

import rospy
from std_msgs.msg import Float32, Int16, String

SWEEP_DEG = (90, 45, 90, 135)  # Fig. 3
RIGHT_DEG, AHEAD_DEG, LEFT_DEG = 0, 90, 180  # servo angles: 0 right .. 180 left
STOP_BELOW_CM = 15.0  # [cm] Fig. 3: "less than 15 cm, the robot will stop moving"
SERVO_SLEW_DEG_S = 500.0  # [deg/s] SG90-class servo, 0.12 s per 60 degrees
SENSOR_PERIOD_S = 0.04  # [s] one IR reading every 40 ms (25 Hz)
MAX_INT16_CM = 32767

# States of the node.
SWEEPING, LOOK_RIGHT, LOOK_LEFT, WAIT_FORWARD = "sweeping", "look right", "look left", "wait"

rospy.init_node("servo")
servo_angle = rospy.Publisher("servo_angle", Int16, queue_size=1)
dist_detect = rospy.Publisher("dist_detect", Int16, queue_size=1)
dist_right = rospy.Publisher("dist_detect_right", Int16, queue_size=1)
dist_left = rospy.Publisher("dist_detect_left", Int16, queue_size=1)

pointing_deg = AHEAD_DEG  # where the servo was last told to point
trust_after_s = 0.0  # readings that arrive from then on were measured at `pointing_deg`
state = SWEEPING
sweep_index = 0  # where in SWEEP_DEG the servo points while sweeping
right_cm = 0.0  # [cm] the reading at 0 degrees, kept until the one at 180 degrees comes


def point(angle_deg):
    """Turn the servo and work out when its readings can be trusted again."""
    global pointing_deg, trust_after_s
    travel_s = abs(angle_deg - pointing_deg) / SERVO_SLEW_DEG_S
    trust_after_s = rospy.get_time() + travel_s + SENSOR_PERIOD_S
    pointing_deg = angle_deg
    servo_angle.publish(Int16(angle_deg))


def as_int16(distance_cm):
    return Int16(min(MAX_INT16_CM, round(distance_cm)))


def on_distance(msg):
    """The flow chart of Fig. 3, one step per reading that arrives at 25 Hz."""
    global state, sweep_index, right_cm
    if rospy.get_time() < trust_after_s:
        return  # the servo may still be moving: this reading is from somewhere on the way
    distance_cm = msg.data
    if state == SWEEPING:
        rospy.loginfo("Check %d degree: %.1f cm", pointing_deg, distance_cm)
        if distance_cm < STOP_BELOW_CM:
            rospy.loginfo("Obstacle detected")
            dist_detect.publish(as_int16(distance_cm))
            state = LOOK_RIGHT
            point(RIGHT_DEG)
        else:
            sweep_index = (sweep_index + 1) % len(SWEEP_DEG)
            point(SWEEP_DEG[sweep_index])
    elif state == LOOK_RIGHT:
        right_cm = distance_cm
        state = LOOK_LEFT
        point(LEFT_DEG)
    elif state == LOOK_LEFT:
        rospy.loginfo("Distance right %.1f cm, left %.1f cm", right_cm, distance_cm)
        dist_right.publish(as_int16(right_cm))
        dist_left.publish(as_int16(distance_cm))
        state = WAIT_FORWARD
        point(AHEAD_DEG)


def on_forward(msg):
    """The dc_motor node drives forward again: resume the sweep."""
    global state, sweep_index
    if state == WAIT_FORWARD:
        state = SWEEPING
        sweep_index = 0
        point(SWEEP_DEG[sweep_index])


rospy.Subscriber("distance_detect", Float32, on_distance)
rospy.Subscriber("forward", String, on_forward)
point(SWEEP_DEG[sweep_index])
rospy.spin()
