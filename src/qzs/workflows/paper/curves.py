"""The curves behind a figure, as data: one dataset per study, written as NetCDF and CSV.

``qzs paper``, ``qzs study`` and ``qzs design`` draw transmissibility curves; each also
writes them beside its figures, through :func:`curves_dataset` and
:func:`qzs.iotools.writer.write_dataset`:

``<name>_curves.nc``
    CF-1.10, dimensions ``case`` and ``frequency``: ``magnitude`` [1], ``phase`` [rad],
    ``coherence`` [1], the ``trusted`` flag (docs/model.md §10) and the linearised model's
    ``linear_magnitude`` [1]; coordinates ``case`` (the label of the figure's legend),
    ``frequency`` [Hz] and every parameter the cases set, on ``case``, with its unit from
    :mod:`qzs.model.registry`.
``<name>_curves.csv``
    The same in long format (one row per case and frequency) with the units row of
    :data:`qzs.iotools.writer.CSV_LAYOUT`: ``pandas.read_csv(path, comment="#",
    header=[0, 1])``.

Curves of one file share their frequency bins; bins a curve lacks are NaN (untrusted).
The spring's characteristic (paper Fig. 5) is written the same way by :func:`spring_dataset`:
the measured points and the fitted law on ``point``.
"""
import numpy as np

from qzs.iotools.schema import Schema, Variable, to_dataset
from qzs.iotools.writer import write_dataset
from qzs.model.registry import ALL_PARAMETERS, unit_of

__all__ = ["law_dataset", "curves_schema", "curves_dataset", "spring_schema", "spring_dataset",
           "write_curves", "case_value", "figure_curves", "case_curves", "study_dataset",
           "case_dataset", "spring_curves", "CURVE_SUFFIXES"]

#: The files :func:`write_curves` writes, by suffix.
CURVE_SUFFIXES = (".nc", ".csv", ".mat")
_ON = ("case", "frequency")


def curves_schema(parameters, cases, bins):
    """The CF-1.10 layout of a study's curves (the module docstring).

    Parameters
    ----------
    parameters : mapping of str to tuple
        The parameters the cases set -> ``(unit, description, dtype)`` (dtype "float64" or
        "str"): coordinates on ``case``.
    cases : int
        Number of curves.
    bins : int
        Number of frequency bins.

    Returns
    -------
    Schema
    """
    coordinates = [Variable(name="case", dims=("case",), dtype="str",
                            long_name="the curve's label in the figure"),
                   Variable(name="frequency", dims=("frequency",), units="Hz",
                            long_name="frequency")]
    for name, (unit, doc, dtype) in parameters.items():
        coordinates.append(Variable(name=name, dims=("case",), units=unit, long_name=doc,
                                    dtype=dtype))
    variables = (
        Variable(name="magnitude", dims=_ON, units="1",
                 long_name="transmissibility, amplitude ratio sqrt(S_payload / S_base)"),
        Variable(name="phase", dims=_ON, units="rad",
                 long_name="phase of payload relative to base (of the cross spectrum)"),
        Variable(name="coherence", dims=_ON, units="1", long_name="magnitude-squared coherence"),
        Variable(name="trusted", dims=_ON, units="1", dtype="int8",
                 flag_meanings="untrusted trusted",
                 long_name="1 where the bin is trusted (docs/model.md section 10)"),
        Variable(name="linear_magnitude", dims=_ON, units="1",
                 long_name="transmissibility of the linearised model (NaN: not drawn)"))
    return Schema(kind="the curves of a figure", dimensions={"case": int(cases), "frequency": bins},
                  coordinates=tuple(coordinates), variables=variables)


def _parameter_info(name, units, values):
    """``(unit, description, dtype)`` of a parameter: the registry's, or ``units``'."""
    numeric = all(isinstance(v, (int, float, np.number)) for v in values if v is not None)
    dtype = "float64" if numeric else "str"
    if name in units:
        return (*units[name], dtype)
    info = ALL_PARAMETERS.get(name)
    return (unit_of(name), info.doc if info is not None else name, dtype)


