"""The parameter registry: every model and excitation parameter's name, unit, doc and default.

One source, read by everything that names parameters: the command line's ``--set``
and ``qzs params``, TOML configs, sweeps, identification, and the metadata of saved
results. The parameters themselves are the fields of the frozen dataclasses
(:class:`~qzs.model.isolator.IsolatorParameters`,
:class:`~qzs.model.controller.ControllerParameters`, its blocks and the excitations), each
declared with its default, unit and one-line description; this module only reads
them.

A spring law's scalar parameters are ``spring.<field>`` (``spring.vertical_stiffness``,
``spring.center``) and a polynomial's coefficients ``spring.c<k>`` (:data:`SPRING_PARAMETERS`):
they change the isolator's own law (``IsolatorParameters.spring``), so a sweep or a design
may vary them; the MagSpring's tanh keeps its ``spring_force`` and ``spring_shape``.

A controller block's scalar parameters have dotted names, ``<block>.<field>``
(``compensation.fraction``, ``dither.frequency``, ``linear.tracking_time``:
:data:`BLOCK_PARAMETERS`); a linear controller's matrices, inputs and name are no
registry parameters (a controller file gives them, docs/model.md §5.1). Setting a block's
parameter on a controller without that block adds the block, with its defaults and the
change (:func:`update_parameters`).
"""
import dataclasses
import math
from dataclasses import dataclass
from types import MappingProxyType

from qzs.errors import ParameterError
from qzs.model.controller import (BLOCK_CLASSES, ControllerParameters, Dither,
                                  FrictionCompensation, LinearController)
from qzs.model.excitation import EXCITATION_KINDS, EXCITATION_OPTIONS, option_field
from qzs.model.isolator import IsolatorParameters
from qzs.model.springs import SPRING_LAWS, PolynomialSpring, TanhSpring

