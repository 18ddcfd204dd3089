"""The iRobot Create/Roomba base over its Open Interface (pyserial), presenting the simulated
turtlebot's topics cmd_vel, odom and bumper.

- `oi`: the wire format (opcodes, sensor packets, command bytes, the stream frame parser);
- `kinematics`: wheel speeds from a Twist, odometry from the encoder counts;
- `topics`: stream frames -> odom and bumper messages;
- `port`: opening the serial port, and the errors, each a sentence;
- `driver`: `CreateDriver`, the lifecycle and the reader thread;
- `link`: `CreateLink`, the driver as the `RobotLink` a hardware run drives.

Only `driver`, `port` and `link` need pyserial.
"""
