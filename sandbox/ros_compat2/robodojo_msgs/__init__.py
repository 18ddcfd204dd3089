"""The ROS 2 package `robodojo_msgs` for student code: srv (ComputeVelocityCommands, the service
the lab's Nav2 controller server calls; the package's messages are the lab's own wire)."""
