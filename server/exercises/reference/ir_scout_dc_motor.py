"""dc_motor node of the IR scout's obstacle avoidance (002_3fcfeb7b4c14107a.txt section II-E,
Fig. 4 and Fig. 14; node `dc_motor` of the ROS graph in Fig. 8): drive forward; stop when the
servo node reports an obstacle on `dist_detect`; turn (or back up) as `direction` says; then
drive forward again and tell the servo node on `forward` to resume its sweep. Reference solution
of the `ir_scout_avoidance` exercise (not shown to students).

Topics: `dist_detect` (std_msgs/Int16) and `direction` (std_msgs/String) in; `motor_command`
(std_msgs/String: forward, backward, left, right, stop, to the robot) and `forward`
(std_msgs/String, "move", the paper's "move message" to the servo node) out.

Assumptions (the paper gives no durations):
- A turn lasts TURN_S = 1.05 s: at the robot's 1.5 rad/s about 90 degrees, so the robot then
  faces where the servo node measured the larger distance ("turn to the right (0 degrees)",
  section II-E). A shorter turn (0.6 s, ~50 degrees) leaves a robot that stopped against an
  angled face still heading into it, and it turns back and forth there.
- Backing up lasts BACKUP_S = 1.0 s (about 8 cm at 0.08 m/s), then the robot drives forward
  again, as the flow chart says.
"""

import rospy
from std_msgs.msg import Int16, String

TURN_S = 1.05  # [s] how long a left/right turn lasts: ~90 degrees at 1.5 rad/s
BACKUP_S = 1.0  # [s] how long backing up lasts
MANOEUVRE_S = {"left": TURN_S, "right": TURN_S, "backward": BACKUP_S}
LOOP_HZ = 20  # [Hz] how often the node checks its timer (turns last whole periods)

rospy.init_node("dc_motor")
motor = rospy.Publisher("motor_command", String, queue_size=1)
forward = rospy.Publisher("forward", String, queue_size=1)
events = []  # "stop" or a direction, in the order they arrived


def on_dist_detect(msg):
    events.append("stop")


def on_direction(msg):
    events.append(msg.data)


def drive(word):
    rospy.loginfo(word)
    motor.publish(String(word))


rospy.Subscriber("dist_detect", Int16, on_dist_detect)
rospy.Subscriber("direction", String, on_direction)
rate = rospy.Rate(LOOP_HZ)
rospy.sleep(0.1)  # let the other nodes come up
drive("forward")
manoeuvre_ends_s = None  # when the current turn or back-up is over
while not rospy.is_shutdown():
    while events:
        event = events.pop(0)
        if event == "stop":
            drive("stop")
            manoeuvre_ends_s = None
        elif event in MANOEUVRE_S:
            drive(event)
            manoeuvre_ends_s = rospy.get_time() + MANOEUVRE_S[event]
        else:
            rospy.logwarn("unknown direction %r", event)
    if manoeuvre_ends_s is not None and rospy.get_time() >= manoeuvre_ends_s:
        manoeuvre_ends_s = None
        drive("forward")
        forward.publish(String("move"))
    rate.sleep()
