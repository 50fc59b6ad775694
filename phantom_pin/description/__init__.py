"""From a configuration to its models: ``describe()`` gives the URDF and SRDF (xacro) and the
MJCF (mjcf), each checked by the one physical check of a link (physical)."""
