"""How programs reach the device, in layers (tests/test_imports.py holds them):

1. What the drivers publish and take, as data and conversions (no ROS, no OpenHaptics):
   ``conventions`` (OpenHaptics' angles, torques and transform to and from the report's theta;
   JointConvention, the one reader of every driver's joint states, and FIXED_CONVENTION, the
   older drivers' profile's) and ``profiles`` (one per public ROS driver, from
   config/drivers/NAME.yaml).
2. The force computation: ``forces`` (Renderer: the joint torques and the driver's force
   command of a state: gravity, friction, inertia, a user force).
3. One module or package per transport: ``ros2.node`` (the ROS 2 node), ``ros2.simulated_driver``
   (a simulated ROS driver), ``openhaptics`` (OpenHaptics' 1 kHz servo loop: the Compensator
   for a pyOpenHaptics callback and a stand-in for libHD).
"""
