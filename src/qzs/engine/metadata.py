"""A run's metadata: every parameter and run setting with its unit, the history line,
and the global attributes of its file.

:func:`parameter_metadata` and :func:`run_metadata` give ``{key: (value, unit)}``;
:func:`file_attributes` makes the file's CF global attributes of them (the part known before
the run and the part known after it); :func:`history_line` is the CF ``history``.
"""
from __future__ import annotations

import dataclasses
import datetime
import os
import shlex
import sys

import numpy as np

from qzs._format import STEP_RECORD_UNITS
from qzs.iotools.schema import CONVENTIONS, NONE_VALUE
from qzs.model.controller import block_parameters
from qzs.model.registry import parameter_fields, unit_of

__all__ = ["RUN_UNITS", "parameter_metadata", "controller_from_attributes", "run_metadata",
           "history_line", "file_attributes"]

#: Units of the entries of :attr:`SimulationResult.run` ("1" for counts and 0/1 booleans,
#: "-" for a choice).
RUN_UNITS = {"solver": "-", "dt": "s", "sample_rate": "Hz", "duration": "s", "steps": "1",
             "elapsed": "s", "completed": "1", "stop_contacts": "1", "stick_events": "1",
             "stop_low": "m", "stop_high": "m", "samples": "1", "preview_every": "1",
             **{key: unit or "-" for key, unit in STEP_RECORD_UNITS.items()}}


def _plain(value):
    if isinstance(value, (bool, np.bool_)):
        return int(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating):
        return float(value)
    return value


def parameter_metadata(isolator, controller, excitation):
    """Every parameter of a run with its unit: ``{key: (value, unit)}``.

    Keys are ``isolator.<name>`` (a spring law's ``isolator.spring.law`` and its fields,
    :meth:`~qzs.model.springs.SpringLaw.parameters`), ``controller.<name>``, ``excitation``
    (the class
    name, no unit) and ``excitation.<field>``; units come from the parameter
    registry and the excitation's field metadata. ``None`` values are kept,
    booleans become 0/1; a displacement record's arrays are data, not metadata.

    Parameters
    ----------
    isolator : IsolatorParameters
        Plant parameters.
    controller : ControllerParameters
        Controller parameters.
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        Base excitation.

    Returns
    -------
    dict of str to (object, str)
    """
    meta = {}
    for section, params in (("isolator", isolator), ("controller", controller)):
        for field in parameter_fields(params):
            meta[f"{section}.{field.name}"] = (_plain(getattr(params, field.name)),
                                               unit_of(field.name))
    if isolator.spring is not None:  # the spring law, as the controller's blocks
        for name, (value, unit) in isolator.spring.parameters().items():
            meta[f"isolator.spring.{name}"] = (_plain(value), unit)
    for name, (value, unit) in block_parameters(controller).items():
        meta[f"controller.{name}"] = (_plain(value), unit)
    meta["excitation"] = (type(excitation).__name__, "")
    for field in dataclasses.fields(excitation):
        value = getattr(excitation, field.name)
        if not isinstance(value, np.ndarray):
            meta[f"excitation.{field.name}"] = (_plain(value), field.metadata.get("unit", ""))
    if "excitation.duration" not in meta and getattr(excitation, "duration", None) is not None:
        meta["excitation.duration"] = (float(excitation.duration), "s")
    return meta


def controller_from_attributes(attrs):
    """The controller a result's attributes record (the inverse of :func:`parameter_metadata`
    for ``controller.*``), its blocks included.

    Parameters
    ----------
    attrs : mapping
        Dotted attributes as :func:`qzs.read_result` gives them (``controller.pi_kp``,
        ``controller.linear.a``: a linear controller's matrices flattened row by row, their
        shapes from ``controller.linear.states`` and the sensors in
        ``controller.linear.inputs``); a list may be its text (``"[1.0, 2.0]"``: CSV).
        A parameter left out takes its default.

    Returns
    -------
    ControllerParameters

    Raises
    ------
    DataError
        Attributes that make no controller (the message names the attribute).
    """
    import json

    from qzs.errors import DataError, ParameterError
    from qzs.model.controller import BLOCK_CLASSES, ControllerParameters

    def plain(value):
        if isinstance(value, str) and value.startswith("["):
            return json.loads(value)
        if isinstance(value, np.ndarray):
            return value.tolist()
        return value.item() if isinstance(value, np.generic) else value

    values = {key[len("controller."):]: plain(value) for key, value in attrs.items()
              if key.startswith("controller.") and not key.endswith("_units")}
    try:
        loops = {f.name: values[f.name] for f in parameter_fields(ControllerParameters())
                 if f.name in values}
        blocks = {}
        for block, cls in BLOCK_CLASSES.items():
            fields = {key.split(".", 1)[1]: value for key, value in values.items()
                      if key.startswith(f"{block}.")}
            if not fields:
                continue
            if block == "linear":
                n = int(fields.pop("states"))
                inputs = str(fields["inputs"]).split()
                fields["inputs"] = tuple(inputs)
                for name, shape in (("a", (n, n)), ("b", (n, len(inputs))), ("c", (n,)),
                                    ("d", (len(inputs),))):
                    matrix = fields[name] if fields[name] is not None else []  # MAT: [] is None
                    fields[name] = np.reshape(np.asarray(matrix, dtype=float), shape)
                fields["name"] = str(fields["name"])
            blocks[block] = cls(**fields)
        return ControllerParameters(**loops, **blocks)
    except (ParameterError, KeyError, TypeError, ValueError) as error:
        raise DataError(f"the attributes make no controller ({error}); was the file written "
                        "by qzs?") from None