__all__ = ["ParameterInfo", "SECTIONS", "PARAMETERS", "BLOCK_PARAMETERS", "SPRING_PARAMETERS",
           "SPRING_POWERS", "ALL_PARAMETERS", "law_parameters", "check_law_parameters",
           "NO_BLOCK", "EXCITATION_PARAMETERS", "parameter_info", "model_inputs",
           "unit_of", "parameter_fields", "parameter_value", "dotted_names",
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
        The parameter's name (``stiction_force``, ``compensation.fraction``,
        ``excitation.f0``).
    section : str
        ``isolator``, ``controller`` (a block's parameters too) or ``excitation.<kind>``.
    unit : str
        SI unit (``N``, ``m``, ``Hz``; ``-`` for a choice, ``1`` for a count).
    doc : str
        One-line description.
    default : object
        Default value (``None`` where that has a meaning, e.g. ``stop_center``).
    numeric : bool
        True for a float parameter that takes any number in its range (fits vary these;
        a block's optional levels too: ``None`` there means the plant's).
    """

    name: str
    section: str
    unit: str
    doc: str
    default: object
    numeric: bool


def _info(section, field, name=None, numeric=(float, "float")):
    default = None if field.default is dataclasses.MISSING else field.default
    return ParameterInfo(name=name or field.name, section=section,
                         unit=field.metadata.get("unit", ""), doc=field.metadata.get("doc", ""),
                         default=default, numeric=field.type in numeric)


#: Model parameters: name -> :class:`ParameterInfo`, isolator first, then controller; the
#: fields of the two classes, not the controller's blocks (what the C model and the FMU
#: have as parameters).
PARAMETERS = MappingProxyType({
    f.name: _info(section, f) for section, cls in SECTIONS.items()
    for f in dataclasses.fields(cls) if not f.metadata.get("block")})
#: The types of a block's fields that are registry parameters (scalars).
_SCALARS = (float, float | None)
#: The controller blocks' scalar parameters: ``<block>.<field>`` -> :class:`ParameterInfo`
#: (section ``controller``; unit, doc and default from the block's field).
BLOCK_PARAMETERS = MappingProxyType({
    f"{block}.{f.name}": _info("controller", f, f"{block}.{f.name}", _SCALARS)
    for block, cls in BLOCK_CLASSES.items() for f in dataclasses.fields(cls)
    if f.type in _SCALARS})
#: The highest power ``k`` of a polynomial spring's coefficient ``spring.c<k>``.
SPRING_POWERS = 7
#: What ``spring.center`` is in each law that has one.
_CENTER_DOC = ("spring law's centre: the oblique springs horizontal, or the polynomial's powers "
               "taken about it")


def _spring_parameters():
    """``spring.<field>`` of every law's float fields but the tanh's (``spring_force`` and
    ``spring_shape`` are its), then ``spring.c0`` .. ``spring.c<SPRING_POWERS>``."""
    found = {}
    for cls in SPRING_LAWS.values():
        for f in dataclasses.fields(cls):
            name = f"spring.{f.name}"
            if cls is not TanhSpring and f.type is float and name not in found:
                info = _info("isolator", f, name)
                found[name] = dataclasses.replace(
                    info, default=None, doc=_CENTER_DOC if f.name == "center" else info.doc)
    for k in range(SPRING_POWERS + 1):
        unit = "N" if k == 0 else "N/m" if k == 1 else f"N/m^{k}"
        found[f"spring.c{k}"] = ParameterInfo(
            name=f"spring.c{k}", section="isolator", unit=unit, default=None, numeric=True,
            doc=f"polynomial spring's coefficient c_{k} of (z - center)^{k}")
    return found


#: A spring law's scalar parameters: ``spring.<field>`` -> :class:`ParameterInfo` (section
#: ``isolator``; default None: the value is the law's); each names a field of the laws that
#: have it, ``spring.c<k>`` a :class:`~qzs.model.springs.PolynomialSpring`'s coefficient.
SPRING_PARAMETERS = MappingProxyType(_spring_parameters())
#: Every registry parameter: :data:`PARAMETERS`, :data:`BLOCK_PARAMETERS`, then
#: :data:`SPRING_PARAMETERS`.
ALL_PARAMETERS = MappingProxyType({**PARAMETERS, **BLOCK_PARAMETERS, **SPRING_PARAMETERS})
#: What :func:`parameter_table` shows for a block's parameter of a controller without it.
NO_BLOCK = "no block"


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
    if name in ALL_PARAMETERS:
        return ALL_PARAMETERS[name]
    if name.startswith("excitation."):
        option = name.split(".", 1)[1]
        kinds = [kind] if kind is not None else list(EXCITATION_PARAMETERS)
        for k in kinds:
            if option in EXCITATION_PARAMETERS.get(k, ()):
                return _excitation_info(k, option)
    valid = sorted(ALL_PARAMETERS) + sorted({f"excitation.{o}"
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

    A controller's blocks (:data:`qzs.model.controller.BLOCKS`) are no fields here:
    :data:`BLOCK_PARAMETERS` has their scalar parameters and
    :func:`qzs.model.controller.block_parameters` lists all of theirs.

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

    A block's parameter (``compensation.fraction``: :data:`BLOCK_PARAMETERS`) changes that
    block; on a controller without the block it adds the block, with its defaults and the
    change (``compensation.fraction=0.8`` adds ``FrictionCompensation(fraction=0.8)``). A
    linear controller has no defaults to add: its matrices come from a controller file.

    Parameters
    ----------
    isolator : IsolatorParameters
        Plant parameters to start from.
    controller : ControllerParameters
        Controller parameters to start from.
    settings : dict
        Parameter names (``mass``, ``pi_kp``, ``dither.amplitude``, ...; see
        :data:`ALL_PARAMETERS`) to values in their SI units; string values are parsed
        (:func:`parse_value`, ``none`` for an optional value).

    Raises
    ------
    ParameterError
        For an unknown name (the message lists the valid ones) or an invalid value (naming
        the parameter as given: ``compensation.fraction``).
    """
    changes = {section: {} for section in SECTIONS}
    blocks, law = {}, {}
    for name, value in settings.items():
        if name not in ALL_PARAMETERS:
            raise ParameterError(f"unknown parameter {name!r}; valid names are: "
                                 f"{', '.join(sorted(ALL_PARAMETERS))}.")
        value = parse_value(value) if isinstance(value, str) else value
        if name in SPRING_PARAMETERS:
            law[name] = value
        elif name in BLOCK_PARAMETERS:
            block, field = name.split(".", 1)
            blocks.setdefault(block, {})[field] = value
        else:
            changes[PARAMETERS[name].section][name] = value
    for block, values in blocks.items():
        changes["controller"][block] = _changed_block(getattr(controller, block), block, values)
    if law:
        changes["isolator"]["spring"] = _changed_law(isolator.spring, law)
    return (dataclasses.replace(isolator, **changes["isolator"]),
            dataclasses.replace(controller, **changes["controller"]))


def _changed_block(current, block, values):
    """The block ``block`` (None: absent, then added with its defaults) with ``values``;
    an error names the parameters as ``block.field``."""
    spelling = {field.name: f"{block}.{field.name}"
                for field in dataclasses.fields(BLOCK_CLASSES[block])}
    try:
        if current is not None:
            return dataclasses.replace(current, **values)
        if block == "linear":
            raise ParameterError(
                f"{', '.join(f'`{spelling[name]}`' for name in values)} changes a linear "
                "controller, and this controller has none (a linear controller has no "
                "defaults: its matrices or transfer function are needed); give one in a "
                "controller file's [controller.linear] table (`qzs params --toml` shows one) "
                "and pass it with --config or --controller.",
                tuple(spelling[name] for name in values))
        return BLOCK_CLASSES[block](**values)
    except ParameterError as error:
        raise error.renamed(spelling) from None


def law_parameters(law):
    """The ``spring.*`` names (:data:`SPRING_PARAMETERS`) a spring law has.

    Parameters
    ----------
    law : SpringLaw or None
        An isolator's ``spring``; None or a TanhSpring (the MagSpring) has none.

    Returns
    -------
    tuple of str
        A polynomial's ``spring.center`` and ``spring.c<k>`` up to its degree (a higher
        power may still be set: :func:`check_law_parameters`); an oblique spring's six
        fields.
    """
    if law is None or isinstance(law, TanhSpring):
        return ()
    names = [f"spring.{f.name}" for f in dataclasses.fields(law)
             if f"spring.{f.name}" in SPRING_PARAMETERS]
    if isinstance(law, PolynomialSpring):
        names += [f"spring.c{k}" for k in range(min(law.coefficients.size, SPRING_POWERS + 1))]
    return tuple(names)


def check_law_parameters(law, names):
    """Refuse ``spring.*`` names ``law`` does not have, before any work.

    Parameters
    ----------
    law : SpringLaw or None
        The isolator's spring law (None: the MagSpring's tanh).
    names : sequence of str
        Names of :data:`SPRING_PARAMETERS` to be set or varied.

    Raises
    ------
    ParameterError
        The law is the tanh (it has no ``spring.*`` parameter), or a name is not one of its
        parameters; the error's ``options`` are the names, the message gives the fix.
    """
    names = tuple(names)
    if not names:
        return
    if law is None or isinstance(law, TanhSpring):
        raise ParameterError(
            f"{', '.join(f'`{n}`' for n in names)} changes a spring law's parameter, and this "
            "isolator's spring is the MagSpring's tanh (its parameters are `spring_force` and "
            "`spring_shape`); give the law first: a [spring] table (law = \"oblique\" or "
            "\"polynomial\", docs/model.md §3.1) in the config, sweep or problem file, "
            "`qzs simulate --spring FILE.toml`, or IsolatorParameters(spring=...).", names)
    own = law_parameters(law)
    if isinstance(law, PolynomialSpring):
        own += tuple(f"spring.c{k}" for k in range(law.coefficients.size, SPRING_POWERS + 1))
    foreign = [n for n in names if n not in own]
    if foreign:
        raise ParameterError(
            f"`{foreign[0]}` is no parameter of this {law.kind!r} spring law; its parameters "
            f"are {', '.join(own)}.", (foreign[0],))


def _changed_law(law, values):
    """``law`` with the ``spring.*`` parameters of ``values`` replaced (a polynomial's
    coefficients padded with zeros up to the highest power set)."""
    check_law_parameters(law, values)
    fields = {n.split(".", 1)[1]: v for n, v in values.items()
              if not (isinstance(law, PolynomialSpring) and n.startswith("spring.c")
                      and n[8:].isdigit())}
    powers = {int(n[8:]): v for n, v in values.items() if n.split(".", 1)[1] not in fields}
    if powers:
        coefficients = list(law.coefficients) + [0.0] * (max(powers) + 1 - law.coefficients.size)
        for k, value in powers.items():
            coefficients[k] = value
        fields["coefficients"] = coefficients
    try:
        return dataclasses.replace(law, **fields)
    except ParameterError as error:
        spelling = {f.name: f"spring.{f.name}" for f in dataclasses.fields(law)}
        if powers:
            spelling["coefficients"] = ", ".join(f"spring.c{k}" for k in sorted(powers))
        raise error.renamed(spelling) from None


def parameter_value(isolator, controller, name, absent=None):
    """The value of the registry parameter ``name`` in ``isolator`` and ``controller``.

    Parameters
    ----------
    isolator : IsolatorParameters
        Plant parameters.
    controller : ControllerParameters
        Controller parameters.
    name : str
        A name of :data:`ALL_PARAMETERS`.
    absent : object
        What a block's parameter is on a controller without that block, and a spring law's
        on an isolator whose law has no such parameter.

    Returns
    -------
    object
    """
    if name in SPRING_PARAMETERS:
        law = isolator.spring
        if name not in law_parameters(law):
            return absent
        if isinstance(law, PolynomialSpring) and name[8:].isdigit():
            return float(law.coefficients[int(name[8:])])
        return getattr(law, name.split(".", 1)[1])
    if name in BLOCK_PARAMETERS:
        block, field = name.split(".", 1)
        block = getattr(controller, block)
        return absent if block is None else getattr(block, field)
    return getattr(isolator if PARAMETERS[name].section == "isolator" else controller, name)


def dotted_names(table):
    """A TOML table of parameters by name with its dotted keys' tables made names again.

    TOML reads an unquoted dotted key (``compensation.fraction = 0.8``) as a nested table
    (``{"compensation": {"fraction": 0.8}}``); this gives back ``compensation.fraction``
    (and ``excitation.f0``), as a quoted key (``"compensation.fraction" = 0.8``) gives it.

    Parameters
    ----------
    table : object
        The table (anything else is returned as it is, for the caller to refuse).

    Returns
    -------
    dict or object
    """
    if not isinstance(table, dict):
        return table
    flat = {}
    for key, value in table.items():
        if key in (*BLOCK_CLASSES, "excitation", "spring") and isinstance(value, dict):
            flat.update({f"{key}.{inner}": item for inner, item in value.items()})
        else:
            flat[key] = value
    return flat


def parameter_table(isolator=None, controller=None):
    """Rows ``(section, name, value, unit, description)`` of every registry parameter.

    The blocks' parameters (:data:`BLOCK_PARAMETERS`) follow the others; where the
    controller has no such block, the value is :data:`NO_BLOCK`. Then the spring law's
    (:data:`SPRING_PARAMETERS`) the isolator's law has (a polynomial's coefficients up to its
    degree), none for the MagSpring's tanh.

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Values to show; defaults if omitted.
    controller : ControllerParameters, optional
        Values to show; defaults if omitted.
    """
    isolator = isolator or IsolatorParameters()
    controller = controller or ControllerParameters()
    shown = law_parameters(isolator.spring)
    return [(info.section, name, parameter_value(isolator, controller, name, NO_BLOCK),
             info.unit, info.doc) for name, info in ALL_PARAMETERS.items()
            if name not in SPRING_PARAMETERS or name in shown]


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
