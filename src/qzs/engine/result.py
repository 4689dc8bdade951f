"""The result of a run: :class:`SimulationResult` holds arrays and metadata, and delegates.

As pvlib's result objects: ``.plot()`` calls :mod:`qzs.viz`, ``.summary()`` calls
:mod:`qzs.analysis.summary`, ``.to_xarray()`` only repackages (the layout of
:func:`~qzs.engine.channels.simulation_schema`, the attributes of
:func:`~qzs.engine.metadata.file_attributes`) and ``.save()`` writes through
:func:`~qzs.engine.result_file.save_result`.
"""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from numpy.typing import NDArray

from qzs.engine.channels import CHANNELS, FLAGS, named_block, run_channels, simulation_schema
from qzs.engine.metadata import file_attributes, parameter_metadata, run_metadata
from qzs.engine.result_file import RESULT_SUFFIXES, save_result
from qzs.iotools.schema import to_dataset

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.figure import Figure

    from qzs.model.controller import ControllerParameters
    from qzs.model.excitation import Excitation
    from qzs.model.isolator import IsolatorParameters

__all__ = ["SimulationResult"]


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
    statistics : dict, optional
        The summary's statistics of every sample, when ``data`` is only a preview of a run
        streamed to a file (see :attr:`statistics`); computed from ``data`` if omitted.

    Attributes
    ----------
    isolator : IsolatorParameters
        Plant parameters of the run.
    controller : ControllerParameters
        PI and damping loops of the run.
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        Base excitation of the run.
    run : dict
        Solver, ``dt`` [s], ``sample_rate`` [Hz], ``steps``, ``elapsed`` [s] (integration
        only: compiling the kernels is not counted), ``completed``, ``stop_contacts``,
        ``stick_events``, stop positions [m], ``samples`` (output samples of the run) and
        ``preview_every`` (1, or k if the result of a streamed run keeps the min/max
        envelope of groups of k samples, for figures).
    """

    def __init__(self, data: NDArray[np.float64], flags: NDArray[np.bool_], *,
                 isolator: IsolatorParameters, controller: ControllerParameters,
                 excitation: Excitation, run: dict[str, Any],
                 statistics: dict[str, Any] | None = None) -> None:
        self._data = data
        self._flags = flags
        self.isolator = isolator
        self.controller = controller
        self._channels = run_channels(controller)
        self.excitation = excitation
        self.run = run
        self._statistics = statistics

    @property
    def statistics(self) -> dict[str, Any]:
        """What the summary reports, from every sample of the run (also of a streamed one).

        A dict, see :data:`qzs.analysis.statistics.SUMMARY_STATISTICS` for names and units.
        """
        if self._statistics is None:  # a result built from arrays: summarise them
            from qzs.engine.channels import summary_statistics

            center = 0.5 * (self.run["stop_low"] + self.run["stop_high"])
            statistics = summary_statistics(self.controller, center,
                                            self.isolator.motor_force_max)
            statistics.add(named_block(self._data, self._flags))
            self._statistics = statistics.result()
        return self._statistics

    @property
    def channels(self) -> tuple[str, ...]:
        """The names of the run's channels and flags (the controller's blocks' included)."""
        return (*self._channels, *FLAGS)

    def __getitem__(self, name: str) -> NDArray[Any]:
        if name in self._channels:
            return self._data[:, self._channels[name][0]]
        if name in FLAGS:
            return self._flags[:, FLAGS[name][0]]
        raise KeyError(f"no channel {name!r}; channels are {', '.join(self.channels)}"
                       + (" (a block's channel is there only when the controller has the "
                          "block)" if name not in CHANNELS else "") + ".")

    def __getattr__(self, name: str) -> NDArray[Any]:
        if name.startswith("_") or (name not in self.__dict__.get("_channels", CHANNELS)
                                    and name not in FLAGS):
            raise AttributeError(name)
        return self[name]

    def __len__(self) -> int:
        return self._data.shape[0]

    @property
    def completed(self) -> bool:
        """False if the run was interrupted before its end."""
        return self.run["completed"]

    @property
    def steps_per_second(self) -> float:
        """Integration throughput of the run [steps/s]."""
        return self.run["steps"] / max(self.run["elapsed"], 1e-12)

    def mechanical_energy(self) -> NDArray[np.float64]:
        """Kinetic + spring + gravity + stop elastic energy [J] at each sample."""
        return cast("NDArray[np.float64]",  # a sum of four arrays, never the start value 0
                    sum(self[n] for n in ("kinetic_energy", "spring_energy", "gravity_energy",
                                          "stop_energy")))

    def energy_residual(self) -> NDArray[np.float64]:
        """Energy-ledger imbalance [J]: change of mechanical energy minus net work.

        ``dE - (W_base + W_motor - D_friction - D_stop)``; zero up to the
        integrator's truncation error.
        """
        energy = self.mechanical_energy()
        net = self.base_work + self.motor_work - self.friction_dissipation - self.stop_dissipation
        return energy - energy[0] - net

    def metadata(self) -> dict[str, Any]:
        """Flat ``dict`` of every parameter, the excitation, the run settings and the version.

        ``None`` values are kept, booleans are 0/1; the units are in
        :func:`parameter_metadata` and :func:`run_metadata`.
        """
        from qzs._version import __version__

        meta: dict[str, Any] = {"qzs_version": __version__}
        meta.update({k: v for k, (v, _) in parameter_metadata(
            self.isolator, self.controller, self.excitation).items()})
        meta.update({k: v for k, (v, _) in run_metadata(self.run).items()})
        return meta

    def to_xarray(self) -> xr.Dataset:
        """The run as an ``xarray.Dataset`` on dimension ``time``, with CF-1.10 metadata.

        The same variables and attributes as a saved NetCDF file (:func:`simulation_schema`,
        docs/model.md §7), except that the flags stay boolean and ``None`` parameters are
        ``"none"`` (listed in ``none_parameters``).
        """
        schema = simulation_schema(self.controller)
        head, tail = file_attributes(self.isolator, self.controller, self.excitation, self.run)
        return to_dataset(schema, {name: self[name] for name in schema.names},
                          {**head, **tail}, boolean_flags=True)

    def summary(self) -> str:
        """One-screen text summary of the run."""
        from qzs.analysis.summary import summary_text

        return summary_text(self)

    def plot(self, path: str | Path | None = None, *, title: str | None = None) -> Figure:
        """Plot the time series (:func:`qzs.viz.simulation.plot_simulation`).

        Parameters
        ----------
        path : str or Path, optional
            Write the figure there too (format from the suffix).
        title : str, optional
            Figure title; default :func:`qzs.analysis.summary.run_title`.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from qzs.viz.simulation import plot_simulation

        return plot_simulation(self, path=path, title=title)

    #: The extensions :meth:`save` accepts.
    save_suffixes = tuple(RESULT_SUFFIXES)

    def save(self, path: str | Path) -> Path:
        """Write the run atomically to NetCDF (``.nc``), CSV (``.csv``) or MATLAB (``.mat``).

        Parameters
        ----------
        path : str or Path
            Target file; its suffix (``.nc``, ``.csv`` or ``.mat``) chooses the format.

        Returns
        -------
        Path
            The path written (see :func:`save_result`).
        """
        return save_result(self, path)

    def __repr__(self):
        return (f"<SimulationResult {len(self)} samples, {self['time'][-1]:.6g} s, "
                f"{self.run['solver']} dt={self.run['dt']:g} s, "
                f"{'complete' if self.completed else 'interrupted'}>")