def run_metadata(run):
    """The run's settings and outcome with units: ``{"run.<key>": (value, unit)}``.

    Parameters
    ----------
    run : dict
        :attr:`SimulationResult.run`; counts stay integers, booleans become 0/1.

    Returns
    -------
    dict of str to (object, str)
    """
    return {f"run.{k}": (_plain(v), RUN_UNITS.get(k, "")) for k, v in run.items()}


def _now():
    return datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0).isoformat()


def history_line(excitation, run):
    """One CF ``history`` line: ISO time, qzs version, command and what was run.

    Parameters
    ----------
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        Base excitation of the run.
    run : dict
        :attr:`SimulationResult.run`.

    Returns
    -------
    str
    """
    from qzs._version import __version__

    program = os.path.basename(sys.argv[0]) if sys.argv and sys.argv[0] else ""
    if program == "qzs" or sys.argv[0].endswith(os.path.join("qzs", "__main__.py")):
        command = shlex.join(["qzs", *sys.argv[1:]])
    else:
        command = "qzs.simulate (Python)"
    state = "" if run.get("completed", True) else ", interrupted"
    return (f"{_now()} qzs {__version__}: {command}; {type(excitation).__name__} base "
            f"excitation, solver {run.get('solver')}, dt {run.get('dt')} s, "
            f"{run.get('steps')} steps{state}")


def _storable(meta):
    """NetCDF global attributes from ``{key: (value, unit)}``: values, ``<key>_units``,
    ``None`` as :data:`NONE_VALUE` listed in ``none_parameters``."""
    attrs, none = {}, []
    for key, (value, unit) in meta.items():
        if value is None:
            value = NONE_VALUE
            none.append(key)
        attrs[key] = value
        if unit:
            attrs[f"{key}_units"] = unit
    return attrs, none


def file_attributes(isolator, controller, excitation, run, history=None):
    """The global attributes of a result file (CF-1.10 and every parameter with its unit).

    Split in two: ``(head, tail)``, the part known before the run (conventions,
    title, source, parameters) and the part known after it (``run.*``, ``history``).

    Parameters
    ----------
    isolator : IsolatorParameters
        Plant parameters.
    controller : ControllerParameters
        Controller parameters.
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        Base excitation.
    run : dict or None
        :attr:`SimulationResult.run`; None for the head only (``tail`` is then empty).
    history : str, optional
        The ``history`` line; default :func:`history_line`.

    Returns
    -------
    (dict, dict)
    """
    from qzs._version import __version__

    params, none = _storable(parameter_metadata(isolator, controller, excitation))
    head = {"Conventions": CONVENTIONS,
            "title": f"qzs simulation of the semi-active QZS isolator under a "
                     f"{type(excitation).__name__} base excitation",
            "source": f"qzs {__version__}: fixed-step simulation of the semi-active "
                      "quasi-zero-stiffness isolator (model: docs/model.md)",
            "references": "Leav, Eriksson, Cazzolato, Robertson, Ding: A novel semi-active "
                          "quasi-zero stiffness vibration isolation system using a "
                          "constant-force magnetic spring and an electromagnetic linear motor",
            "comment": "parameters are global attributes '<section>.<name>' in SI units, "
                       "each with its unit in '<section>.<name>_units'",
            "qzs_version": __version__}
    head.update(params)
    if none:
        head["none_parameters"] = " ".join(none)
    if run is None:
        return head, {}
    tail, _ = _storable(run_metadata(run))
    tail["history"] = history if history is not None else history_line(excitation, run)
    return head, tail
