"""OpenHaptics' servo loop: the compensation in its 1 ms tick, and a stand-in for its libHD.

- ``Compensator``: the forces (HD_CURRENT_FORCE, N) or joint torques (HD_CURRENT_JOINT_TORQUE,
  mN m) that compensate the device's gravity, optionally its friction, for one call a tick of
  a pyOpenHaptics callback (``compensator``).
- ``build``: writes an OpenHaptics-like tree, DIR/include/HD/hd.h and DIR/lib/libHD.so, whose
  library runs HDAPI programs against the simulated device (``stand_in``; the device behind it
  is ``plant``, its per-tick record ``read_record``).

docs/servo-loop.md ("In your servo loop") shows both sides and the sources of every enum.
"""

from phantom_pin.interfaces.openhaptics.compensator import MODES, Compensator
from phantom_pin.interfaces.openhaptics.protocol import read_record
from phantom_pin.interfaces.openhaptics.stand_in import build

__all__ = ["MODES", "Compensator", "build", "read_record"]
