"""How programs reach the device: the transports beside the rigid body and the device.

``phantom_pin.interfaces.openhaptics``: OpenHaptics' servo loop (HDAPI, 1 kHz) — a stand-in for
libHD that runs unchanged HDAPI programs against the simulated device, and the gravity
compensation for a pyOpenHaptics callback.
"""
