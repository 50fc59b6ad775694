"""ROS 2, one module per program: ``node`` (the ``ros2`` node beside a driver: gravity torques,
poses and forces rendered through the driver's profile) and ``simulated_driver`` (a stand-in
for a driver over the simulated device, ``sim-driver``). rclpy loads when a node is made."""