def curves_dataset(curves, attrs=None, *, units=None):
    """A dataset of transmissibility curves on one frequency axis (:func:`curves_schema`).

    Parameters
    ----------
    curves : sequence of dict
        One per case, as the figure draws them: ``label``, ``frequency`` [Hz],
        ``magnitude`` [-], and optionally ``phase`` [rad], ``coherence`` [-], ``trusted``
        (bool per bin; default all above 0 Hz), ``linear`` (the linearised model's
        magnitude [-]) and ``parameters`` (name -> value: the case's parameters).
    attrs : mapping, optional
        Global attributes (title, study, run settings with ``<key>_units``).
    units : mapping of str to (str, str), optional
        ``(unit, description)`` of parameters that are not in the registry.

    Returns
    -------
    xarray.Dataset
    """
    units = dict(units or {})
    frequency = np.unique(np.concatenate([np.asarray(c["frequency"], float) for c in curves]))
    names = list(dict.fromkeys(k for c in curves for k in c.get("parameters", {})))
    parameters = {name: _parameter_info(name, units, [c.get("parameters", {}).get(name)
                                                      for c in curves]) for name in names}
    n, m = len(curves), frequency.size
    values = {name: np.full((n, m), np.nan) for name in
              ("magnitude", "phase", "coherence", "linear_magnitude")}
    values["trusted"] = np.zeros((n, m), bool)
    for i, curve in enumerate(curves):
        f = np.asarray(curve["frequency"], float)
        at = np.searchsorted(frequency, f)
        trusted = curve.get("trusted")
        values["trusted"][i, at] = f > 0 if trusted is None else np.asarray(trusted, bool)
        for name, key in (("magnitude", "magnitude"), ("phase", "phase"),
                          ("coherence", "coherence"), ("linear_magnitude", "linear")):
            if curve.get(key) is not None:
                values[name][i, at] = np.asarray(curve[key], float)
    values["case"] = [str(c["label"]) for c in curves]
    values["frequency"] = frequency
    for name in names:
        given = [c.get("parameters", {}).get(name) for c in curves]
        values[name] = ([np.nan if v is None else float(v) for v in given]
                        if parameters[name][2] == "float64" else [str(v) for v in given])
    return to_dataset(curves_schema(parameters, n, m), values, attrs)


def write_curves(dataset, folder, name):
    """Write a curves dataset as ``<name>_curves.nc`` and ``<name>_curves.csv``, atomically.

    Parameters
    ----------
    dataset : xarray.Dataset
        The curves (:func:`curves_dataset`).
    folder : str or Path
        The output folder (the figures').
    name : str
        The files' stem before ``_curves``: the study's or the figure's name.

    Returns
    -------
    list of Path
        The files written, in the order of :data:`CURVE_SUFFIXES`.
    """
    from pathlib import Path

    return [write_dataset(dataset, Path(folder) / f"{name}_curves{suffix}")
            for suffix in CURVE_SUFFIXES]


def spring_schema(points, law=None):
    """The CF-1.10 layout of the spring's characteristic: the points and the fitted law.

    Parameters
    ----------
    points : int
        Number of measured points.
    law : str, optional
        The fitted law's kind (``"polynomial"``, ...); default the MagSpring's tanh.

    Returns
    -------
    Schema
    """
    on = ("point",)
    spring, fitted = (("the MagSpring", "-a tanh(b z)") if law is None
                      else ("the spring", f"{law}"))
    return Schema(kind="the spring's characteristic", dimensions={"point": int(points)},
                  coordinates=(Variable(name="displacement", dims=on, units="m",
                                        long_name=f"displacement z of {spring}"),),
                  variables=(Variable(name="force", dims=on, units="N",
                                      long_name="measured spring force"),
                             Variable(name="fitted_force", dims=on, units="N",
                                      long_name=f"fitted law {fitted} at the points")))


