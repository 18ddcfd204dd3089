"""compare_distance node of the IR scout's obstacle avoidance (002_3fcfeb7b4c14107a.txt section
II-E, Fig. 3 and Fig. 7; node `compare_distance` of the ROS graph in Fig. 8): compare the
distances the servo node measured at 0 degrees (right) and 180 degrees (left) and tell the
dc_motor node which way to go. Reference solution of the `ir_scout_avoidance` exercise.

Topics: `dist_detect_right` and `dist_detect_left` (std_msgs/Int16, cm, as section II-E gives
the type) in; `direction` (std_msgs/String: "left", "right" or "backward") out.

The rule is the flow chart's (section II-E): turn toward the side with more room; if both sides
are under 30 cm, back up. (A later sentence of the same section and Fig. 13 have the sides the
other way round; turning toward the larger distance is the rule that avoids obstacles.)

Assumption: the servo node publishes right, then left, for each stop; a decision needs one of
each, and then both are forgotten so a stale side never pairs with a new one.
"""

import rospy
from std_msgs.msg import Int16, String

BOTH_NEAR_CM = 30  # [cm] "less than 30cm, the robot will turn backward"

rospy.init_node("compare_distance")
direction = rospy.Publisher("direction", String, queue_size=1)
sides = {}


def decide(right_cm, left_cm):
    if right_cm < BOTH_NEAR_CM and left_cm < BOTH_NEAR_CM:
        return "backward"
    return "right" if right_cm > left_cm else "left"


def on_side(msg, side):
    sides[side] = msg.data
    rospy.loginfo("Distance %s: %d cm", side, msg.data)
    if len(sides) == 2:
        choice = decide(sides.pop("right"), sides.pop("left"))
        rospy.loginfo("turning %s", choice)
        direction.publish(String(choice))


rospy.Subscriber("dist_detect_right", Int16, on_side, callback_args="right")
rospy.Subscriber("dist_detect_left", Int16, on_side, callback_args="left")
rospy.spin()
