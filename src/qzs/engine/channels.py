"""A run's output channels and flags, and the CF layout of its dataset and file.

:data:`CHANNELS` and :data:`FLAGS` name the kernel's output columns with their units;
:func:`simulation_schema` is the file schema (:mod:`qzs.iotools.schema`) that
:meth:`~qzs.engine.result.SimulationResult.to_xarray` and
:class:`~qzs.engine.result_file.ResultWriter` share; :func:`named_block` hands output rows by
name to the run statistics.
"""
from __future__ import annotations

from qzs.engine import kernels as K
from qzs.iotools.schema import Schema, Variable, time_coordinate

__all__ = ["CHANNELS", "FLAGS", "FLAG_MEANINGS", "simulation_schema", "variable_attributes",
           "named_block", "sample_bytes"]

#: Output channels: descriptive name -> (kernel column, unit, description).
CHANNELS = {
    "time": (K.C_TIME, "s", "time"),
    "base_displacement": (K.C_BASE_Y, "m", "base displacement y"),
    "base_velocity": (K.C_BASE_YD, "m/s", "base velocity"),
    "base_acceleration": (K.C_BASE_YDD, "m/s^2", "base acceleration"),
    "payload_displacement": (K.C_X, "m", "payload displacement x = y + z"),
    "payload_velocity": (K.C_XD, "m/s", "payload velocity"),
    "payload_acceleration": (K.C_XDD, "m/s^2", "payload acceleration"),
    "relative_position": (K.C_Z, "m", "relative position z = x - y (encoder)"),
    "relative_velocity": (K.C_V, "m/s", "relative (slip) velocity v"),
    "spring_force": (K.C_F_SPRING, "N", "MagSpring force on the payload"),
    "friction_force": (K.C_F_FRICTION, "N", "friction force on the payload"),
    "stop_force": (K.C_F_STOP, "N", "hard-stop force on the payload"),
    "motor_force": (K.C_F_MOTOR, "N", "motor force on the payload (saturated)"),
    "pi_force": (K.C_F_PI, "N", "PI position-loop command (before saturation)"),
    "damping_force": (K.C_F_DAMP, "N", "active damping command (before saturation)"),
    "measured_payload_velocity": (K.C_V_MEASURED, "m/s",
                                  "payload velocity seen by the controller (high-passed)"),
    "base_work": (K.C_W_BASE, "J", "work done by the base on the payload"),
    "friction_dissipation": (K.C_D_FRICTION, "J", "energy dissipated by friction"),
    "motor_work": (K.C_W_MOTOR, "J", "work done by the motor on the payload"),
    "stop_dissipation": (K.C_D_STOP, "J", "energy dissipated in the hard stops"),
    "kinetic_energy": (K.C_E_KINETIC, "J", "kinetic energy of the payload"),
    "spring_energy": (K.C_E_SPRING, "J", "energy stored in the MagSpring"),
    "gravity_energy": (K.C_E_GRAVITY, "J", "gravitational potential energy m*g*x"),
    "stop_energy": (K.C_E_STOP, "J", "elastic energy stored in a compliant stop"),
}
#: Boolean output channels: name -> (column, description).
FLAGS = {
    "locked": (K.O_LOCKED, "payload held at zero slip (stuck by friction or on a plastic stop)"),
    "stop_contact": (K.O_CONTACT, "payload in contact with a hard stop"),
}
#: CF ``flag_meanings`` of the flags: the words for the values 0 and 1.
FLAG_MEANINGS = {"locked": "slipping locked", "stop_contact": "free contact"}


def sample_bytes(channels):
    """Memory one sample of ``channels`` takes in a result [bytes]: 8 a float channel, 1 a flag.

    Parameters
    ----------
    channels : iterable of str
        Names of :data:`CHANNELS` and :data:`FLAGS`.

    Returns
    -------
    int
    """
    return sum(1 if name in FLAGS else 8 for name in channels)


def simulation_schema():
    """The CF-1.10 layout of a run's dataset and file (docs/model.md §7).

    Dimension ``time`` (unlimited: a run is streamed along it); coordinate ``time`` [s]; a
    float64 variable per channel of :data:`CHANNELS` and an int8 flag per flag of
    :data:`FLAGS` (``flag_values`` 0 and 1, ``flag_meanings``), each with ``units`` and
    ``long_name``.

    Returns
    -------
    Schema
    """
    channels = [Variable(name=name, dims=("time",), units=unit, long_name=doc)
                for name, (_, unit, doc) in CHANNELS.items() if name != "time"]
    flags = [Variable(name=name, dims=("time",), units="1", long_name=doc, dtype="int8",
                      flag_meanings=FLAG_MEANINGS[name]) for name, (_, doc) in FLAGS.items()]
    return Schema(kind="a run", dimensions={"time": None}, coordinates=(time_coordinate(),),
                  variables=(*channels, *flags))


def variable_attributes():
    """CF attributes of every variable of a result, ``time`` first, then channels and flags.

    Every variable has ``units`` and ``long_name``; ``time`` also ``standard_name`` and
    ``axis``; the flags (stored as int8 0/1) ``flag_values`` and ``flag_meanings``
    (:func:`simulation_schema`).

    Returns
    -------
    dict of str to dict
        Variable name -> attributes.
    """
    return simulation_schema().attributes()


def named_block(data, flags):
    """Output rows as the named arrays :class:`~qzs.analysis.statistics.SummaryStatistics` takes.

    Parameters
    ----------
    data : ndarray, shape (n, N_CHANNELS)
        Output rows, one column per channel of :data:`CHANNELS`.
    flags : ndarray of bool, shape (n, 2)
        The flags of :data:`FLAGS`.

    Returns
    -------
    dict of str to ndarray
        Every channel and flag by name (views), plus ``mechanical_energy`` [J].
    """
    block = {name: data[:, column] for name, (column, _, _) in CHANNELS.items()}
    block.update({name: flags[:, column] for name, (column, _) in FLAGS.items()})
    block["mechanical_energy"] = (block["kinetic_energy"] + block["spring_energy"]
                                  + block["gravity_energy"] + block["stop_energy"])
    return block
