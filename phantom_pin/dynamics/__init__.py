"""The rigid body in the report's coordinates, computed by Pinocchio: ``Phantom`` (model),
the mimic coupling of the parallelogram (coupling) and ``load()`` as a RobotWrapper (loader)."""
