"""Sensor node (002_3fcfeb7b4c14107a.txt section II-E, Fig. 5; node `sensor` in Fig. 8).

Read the IR rangefinder's raw AIN0 count on `ir_adc` (std_msgs/Int32, 12 bit: 0..4095 for
0..1.8 V), convert it to centimetres and publish it on `distance_detect` (std_msgs/Float32, cm)
for the servo node.

The sensor's output goes through a 1:2 divider before AIN0 (the BeagleBone takes at most 1.8 V),
so the sensor's voltage is twice what the ADC sees. A common fit of the Sharp GP2Y0A21 curve:
d [cm] = 29.988 * V ** -1.173. Near 0 V nothing reflected the beam: report a large distance.
"""

import rospy
from std_msgs.msg import Float32, Int32

ADC_MAX_COUNT = 4095  # 12-bit AIN
ADC_FULL_SCALE_V = 1.8  # [V]
FAR_CM = 150.0  # [cm] what "nothing in range" is reported as


def adc_count_to_cm(count: int) -> float:
    """Distance [cm] for an AIN0 count."""
    # TODO: count -> volts at AIN0 -> volts at the sensor (undo the divider) -> centimetres.
    return FAR_CM


def main() -> None:
    rospy.init_node("sensor")
    distance_detect = rospy.Publisher("distance_detect", Float32, queue_size=1)

    def on_adc(msg):
        distance_detect.publish(Float32(adc_count_to_cm(msg.data)))

    rospy.Subscriber("ir_adc", Int32, on_adc)
    rospy.spin()


if __name__ == "__main__":
    main()
