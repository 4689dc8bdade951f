"""The parameter registry: every model and excitation parameter's name, unit, doc and default.

One source, read by everything that names parameters: the command line's ``--set``
and ``qzs params``, TOML configs, sweeps, identification, and the metadata of saved
results. The parameters themselves are the fields of the frozen dataclasses
(:class:`~qzs.model.isolator.IsolatorParameters`,
:class:`~qzs.model.controller.ControllerParameters` and the excitations), each
declared with its default, unit and one-line description; this module only reads
them.
"""
import dataclasses
import math
from dataclasses import dataclass
from types import MappingProxyType

from qzs.errors import ParameterError
from qzs.model.controller import (ControllerParameters, Dither, FrictionCompensation,
                                  LinearController)
from qzs.model.excitation import EXCITATION_KINDS, EXCITATION_OPTIONS, option_field
from qzs.model.isolator import IsolatorParameters

__all__ = ["ParameterInfo", "SECTIONS", "PARAMETERS", "EXCITATION_PARAMETERS", "parameter_info",
           "model_inputs",
           "unit_of", "parameter_fields",
           "numeric_parameters", "update_parameters", "parameter_table", "parse_value",
           "format_value"]

#: Sections of the model parameters: config table name -> dataclass.
SECTIONS = MappingProxyType({"isolator": IsolatorParameters,
                             "controller": ControllerParameters})


@dataclass(frozen=True, kw_only=True)
class ParameterInfo:
    """What the registry knows of one parameter.

    Attributes
    ----------
    name : str
        The parameter's name (``stiction_force``, ``excitation.f0``).
    section : str
        ``isolator``, ``controller`` or ``excitation.<kind>``.
    unit : str
        SI unit (``N``, ``m``, ``Hz``; ``-`` for a choice, ``1`` for a count).
    doc : str
        One-line description.
    default : object
        Default value (``None`` where that has a meaning, e.g. ``stop_center``).
    numeric : bool
        True for a float parameter that takes any number in its range (fits vary these).
    """

    name: str
    section: str
    unit: str
    doc: str
    default: object
    numeric: bool


def _info(section, field, name=None):
    default = None if field.default is dataclasses.MISSING else field.default
    return ParameterInfo(name=name or field.name, section=section,
                         unit=field.metadata.get("unit", ""), doc=field.metadata.get("doc", ""),
                         default=default, numeric=field.type in (float, "float"))


#: Model parameters: name -> :class:`ParameterInfo`, isolator first, then controller.
PARAMETERS = MappingProxyType({
    f.name: _info(section, f) for section, cls in SECTIONS.items()
    for f in dataclasses.fields(cls) if not f.metadata.get("block")})


#: Excitation parameters by kind: the factory's options, and the run's duration where the
#: kind has no duration of its own (a sine runs as long as the run).
EXCITATION_PARAMETERS = MappingProxyType({
    kind: (*options, *(() if "duration" in options else ("duration",)))
    for kind, options in EXCITATION_OPTIONS.items()})
# What an option that is no field of its class means: (unit, description).
_RUN_OPTIONS = {"duration": ("s", "run duration"),
                "record": ("", "CSV file of time [s] and displacement [m]")}


def _excitation_info(kind, option):
    fields = {f.name: f for f in dataclasses.fields(EXCITATION_KINDS[kind])}
    field = fields.get(option_field(kind, option))
    if field is not None:
        return _info(f"excitation.{kind}", field, name=f"excitation.{option}")
    unit, doc = _RUN_OPTIONS[option]
    return ParameterInfo(name=f"excitation.{option}", section=f"excitation.{kind}", unit=unit,
                         doc=doc, default=None, numeric=option == "duration")


def parameter_info(name, kind=None):
    """The :class:`ParameterInfo` of a model parameter or of ``excitation.<option>``.

    Parameters
    ----------
    name : str
        A model parameter (``pi_kp``) or an excitation option (``excitation.f0``).
    kind : str, optional
        Excitation kind for ``excitation.<option>`` (default: the first kind that
        has the option).

    Raises
    ------
    ParameterError
        Unknown name; the message lists the valid ones.
    """
    if name in PARAMETERS:
        return PARAMETERS[name]
    if name.startswith("excitation."):
        option = name.split(".", 1)[1]
        kinds = [kind] if kind is not None else list(EXCITATION_PARAMETERS)
        for k in kinds:
            if option in EXCITATION_PARAMETERS.get(k, ()):
                return _excitation_info(k, option)
    valid = sorted(PARAMETERS) + sorted({f"excitation.{o}"
                                         for v in EXCITATION_PARAMETERS.values() for o in v})
    raise ParameterError(f"unknown parameter {name!r}; valid names are: {', '.join(valid)}.")