def law_dataset(displacement, force, fitted_force, parameters, attrs=None, law=None):
    """A spring law's measured characteristic and its fitted law (docs/model.md §3.1).

    As :func:`spring_dataset`, the fitted force given and the fit's parameters as
    attributes ``spring_<name>`` with their ``_units`` (CF attribute names: no dots).

    Parameters
    ----------
    displacement : array_like
        Displacements of the points [m].
    force : array_like
        Measured forces [N].
    fitted_force : array_like
        The fitted law's force at ``displacement`` [N].
    parameters : dict
        The fit: name -> ``(value, unit)`` (``kind`` first, unit ``-``).
    attrs : dict, optional
        Further global attributes.
    law : str, optional
        The fitted law's kind, for the labels (:func:`spring_schema`); default the tanh.

    Returns
    -------
    xarray.Dataset
    """
    z = np.asarray(displacement, dtype=float)
    meta = {}
    for name, (value, unit) in parameters.items():
        meta[f"spring_{name}"] = value
        meta[f"spring_{name}_units"] = unit
    return to_dataset(spring_schema(z.size, law), {"displacement": z, "force": force,
                                                    "fitted_force": fitted_force},
                      {**(attrs or {}), **meta})


def spring_dataset(displacement, force, spring_force, spring_shape, attrs=None):
    """The spring's measured characteristic and its fitted tanh law, as a dataset.

    Parameters
    ----------
    displacement : array_like
        Displacements of the points [m].
    force : array_like
        Measured forces [N].
    spring_force : float
        Fitted force amplitude a [N].
    spring_shape : float
        Fitted shape b [1/m].
    attrs : mapping, optional
        Further global attributes.

    Returns
    -------
    xarray.Dataset
        With the fit as attributes ``spring_force`` [N] and ``spring_shape`` [1/m].
    """
    import dataclasses

    from qzs.model.isolator import IsolatorParameters, spring_force as law

    z = np.asarray(displacement, dtype=float)
    fitted = law(z, dataclasses.replace(IsolatorParameters(), spring_force=spring_force,
                                        spring_shape=spring_shape))
    return law_dataset(z, force, fitted, {  # attributes spring_force, spring_shape
        "force": (float(spring_force), unit_of("spring_force")),
        "shape": (float(spring_shape), unit_of("spring_shape"))}, attrs)


def case_value(case, name):
    """A case's value of model parameter ``name``: its override, else the default.

    Parameters
    ----------
    case : CaseResult
        The case.
    name : str
        A model parameter's registry name.

    Returns
    -------
    float
    """
    return case.settings.get(name, ALL_PARAMETERS[name].default)


def figure_curves(result):
    """The curves a study's figures draw, each with its case's ``parameters`` and ``phase``.

    Parameters
    ----------
    result : StudyResult
        A study.

    Returns
    -------
    list of dict
    """
    cases = result.cases
    names = list(dict.fromkeys(k for c in cases for k in c.settings))
    if result.study.kind == "processing":
        return case_curves(cases[0], names)
    return [curve for case in cases for curve in case_curves(case, names)]


def case_curves(case, names=None):
    """The curves of one case as the figures draw them: its own and, processed like the
    experiment (a ``processing`` study's), the experiment-style one.

    Parameters
    ----------
    case : CaseResult
        A simulated case.
    names : sequence of str, optional
        The parameters each curve carries; default the case's own settings.

    Returns
    -------
    list of dict
    """
    parameters = {name: case_value(case, name)
                  for name in (case.settings if names is None else names)}
    if "highpass" in case.extra:  # processed like the experiment
        return [dict(label=f"ideal: accelerations, {case.stats['n_averages']} averages",
                     frequency=case.frequency, magnitude=case.magnitude, trusted=case.trusted,
                     coherence=case.coherence, linear=case.linear.get("magnitude"),
                     phase=case.phase, parameters=parameters),
                dict(label=f"experiment-style: velocities through the "
                           f"{case.extra['highpass']:g} Hz high-pass, "
                           f"{case.extra['n_averages']} averages",
                     frequency=case.extra["frequency"], magnitude=case.extra["magnitude"],
                     trusted=case.extra.get("trusted"), coherence=case.extra.get("coherence"),
                     phase=case.extra.get("phase"), parameters=parameters)]
    return [dict(label=case.label, frequency=case.frequency, magnitude=case.magnitude,
                 trusted=case.trusted, coherence=case.coherence,
                 linear=case.linear.get("magnitude"), phase=case.phase, parameters=parameters)]


