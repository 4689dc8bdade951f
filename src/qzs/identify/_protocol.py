"""What every fit shares (issue 42: every result one protocol).

A fit holds its numbers; :class:`FitProtocol` gives it the result protocol by delegation:
``plot`` to its function of :mod:`qzs.viz.identify`, ``save`` to
:func:`qzs.iotools.result_files.save_by_extension` (``.json`` of :meth:`to_record`,
``.nc``/``.csv``/``.mat`` of :meth:`to_xarray`), ``to_xarray`` to
:func:`qzs.iotools.schema.to_dataset` of the fit's own schema. Its confidence intervals
are spelled once: ``intervals``, estimated name -> ``(low, high)`` at ``confidence``.
"""
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from qzs.iotools.result_files import save_by_extension, save_doc, suffixes_of

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.figure import Figure

__all__ = ["FitProtocol", "interval_attributes", "plot_doc",
           "FREQUENCY_SCALE_OPTION"]

_PLOT_DOC = """The fitted data and the fit, with the residuals (:mod:`qzs.viz.identify`).

        Parameters
        ----------
        path : str or Path, optional
            Write the figure there, atomically (format from the suffix; a .png also as .svg).
        title : str, optional
            Figure title; default none.{options}

        Returns
        -------
        matplotlib.figure.Figure
            Its axes labelled with their units.
        """
#: The option of a fit's figure with a frequency axis.
FREQUENCY_SCALE_OPTION = """
        frequency_scale : {"log", "linear"}, optional
            Frequency axis; default ``qzs.defaults.FIGURES["frequency_scale"]`` (log)."""


def plot_doc(options: str = "") -> str:
    """The docstring every fit's ``plot`` shares, with the figure's own options.

    Parameters
    ----------
    options : str
        Numpydoc entries of the options after ``title`` (e.g. :data:`FREQUENCY_SCALE_OPTION`).

    Returns
    -------
    str
    """
    return _PLOT_DOC.format(options=options)


def interval_attributes(fit: Any, units: Any) -> dict[str, Any]:
    """A fit's estimates and intervals as global attributes of its dataset.

    Parameters
    ----------
    fit : FitProtocol
        The fit (``estimates()``, ``intervals``, ``confidence``).
    units : callable
        Estimated name -> its unit.

    Returns
    -------
    dict
        ``<name>``, ``<name>_lower``, ``<name>_upper`` and ``<name>_units`` per estimate,
        and ``confidence_level``.
    """
    attrs: dict[str, Any] = {"confidence_level": float(fit.confidence)}
    for name, value in fit.estimates().items():
        attrs[name] = float(value)
        if name in fit.intervals:
            attrs[f"{name}_lower"], attrs[f"{name}_upper"] = map(float, fit.intervals[name])
        if units(name):
            attrs[f"{name}_units"] = units(name)
    return attrs


class FitProtocol:
    """The result protocol of a fit: ``summary``, ``plot``, ``save``, ``to_xarray``.

    A subclass (a frozen dataclass) names its figure function (``_figure``, in
    :mod:`qzs.viz.identify`) and defines ``summary``, ``to_record``, ``to_xarray`` and,
    without ``parameters``, ``estimates``; it has ``intervals`` (estimated name ->
    ``(low, high)``) and ``confidence`` (their level [-]).
    """

    #: The function of :mod:`qzs.viz.identify` that draws the fit.
    _figure = ""
    #: The extensions :meth:`save` accepts.
    save_suffixes = suffixes_of(dataset=True, record=True)

    def estimates(self) -> dict[str, float]:
        """The estimated values by name (those with an interval are the keys of
        ``intervals``): the fit's ``parameters`` unless it says otherwise.

        Returns
        -------
        dict of str to float
        """
        return dict(self.parameters)  # type: ignore[attr-defined]

    def to_record(self) -> dict[str, Any]:  # pragma: no cover - each fit defines it
        """The fit as plain data (what :meth:`save` writes as JSON)."""
        raise NotImplementedError

    def to_xarray(self) -> "xr.Dataset":  # pragma: no cover - each fit defines it
        """The fitted data as an ``xarray.Dataset`` (CF-1.10, units on every variable)."""
        raise NotImplementedError

    def _writers(self) -> dict[str, Callable[[Path], Path]]:
        """Writers of formats of the fit's own, by extension (none by default)."""
        return {}

    def plot(self, path: str | Path | None = None, *, title: str | None = None) -> "Figure":
        from qzs.viz import identify

        return getattr(identify, self._figure)(self, path=path, title=title or "")

    plot.__doc__ = plot_doc()

    def save(self, path: str | Path) -> Path:
        return save_by_extension(path, dataset=self.to_xarray, record=self.to_record,
                                 writers=self._writers())

    save.__doc__ = save_doc("``.json`` (:meth:`to_record`: the estimates, ``intervals``, "
                            "``confidence``, units, residual); ``.nc``, ``.csv``, ``.mat`` "
                            "(:meth:`to_xarray`: the fitted data [SI units], the estimates "
                            "and intervals as global attributes); a spring fit also ``.toml`` "
                            "(its law as a ``[spring]`` table)")
