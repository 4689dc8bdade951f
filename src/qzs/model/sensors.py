"""What a user's controller may read, and how many states it may have (docs/model.md §5).

One small module that the kernels read too (:mod:`qzs.engine.kernels` packs a linear
controller by these), kept apart from :mod:`qzs.model.controller` so that an edit there does
not make the kernels compile again.
"""
__all__ = ["SENSORS", "MAX_STATES"]

#: What a :class:`~qzs.model.controller.LinearController` may read, in the kernels' order:
#: name -> (unit, description). The payload's acceleration enters a continuous controller
#: through its states only (no direct feedthrough: that would be an algebraic loop through
#: the motor).
SENSORS: dict[str, tuple[str, str]] = {
    "position_error": ("m", "encoder position error z_ref - z"),
    "measured_payload_velocity": ("m/s", "payload velocity from the charge amplifier "
                                         "(high-passed)"),
    "payload_acceleration": ("m/s^2", "payload acceleration (accelerometer)"),
    "base_acceleration": ("m/s^2", "base acceleration (the rig's second accelerometer)"),
    "relative_velocity": ("m/s", "relative velocity z-dot (the encoder's)"),
}
#: Most states of a :class:`~qzs.model.controller.LinearController` (the kernels hold this many).
MAX_STATES = 8
