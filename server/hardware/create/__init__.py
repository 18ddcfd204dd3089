"""The iRobot Create/Roomba base over its Open Interface (pyserial): `oi` (the wire format),
`kinematics` (wheel speeds and encoder odometry), `driver` (`CreateDriver`, the serial port and
the turtlebot's topics cmd_vel, odom, bumper)."""
