"""sensor_msgs: laser scans, IMU readings and single-beam range sensors (ros/common_msgs)."""

from __future__ import annotations

from . import geometry_msgs as _geometry_msgs  # noqa: F401  # registers nested types
from ._core import Message


class LaserScan(Message):
    """A planar laser/lidar scan; angles in [rad], ranges in [m], times in [s]."""

    _type = "sensor_msgs/LaserScan"
    _definition = """
# Single scan from a planar laser range-finder

Header header            # timestamp in the header is the acquisition time of
                         # the first ray in the scan.

float32 angle_min        # start angle of the scan [rad]
float32 angle_max        # end angle of the scan [rad]
float32 angle_increment  # angular distance between measurements [rad]

float32 time_increment   # time between measurements [seconds]
float32 scan_time        # time between scans [seconds]

float32 range_min        # minimum range value [m]
float32 range_max        # maximum range value [m]

float32[] ranges         # range data [m] (Note: values < range_min or > range_max should be
                         # discarded)
float32[] intensities    # intensity data [device-specific units].  If your
                         # device does not provide intensities, please leave
                         # the array empty.
"""


class Imu(Message):
    """Orientation, angular velocity [rad/s] and linear acceleration [m/s^2]."""

    _type = "sensor_msgs/Imu"
    _definition = """
# This is a message to hold data from an IMU (Inertial Measurement Unit)
#
# If the covariance of the measurement is known, it should be filled in (if all you know is the
# variance of each measurement, e.g. from the datasheet, just put those along the diagonal)
# A covariance matrix of all zeros will be interpreted as "covariance unknown"
# If you have no estimate for one of the data elements, set element 0 of the associated
# covariance matrix to -1

Header header

geometry_msgs/Quaternion orientation
float64[9] orientation_covariance # Row major about x, y, z axes

geometry_msgs/Vector3 angular_velocity
float64[9] angular_velocity_covariance # Row major about x, y, z axes

geometry_msgs/Vector3 linear_acceleration
float64[9] linear_acceleration_covariance # Row major x, y z
"""


class Range(Message):
    """One range reading from an ultrasonic or infrared sensor; distances in [m]."""

    _type = "sensor_msgs/Range"
    _definition = """
# Single range reading from an active ranger that emits energy and reports
# one range reading that is valid along an arc at the distance measured.

Header header           # timestamp in the header is the time the ranger
                        # returned the distance reading

# Radiation type enums
# If you want a value added to this list, send an email to the ros-users list
uint8 ULTRASOUND=0
uint8 INFRARED=1

uint8 radiation_type    # the type of radiation used by the sensor
                        # (sound, IR, etc) [enum]

float32 field_of_view   # the size of the arc that the distance reading is
                        # valid for [rad]

float32 min_range       # minimum range value [m]
float32 max_range       # maximum range value [m]
                        # Fixed distance rangers require min_range==max_range

float32 range           # range data [m]
                        # (Note: values < range_min or > range_max
                        # should be discarded)
"""
