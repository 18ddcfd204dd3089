"""compare_distance node (002_3fcfeb7b4c14107a.txt section II-E, Fig. 3 and 7; node
`compare_distance` in Fig. 8).

Receive the distances [cm] the servo node measured to the right (`dist_detect_right`, 0 degrees)
and to the left (`dist_detect_left`, 180 degrees), both std_msgs/Int16, and publish on
`direction` (std_msgs/String) which way the dc_motor node should go: "right" or "left", toward
the side with more room, or "backward" if both are under 30 cm.
"""

import rospy
from std_msgs.msg import Int16, String

BOTH_NEAR_CM = 30  # [cm]

rospy.init_node("compare_distance")
direction = rospy.Publisher("direction", String, queue_size=1)
sides = {}


def decide(right_cm, left_cm):
    # TODO: compare the two sides (and back up when both are near).
    return "left"


def on_side(msg, side):
    sides[side] = msg.data
    if len(sides) == 2:
        direction.publish(String(decide(sides.pop("right"), sides.pop("left"))))


rospy.Subscriber("dist_detect_right", Int16, on_side, callback_args="right")
rospy.Subscriber("dist_detect_left", Int16, on_side, callback_args="left")
rospy.spin()