def _run_attributes(attrs, settings, run_units):
    """``attrs`` with the run settings and their ``<key>_units`` (values joined if several)."""
    from qzs.model.registry import format_value

    for key, value in settings.items():
        attrs[key] = (", ".join(format_value(v) for v in value) if isinstance(value, list)
                      else value)
        if run_units.get(key):
            attrs[f"{key}_units"] = run_units[key]
    return attrs


def study_dataset(result, *, quick, run_units):
    """A study's curves as a dataset (:func:`curves_dataset`): ``<study>_curves.nc``.

    The curves its figures draw (:func:`figure_curves`), on ``case`` and ``frequency``, with
    each case's parameters as coordinates and the run settings, study and definition as
    attributes; for the spring's characteristic, its points and fitted law
    (:func:`spring_curves`).

    Parameters
    ----------
    result : StudyResult
        A study.
    quick : bool
        Whether the runs were the quick ones (an attribute).
    run_units : mapping of str to str
        The unit of each run setting (:data:`qzs.workflows.paper.cases.RUN_UNITS`).

    Returns
    -------
    xarray.Dataset
    """
    from pathlib import Path

    from qzs._version import __version__
    from qzs.workflows.findings.tables import run_settings

    attrs = {"title": result.study.title, "study": result.study.name,
             "definition": Path(result.study.source).name if result.study.source else "",
             "quick": int(bool(quick)), "source": f"qzs {__version__} (qzs paper / qzs study)"}
    if result.study.kind == "spring_characteristic":
        return spring_curves(result.cases[0], attrs)
    return curves_dataset(figure_curves(result),
                          _run_attributes(attrs, run_settings(result), run_units))


def case_dataset(case, run_units):
    """One case's curves (:func:`case_curves`) as a curves dataset with its run settings, or
    a spring case's points and fitted law (:func:`study_dataset`'s layouts).

    Parameters
    ----------
    case : CaseResult
        The case.
    run_units : mapping of str to str
        The unit of each run setting (:data:`qzs.workflows.paper.cases.RUN_UNITS`).

    Returns
    -------
    xarray.Dataset
    """
    from qzs._version import __version__

    attrs = {"title": case.label, "source": f"qzs {__version__} (a case of qzs paper / qzs "
                                            "study)"}
    if case.frequency is None:
        return spring_curves(case, attrs)
    return curves_dataset(case_curves(case), _run_attributes(attrs, dict(case.run), run_units))


def spring_curves(case, attrs):
    """The spring study's points and fitted law as a dataset (``spring_curves.nc``).

    Parameters
    ----------
    case : CaseResult
        The spring study's case.
    attrs : dict
        Global attributes.

    Returns
    -------
    xarray.Dataset
    """
    extra = case.extra
    if "law_fit" in extra:
        fit = extra["law_fit"]
        fitted = {"kind": (fit.kind, "-"), **{name: (value, fit.units.get(name, ""))
                                             for name, value in fit.parameters.items()}}
        return law_dataset(fit.displacement, fit.force, fit.predict(fit.displacement), fitted,
                           attrs, law=fit.kind)
    return spring_dataset(extra["displacement"], extra["force"], extra["fit"]["spring_force"],
                          extra["fit"]["spring_shape"], attrs)
