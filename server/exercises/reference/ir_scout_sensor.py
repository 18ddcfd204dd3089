"""Sensor node of the IR scout's obstacle avoidance (002_3fcfeb7b4c14107a.txt section II-E,
Fig. 5; node `sensor` of the ROS graph in Fig. 8): read the IR rangefinder on AIN0, convert the
reading to centimetres and publish it on `distance_detect` for the servo node. Reference solution
of the `ir_scout_avoidance` exercise (not shown to students).

    robodojo check ir_scout_avoidance --reference

Topics: `ir_adc` (std_msgs/Int32, raw 12-bit AIN0 count) in; `distance_detect`
(std_msgs/Float32, cm) out. Float32 because the paper's sensor node prints fractional
centimetres (Fig. 11: "Distance detected: 64.9450746534").

Assumptions (not in the paper):
- The conversion is the common power-law fit of the Sharp GP2Y0A21 curve,
  d [cm] = 29.988 * V ** -1.173, with V the sensor's output before the 1:2 divider that keeps
  AIN0 under the BeagleBone's 1.8 V (section II-B names AIN0, not the divider).
- A near-zero voltage means nothing reflected: reported as `FAR_CM`, beyond the 80 cm the
  sensor can see (the paper's Fig. 11 prints readings up to 146.9 cm when nothing is near).
- The paper's sensor node also waits for a "check" message (section II-E); Fig. 8 shows no such
  topic, so this node converts every reading as it arrives (25 Hz).
"""

import rospy
from std_msgs.msg import Float32, Int32

ADC_MAX_COUNT = 4095  # 12-bit AIN
ADC_FULL_SCALE_V = 1.8  # [V] BeagleBone Black analog input range
DIVIDER_GAIN = 2.0  # the 1:2 divider halves the sensor's voltage: multiply it back
FIT_SCALE_CM = 29.988  # [cm] d = 29.988 * V ** -1.173
FIT_EXPONENT = -1.173
NOTHING_BELOW_V = 0.05  # [V] this close to zero no light came back
FAR_CM = 150.0  # [cm] what "nothing in range" is reported as (fits an Int16 downstream)


def adc_count_to_volts(count: int) -> float:
    """Sensor output [V] (before the divider) for an AIN0 count."""
    return count / ADC_MAX_COUNT * ADC_FULL_SCALE_V * DIVIDER_GAIN


def adc_count_to_cm(count: int) -> float:
    """Distance [cm] for an AIN0 count, at most FAR_CM (also when nothing answered)."""
    volts = adc_count_to_volts(count)
    if volts < NOTHING_BELOW_V:
        return FAR_CM
    return min(FAR_CM, FIT_SCALE_CM * volts**FIT_EXPONENT)


def main() -> None:
    rospy.init_node("sensor")
    distance_detect = rospy.Publisher("distance_detect", Float32, queue_size=1)

    def on_adc(msg):
        distance_detect.publish(Float32(adc_count_to_cm(msg.data)))

    rospy.Subscriber("ir_adc", Int32, on_adc)
    rospy.spin()


if __name__ == "__main__":
    main()
