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

__all__ = ["CHANNELS", "BLOCK_CHANNELS", "FLAGS", "FLAG_MEANINGS", "run_channels", "unrecorded",
           "channel_count", "summary_statistics", "block_costs", "simulation_schema", "variable_attributes",
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
#: The channels of the controller's blocks beyond PI + damping, recorded only with them:
#: name -> (kernel column, unit, description, the block that has it).
BLOCK_CHANNELS = {
    "compensation_force": (K.C_F_COMPENSATION, "N", "friction compensation command (the "
                           "feedforward less the observer's estimate, before saturation)",
                           "compensation"),
    "friction_estimate": (K.C_F_OBSERVER, "N", "the observer's estimate of the friction "
                          "left after the feedforward", "observer"),
    "dither_force": (K.C_F_DITHER, "N", "dither command (before saturation)", "dither"),
    "linear_force": (K.C_F_LINEAR, "N", "the linear controller's command (before saturation)",
                     "linear"),
}
#: Boolean output channels: name -> (column, description).
FLAGS = {
    "locked": (K.O_LOCKED, "payload held at zero slip (stuck by friction or on a plastic stop)"),
    "stop_contact": (K.O_CONTACT, "payload in contact with a hard stop"),
}
#: CF ``flag_meanings`` of the flags: the words for the values 0 and 1.
FLAG_MEANINGS = {"locked": "slipping locked", "stop_contact": "free contact"}


def _has(controller, block):
    if controller is None:
        return False
    if block == "observer":
        return (controller.compensation is not None
                and controller.compensation.observer_bandwidth > 0)
    return getattr(controller, block) is not None


def run_channels(controller=None, *, every_block=False):
    """The channels a run with ``controller`` records: name -> (column, unit, description).

    :data:`CHANNELS`, then those of :data:`BLOCK_CHANNELS` whose block the controller has
    (the friction estimate with an observer only).

    Parameters
    ----------
    controller : ControllerParameters, optional
        The run's controller; None: PI + damping alone.
    every_block : bool
        Every block's channels (what a file may hold, for reading it back).

    Returns
    -------
    dict
    """
    extra = {name: (column, unit, doc) for name, (column, unit, doc, block)
             in BLOCK_CHANNELS.items() if every_block or _has(controller, block)}
    return {**CHANNELS, **extra}


def unrecorded(names, controller):
    """The blocks' channels among ``names`` that a run with ``controller`` does not record.

    Parameters
    ----------
    names : iterable of str
        Channel (or flag) names asked for.
    controller : ControllerParameters
        The run's controller.

    Returns
    -------
    list of str
        Those of :data:`BLOCK_CHANNELS` whose block the controller lacks, in order.
    """
    recorded = run_channels(controller)
    return [name for name in names if name in BLOCK_CHANNELS and name not in recorded]


def summary_statistics(controller, stop_center, motor_force_max):
    """The accumulator of a run's summary statistics, with what the controller's blocks add.

    Parameters
    ----------
    controller : ControllerParameters
        The run's controller.
    stop_center : float
        Centre of the stroke [m].
    motor_force_max : float
        The motor's force limit [N].

    Returns
    -------
    SummaryStatistics
    """
    from qzs.analysis.statistics import SummaryStatistics

    blocks, dither_frequency = block_costs(controller)
    return SummaryStatistics(stop_center, motor_force_max, blocks=blocks,
                             dither_frequency=dither_frequency)


def block_costs(controller):
    """What a controller's blocks cost in a run's summary: the block channels it records
    (:data:`BLOCK_CHANNELS`) and its dither's frequency [Hz] (None without one), as
    :class:`qzs.analysis.statistics.BlockStatistics` takes them.

    Parameters
    ----------
    controller : ControllerParameters or None
        The controller (of a run, or of one leg of a platform).

    Returns
    -------
    blocks : list of str
    dither_frequency : float or None
    """
    blocks = [name for name in run_channels(controller) if name in BLOCK_CHANNELS]
    dither = getattr(controller, "dither", None)
    return blocks, None if dither is None else dither.frequency


def channel_count(controller=None):
    """Columns of a run's output rows [-]: ``K.N_BASE_CHANNELS``, or ``K.N_CHANNELS`` with blocks.

    Parameters
    ----------
    controller : ControllerParameters, optional
        The run's controller.

    Returns
    -------
    int
    """
    blocks = controller is not None and controller.has_blocks
    return K.N_CHANNELS if blocks else K.N_BASE_CHANNELS


def sample_bytes(channels):
    """Memory one sample of ``channels`` takes in a result [bytes]: 8 a float channel, 1 a flag.

    Parameters
    ----------
    channels : iterable of str
        Names of :func:`run_channels` and :data:`FLAGS`.

    Returns
    -------
    int
    """
    return sum(1 if name in FLAGS else 8 for name in channels)


def simulation_schema(controller=None, *, every_block=False):
    """The CF-1.10 layout of a run's dataset and file (docs/model.md §7).

    Dimension ``time`` (unlimited: a run is streamed along it); coordinate ``time`` [s]; a
    float64 variable per channel of :data:`CHANNELS` (and of the controller's blocks,
    :func:`run_channels`) and an int8 flag per flag of :data:`FLAGS` (``flag_values`` 0 and
    1, ``flag_meanings``), each with ``units`` and ``long_name``.

    Parameters
    ----------
    controller : ControllerParameters, optional
        The run's controller (its blocks' channels); None: PI + damping alone.
    every_block : bool
        Every block's channels (the schema to read any run's file back with).

    Returns
    -------
    Schema
    """
    channels = [Variable(name=name, dims=("time",), units=unit, long_name=doc)
                for name, (_, unit, doc) in run_channels(controller, every_block=every_block).items()
                if name != "time"]
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
    data : ndarray, shape (n, N_BASE_CHANNELS) or (n, N_CHANNELS)
        Output rows, one column per channel of :data:`CHANNELS` (then of
        :data:`BLOCK_CHANNELS`, with blocks).
    flags : ndarray of bool, shape (n, 2)
        The flags of :data:`FLAGS`.

    Returns
    -------
    dict of str to ndarray
        Every channel and flag by name (views), plus ``mechanical_energy`` [J].
    """
    named = CHANNELS if data.shape[1] <= K.N_BASE_CHANNELS else run_channels(every_block=True)
    block = {name: data[:, column] for name, (column, _, _) in named.items()}
    block.update({name: flags[:, column] for name, (column, _) in FLAGS.items()})
    block["mechanical_energy"] = (block["kinetic_energy"] + block["spring_energy"]
                                  + block["gravity_energy"] + block["stop_energy"])
    return block
