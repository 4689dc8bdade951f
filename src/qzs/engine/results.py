"""Result objects: they hold arrays and metadata, and delegate (pvlib style).

``SimulationResult.plot()`` calls :mod:`qzs.viz`, ``.save()`` calls
:mod:`qzs.iotools`, ``.summary()`` calls :mod:`qzs.analysis.summary`, and
``.to_xarray()`` only repackages.
"""
import dataclasses

import numpy as np

from qzs.engine import kernels as K

__all__ = ["SimulationResult", "CHANNELS", "FLAGS"]

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


class SimulationResult:
    """Time series and metadata of one simulation.

    Channels are attributes (``result.payload_acceleration``) and items
    (``result["locked"]``); see :data:`CHANNELS` and :data:`FLAGS`.

    Parameters
    ----------
    data : ndarray, shape (n_samples, N_CHANNELS)
        The output samples, one column per channel of :data:`CHANNELS` (in their units).
    flags : ndarray of bool, shape (n_samples, 2)
        The boolean outputs, one column per flag of :data:`FLAGS`.

    Attributes
    ----------
    isolator : IsolatorParameters
        Plant parameters of the run.
    controller : ControllerParameters
        PI and damping loops of the run.
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        Base excitation of the run.
    run : dict
        Solver, ``dt`` [s], ``sample_rate`` [Hz], ``steps``, ``elapsed`` [s],
        ``completed``, ``stop_contacts``, ``stick_events``, stop positions [m].
    """

    def __init__(self, data, flags, *, isolator, controller, excitation, run):
        self._data = data
        self._flags = flags
        self.isolator = isolator
        self.controller = controller
        self.excitation = excitation
        self.run = run

    def __getitem__(self, name):
        if name in CHANNELS:
            return self._data[:, CHANNELS[name][0]]
        if name in FLAGS:
            return self._flags[:, FLAGS[name][0]]
        raise KeyError(f"no channel {name!r}; channels are {', '.join([*CHANNELS, *FLAGS])}.")

    def __getattr__(self, name):
        if name.startswith("_") or (name not in CHANNELS and name not in FLAGS):
            raise AttributeError(name)
        return self[name]

    def __len__(self):
        return self._data.shape[0]

    @property
    def completed(self):
        """False if the run was interrupted before its end."""
        return self.run["completed"]

    @property
    def steps_per_second(self):
        """Integration throughput of the run [steps/s]."""
        return self.run["steps"] / max(self.run["elapsed"], 1e-12)

    def mechanical_energy(self):
        """Kinetic + spring + gravity + stop elastic energy [J] at each sample."""
        return sum(self[n] for n in ("kinetic_energy", "spring_energy", "gravity_energy",
                                     "stop_energy"))

    def energy_residual(self):
        """Energy-ledger imbalance [J]: change of mechanical energy minus net work.

        ``dE - (W_base + W_motor - D_friction - D_stop)``; zero up to the
        integrator's truncation error.
        """
        energy = self.mechanical_energy()
        net = self.base_work + self.motor_work - self.friction_dissipation - self.stop_dissipation
        return energy - energy[0] - net

    def metadata(self):
        """Flat ``dict`` of every parameter, the excitation, the run settings and the version."""
        from qzs._version import __version__

        meta = {"qzs_version": __version__}
        meta.update({f"isolator.{k}": v for k, v in self.isolator.to_dict().items()})
        meta.update({f"controller.{k}": v for k, v in self.controller.to_dict().items()})
        meta["excitation"] = type(self.excitation).__name__
        for field in dataclasses.fields(self.excitation):  # scalars; a record's arrays are data
            value = getattr(self.excitation, field.name)
            if value is not None and not isinstance(value, np.ndarray):
                meta[f"excitation.{field.name}"] = value
        if self.excitation.duration is not None:
            meta.setdefault("excitation.duration", self.excitation.duration)
        meta.update({f"run.{k}": v for k, v in self.run.items()})
        return {k: (int(v) if isinstance(v, bool) else v) for k, v in meta.items()}

    def to_xarray(self):
        """The run as an ``xarray.Dataset`` on dimension ``time`` with units and metadata."""
        import xarray as xr

        time = self["time"]
        variables = {
            name: ("time", self._data[:, col], {"units": unit, "long_name": doc})
            for name, (col, unit, doc) in CHANNELS.items() if name != "time"}
        variables.update({
            name: ("time", self._flags[:, col], {"long_name": doc})
            for name, (col, doc) in FLAGS.items()})
        return xr.Dataset(variables, coords={"time": ("time", time, {"units": "s"})},
                          attrs=self.metadata())

    def summary(self):
        """One-screen text summary of the run."""
        from qzs.analysis.summary import summary_text

        return summary_text(self)

    def plot(self, **kwargs):
        """Plot the time series (see :func:`qzs.viz.plot_simulation`)."""
        from qzs.viz.simulation import plot_simulation

        return plot_simulation(self, **kwargs)

    def save(self, path):
        """Write the run atomically to NetCDF (``.nc``) or CSV (``.csv``), with metadata.

        Parameters
        ----------
        path : str or Path
            Target file; its suffix (``.nc`` or ``.csv``) chooses the format.

        Returns
        -------
        Path
            The path written (see :func:`qzs.iotools.files.save_result`).
        """
        from qzs.iotools.files import save_result

        return save_result(self, path)

    def __repr__(self):
        return (f"<SimulationResult {len(self)} samples, {self['time'][-1]:.6g} s, "
                f"{self.run['solver']} dt={self.run['dt']:g} s, "
                f"{'complete' if self.completed else 'interrupted'}>")