def unit_of(name, kind=None):
    """SI unit [string] of a model parameter or of ``excitation.<option>`` (see :func:`parameter_info`).

    Parameters
    ----------
    name : str
        Parameter name.
    kind : str, optional
        Excitation kind, for excitation options.
    """
    return parameter_info(name, kind).unit


def parameter_fields(params):
    """The registry parameters of an isolator's or a controller's fields, in field order.

    A controller's blocks (:data:`qzs.model.controller.BLOCKS`) are no parameters of the
    registry: :func:`qzs.model.controller.block_parameters` lists theirs.

    Parameters
    ----------
    params : IsolatorParameters or ControllerParameters
        The values.

    Returns
    -------
    list of dataclasses.Field
    """
    return [field for field in dataclasses.fields(params) if not field.metadata.get("block")]


def numeric_parameters():
    """Names of the float model parameters (those a fit or a sweep may vary continuously)."""
    return tuple(name for name, info in PARAMETERS.items() if info.numeric)


def update_parameters(isolator, controller, settings):
    """Return ``(isolator, controller)`` with the named parameters replaced.

    Parameters
    ----------
    isolator : IsolatorParameters
        Plant parameters to start from.
    controller : ControllerParameters
        Controller parameters to start from.
    settings : dict
        Parameter names (``mass``, ``pi_kp``, ...; see :data:`PARAMETERS`) to values in
        their SI units; string values are parsed (:func:`parse_value`, ``none`` for
        an optional value).

    Raises
    ------
    ParameterError
        For an unknown name (the message lists the valid ones) or an invalid value.
    """
    changes = {section: {} for section in SECTIONS}
    for name, value in settings.items():
        if name not in PARAMETERS:
            raise ParameterError(f"unknown parameter {name!r}; valid names are: "
                                 f"{', '.join(sorted(PARAMETERS))}.")
        changes[PARAMETERS[name].section][name] = (parse_value(value) if isinstance(value, str)
                                                   else value)
    return (dataclasses.replace(isolator, **changes["isolator"]),
            dataclasses.replace(controller, **changes["controller"]))


def parameter_table(isolator=None, controller=None):
    """Rows ``(section, name, value, unit, description)`` of every model parameter.

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Values to show; defaults if omitted.
    controller : ControllerParameters, optional
        Values to show; defaults if omitted.
    """
    objects = {"isolator": isolator or IsolatorParameters(),
               "controller": controller or ControllerParameters()}
    return [(info.section, name, getattr(objects[info.section], name), info.unit, info.doc)
            for name, info in PARAMETERS.items()]


def parse_value(text):
    """Parse a ``--set`` or header value: number, none, true/false, else the string.

    Parameters
    ----------
    text : str
        The value as typed (``5``, ``1e-3``, ``none``, ``plastic``).
    """
    lowered = text.strip().lower()
    if lowered in ("none", "null"):
        return None
    if lowered in ("true", "false"):
        return lowered == "true"
    try:
        number = float(text)
    except ValueError:
        return text.strip()
    return int(number) if number.is_integer() and "." not in text and "e" not in lowered else number


def format_value(value):
    """Human-readable parameter value: ``none``, ``%g`` for floats, else ``str``.

    Parameters
    ----------
    value : object
        A parameter value.
    """
    if value is None:
        return "none"
    if isinstance(value, float) and math.isfinite(value):
        return f"{value:g}"
    return str(value)


def model_inputs(isolator=None, controller=None):
    """The plant and loops of a computation, Table 1's and the default loops for None.

    The one place every API function puts in these defaults and checks their types.

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; default Table 1.
    controller : ControllerParameters, optional
        PI and damping loops; default the defaults.

    Returns
    -------
    isolator, controller

    Raises
    ------
    ParameterError
        An argument of another type (names it and what it got).
    """
    isolator = IsolatorParameters() if isolator is None else isolator
    controller = ControllerParameters() if controller is None else controller
    for name, value, kind in (("isolator", isolator, IsolatorParameters),
                              ("controller", controller, ControllerParameters)):
        if not isinstance(value, kind):
            fix = ""
            if name == "controller" and isinstance(value, (FrictionCompensation, Dither,
                                                           LinearController)):
                fix = (f"; a {type(value).__name__} is a block: add it to a controller, "
                       f"PIDamping() + {type(value).__name__}(...) (PIDamping(pi_kp=0, "
                       "pi_ki=0) for no position loop)")
            raise ParameterError(f"`{name}` must be a {kind.__name__}, got "
                                 f"{type(value).__name__}{fix}.", (name,))
    return isolator, controller
