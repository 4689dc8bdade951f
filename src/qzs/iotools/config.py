"""Run configuration files (TOML): model parameters, excitation and simulation tables."""
import dataclasses
from pathlib import Path
from typing import Any

from qzs._validation import known_keys, read_toml
from qzs.errors import ParameterError
from qzs.iotools.files import atomic_path
from qzs.model.controller import (BLOCK_CLASSES, BLOCKS, ControllerParameters,
                                  LinearController)
from qzs.model.excitation import EXCITATION_OPTIONS
from qzs.model.isolator import IsolatorParameters
from qzs.model.registry import PARAMETERS, update_parameters
from qzs.model.springs import SPRING_LAWS, ObliqueSpringQZS, TabulatedSpring

__all__ = ["load_config", "load_controller", "load_spring", "controller_from_table",
           "spring_from_table", "save_config", "config_text", "spring_text", "EXCITATION_KEYS",
           "SIMULATION_KEYS", "LINEAR_KEYS", "SPRING_CSV_KEYS"]

#: Keys allowed in the ``[excitation]`` and ``[simulation]`` tables of a config file.
EXCITATION_KEYS = ("kind", *dict.fromkeys(o for v in EXCITATION_OPTIONS.values() for o in v))
SIMULATION_KEYS = ("dt", "sample_rate", "solver", "duration")
#: The fix of an empty config file.
EMPTY_CONFIG = ("write the parameters to change into it (`qzs params --toml > FILE.toml` writes "
                "every one with its default), or give no config file for the defaults")


#: Keys of a ``[controller.linear]`` table: the matrices (``a``, ``b``, ``c``, ``d``) or a
#: transfer function (``num``, ``den``), then the fields of
#: :class:`~qzs.model.controller.LinearController`.
LINEAR_KEYS = ("a", "b", "c", "d", "num", "den", "inputs", "sample_time", "tracking_time",
               "name")
#: Where a config file's options come from: a ``[controller.linear]`` key -> the
#: :class:`~qzs.model.controller.LinearController` option an error names.
_LINEAR_OPTIONS = {"numerator": "num", "denominator": "den", "system": "num"}
#: Keys of a ``[spring]`` table with ``law = "table"`` beyond the law's fields: the CSV file
#: of the force curve (relative to the TOML file) and its reader's options
#: (:meth:`~qzs.model.springs.TabulatedSpring.read_csv`).
SPRING_CSV_KEYS = ("csv", "position_unit", "force_unit", "position_column", "force_column")
#: What ``vertical_stiffness`` may say of an oblique-spring law instead of a number.
QUASI_ZERO = "quasi-zero"


def load_config(path: str | Path) -> dict[str, Any]:
    """Read a TOML run configuration.

    Tables ``[isolator]`` and ``[controller]`` take the registry's parameter names
    (``qzs params``, :data:`qzs.model.registry.PARAMETERS`); the controller's blocks are
    its sub-tables ``[controller.compensation]``, ``[controller.dither]`` and
    ``[controller.linear]`` (:func:`controller_from_table`). ``[spring]`` (the spring law,
    :func:`spring_from_table`), ``[excitation]`` (``kind`` = chirp, sine, random or file,
    and its options) and ``[simulation]`` (``dt``, ``sample_rate``, ``solver``,
    ``duration``) are optional. Unknown tables or keys are errors.

    Parameters
    ----------
    path : str or Path
        The TOML file.

    Returns
    -------
    dict
        ``isolator`` and ``controller`` (parameter objects), ``excitation`` and
        ``simulation`` (plain dicts).

    Raises
    ------
    ParameterError
        A missing, binary or malformed file, an unknown table or key, a bad value (the
        message names the table and key, as ``[controller.linear] b in 'FILE'``).
    """
    path = Path(path)
    document = read_toml(path, "config file", empty=EMPTY_CONFIG)
    allowed = {"isolator", "controller", "excitation", "simulation", "spring"}
    known_keys(document, allowed, "the config file", f"{str(path)!r}: ", noun="table")
    isolator_table = document.get("isolator", {})
    if not isinstance(isolator_table, dict):
        raise ParameterError(f"{str(path)!r}: [isolator] must be a table, got "
                             f"{isolator_table!r}.")
    misplaced = {name for name in isolator_table
                 if name in PARAMETERS and PARAMETERS[name].section == "controller"
                 or name in BLOCKS}
    if misplaced:
        raise ParameterError(f"{str(path)!r}: {sorted(misplaced)} belong in [controller], "
                             "not [isolator].")
    isolator, _ = update_parameters(IsolatorParameters(), ControllerParameters(),
                                    isolator_table)
    if "spring" in document:
        isolator = dataclasses.replace(isolator,
                                       spring=spring_from_table(document["spring"], path))
    controller = controller_from_table(document.get("controller", {}), path)
    for section, keys in (("excitation", EXCITATION_KEYS), ("simulation", SIMULATION_KEYS)):
        known_keys(document.get(section, {}), keys, f"[{section}]", f"{str(path)!r}: ")
    return {"isolator": isolator, "controller": controller,
            "excitation": dict(document.get("excitation", {})),
            "simulation": dict(document.get("simulation", {}))}


def load_controller(path: str | Path) -> ControllerParameters:
    """Read a controller file: a TOML file with a ``[controller]`` table and nothing else.

    What ``qzs simulate --controller FILE.toml`` reads: the loops' parameters
    (``pi_kp = 80``) and the blocks' tables ``[controller.compensation]``,
    ``[controller.dither]`` and ``[controller.linear]`` (:func:`controller_from_table`);
    a parameter it leaves out takes its default. ``qzs params --toml`` writes one
    (with an ``[isolator]`` table to remove, or to pass with ``--config``).

    Parameters
    ----------
    path : str or Path
        The TOML file.

    Returns
    -------
    ControllerParameters

    Raises
    ------
    ParameterError
        A missing, binary or malformed file, another table than ``[controller]``, an
        unknown key, a bad value (the message names the table and key).
    """
    path = Path(path)
    document = read_toml(path, "controller file", empty=(
        "write a [controller] table into it (`qzs params --toml` shows one)"))
    known_keys(document, (), f"controller file {str(path)!r}", required=("controller",),
               noun="table", options=("controller",),
               fix="it must hold a [controller] table (and its [controller.<block>] tables) "
                   "and nothing else: put [isolator], [excitation] and [simulation] in a "
                   "config file (--config)")
    return controller_from_table(document["controller"], path)


def load_spring(path: str | Path):
    """Read a spring file: a TOML file with a ``[spring]`` table and nothing else.

    What ``qzs simulate --spring FILE.toml`` reads (:func:`spring_from_table`).

    Parameters
    ----------
    path : str or Path
        The TOML file.

    Returns
    -------
    SpringLaw

    Raises
    ------
    ParameterError
        A missing, binary or malformed file, another table than ``[spring]``, an unknown
        law or key, a bad value (the message names the table and key).
    DataError
        A table's CSV file that is missing or malformed.
    """
    path = Path(path)
    document = read_toml(path, "spring file", empty=(
        'write a [spring] table into it, e.g. law = "oblique"'))
    known_keys(document, (), f"spring file {str(path)!r}", required=("spring",), noun="table",
               options=("spring",), fix="it must hold a [spring] table and nothing else: put "
                                         "the other tables in a config file (--config)")
    return spring_from_table(document["spring"], path)


def spring_from_table(table: Any, path: str | Path | None = None, *, name: str = "spring"):
    """A spring law from a TOML ``[spring]`` table (parsed; docs/model.md §3.1).

    ``law`` is ``"tanh"``, ``"oblique"``, ``"polynomial"`` or ``"table"``; the other keys are
    the law's fields in SI units (``plateau`` [N] and ``shape`` [1/m]; ``vertical_stiffness``
    [N/m], ..., ``vertical_stiffness = "quasi-zero"`` choosing the quasi-zero value;
    ``coefficients`` and ``center``; ``positions`` [m] and ``forces`` [N], or ``csv`` = a
    CSV file of the force curve, relative to the TOML file, with ``position_unit``,
    ``force_unit``, ``position_column``, ``force_column`` as
    :meth:`~qzs.model.springs.TabulatedSpring.read_csv` takes them, and ``outside``).

    Parameters
    ----------
    table : dict
        The parsed table.
    path : str or Path, optional
        The TOML file, for the messages and a relative ``csv``.
    name : str
        The table's name in the file, for the messages.

    Returns
    -------
    SpringLaw

    Raises
    ------
    ParameterError
        No or an unknown ``law``, an unknown key, a bad value; the message names the table
        and key (``[spring] free_length in 'FILE'``), the value and the fix.
    DataError
        A missing or malformed CSV file.
    """
    where = f" in {str(path)!r}" if path is not None else ""
    prefix = f"{str(path)!r}: " if path is not None else ""
    if not isinstance(table, dict):
        raise ParameterError(f"{prefix}[{name}] must be a table, got {table!r}.", (name,))
    kind = table.get("law")
    if kind not in SPRING_LAWS:
        got = "no `law`" if "law" not in table else f"law = {kind!r}"
        raise ParameterError(f"{prefix}[{name}] has {got}; write law = one of "
                             f"{', '.join(repr(k) for k in SPRING_LAWS)} (e.g. law = "
                             '"oblique").', ("law",))
    cls = SPRING_LAWS[kind]
    fields = [f.name for f in dataclasses.fields(cls)]
    allowed = ["law", *fields, *(SPRING_CSV_KEYS if cls is TabulatedSpring else ())]
    known_keys(table, allowed, f"[{name}] (law = {kind!r})", prefix)
    values = {key: value for key, value in table.items() if key in fields}
    spelling = {key: f"[{name}] {key}{where}" for key in allowed}
    try:
        if cls is TabulatedSpring:
            return _table_law(table, values, path, prefix, name)
        if cls is ObliqueSpringQZS and values.get("vertical_stiffness") == QUASI_ZERO:
            del values["vertical_stiffness"]
            return ObliqueSpringQZS.quasi_zero(**values)
        return cls(**values)
    except ParameterError as error:
        raise error.renamed(spelling) from None


def _table_law(table, values, path, prefix, name):
    """A :class:`TabulatedSpring` from a ``[spring]`` table: ``csv`` or the two columns."""
    if "csv" in table:
        inline = sorted({"positions", "forces"} & set(table))
        if inline:
            raise ParameterError(f"{prefix}[{name}] gives both csv and {inline}: give the force "
                                 "curve once, as a CSV file or as positions and forces.",
                                 ("csv",))
        csv = Path(str(table["csv"]))
        if path is not None and not csv.is_absolute():
            csv = Path(path).parent / csv
        options = {key: table[key] for key in SPRING_CSV_KEYS[1:] if key in table}
        return TabulatedSpring.read_csv(csv, outside=values.get("outside", "refuse"),
                                        **options)
    missing = [key for key in ("positions", "forces") if key not in table]
    if missing:
        raise ParameterError(f"{prefix}[{name}] (law = 'table') needs csv = \"FILE.csv\", or "
                             f"positions [m] and forces [N]; {missing} missing.",
                             tuple(missing))
    stray = sorted(set(SPRING_CSV_KEYS[1:]) & set(table))
    if stray:
        raise ParameterError(f"{prefix}[{name}] {stray} are options of csv, which is not "
                             "given: positions are in m and forces in N.", tuple(stray))
    return TabulatedSpring(**values)


def controller_from_table(table: Any, path: str | Path | None = None,
                          controller: ControllerParameters | None = None, *,
                          name: str = "controller") -> ControllerParameters:
    """A controller from a TOML ``[controller]`` table (parsed), blocks included.

    Its keys are the loops' parameters (``pi_kp``, ...; :data:`qzs.model.registry.PARAMETERS`)
    and the blocks' tables: ``[controller.compensation]`` and ``[controller.dither]`` take
    their block's scalar fields (``fraction``, ``deadband``, ...; ``"none"`` for an
    optional level: the plant's), ``[controller.linear]`` takes ``a``, ``b``, ``c``, ``d``
    (matrices, as lists of rows) or ``num``, ``den`` (one input's transfer function,
    highest power first), and ``inputs`` (sensor names), ``sample_time`` [s],
    ``tracking_time`` [s], ``name`` (:data:`LINEAR_KEYS`).

    Parameters
    ----------
    table : dict
        The parsed table.
    path : str or Path, optional
        The file, for the messages.
    controller : ControllerParameters, optional
        The controller to start from; default :class:`ControllerParameters`.
    name : str
        The table's name in the file, for the messages (``legs.2.controller`` for a
        hexapod leg's own: ``[legs.2.controller.dither] amplitude in 'FILE'``).

    Returns
    -------
    ControllerParameters

    Raises
    ------
    ParameterError
        An unknown key, an isolator's parameter, or a bad value; the message names the
        table and key (``[controller.linear] sample_time in 'FILE'``), the value and the fix.
    """
    where = f" in {str(path)!r}" if path is not None else ""
    prefix = f"{str(path)!r}: " if path is not None else ""
    if not isinstance(table, dict):
        raise ParameterError(f"{prefix}[{name}] must be a table, got {table!r}.", (name,))
    misplaced = sorted(key for key in table
                       if key in PARAMETERS and PARAMETERS[key].section == "isolator")
    if misplaced:
        raise ParameterError(f"{prefix}{misplaced} belong in [isolator], not [{name}].")
    settings, spelling = {}, {}
    for key, value in table.items():
        if key in BLOCKS and isinstance(value, dict):
            if key == "linear":
                continue
            fields = [f.name for f in dataclasses.fields(BLOCK_CLASSES[key])]
            known_keys(value, fields, f"[{name}.{key}]", prefix)
            for field, item in value.items():
                settings[f"{key}.{field}"] = item
                spelling[f"{key}.{field}"] = f"[{name}.{key}] {field}{where}"
        else:
            settings[key] = value
            spelling[key] = f"[{name}] {key}{where}"
    controller = controller or ControllerParameters()
    linear = table.get("linear")
    if isinstance(linear, dict):
        controller = dataclasses.replace(controller, linear=_linear(linear, where, prefix,
                                                                    f"{name}.linear"))
    try:
        _, controller = update_parameters(IsolatorParameters(), controller, settings)
    except ParameterError as error:
        raise error.renamed(spelling) from None
    return controller


def _linear(table, where, prefix, name="controller.linear"):
    """A :class:`LinearController` from its ``[controller.linear]`` table (``name``)."""
    known_keys(table, LINEAR_KEYS, f"[{name}]", prefix)
    spelling = {key: f"[{name}] {key}{where}" for key in LINEAR_KEYS}
    spelling.update({option: spelling[key] for option, key in _LINEAR_OPTIONS.items()})
    spelling["denominator"] = spelling["den"]
    matrices = [key for key in ("a", "b", "c", "d") if key in table]
    polynomial = [key for key in ("num", "den") if key in table]
    if bool(matrices) == bool(polynomial) or (polynomial and len(polynomial) != 2):
        raise ParameterError(
            f"{prefix}[{name}] must give its controller either as matrices (a, b, "
            f"c, d; a and b may be left out for a static gain) or as a transfer function "
            f"(num and den), got {sorted(matrices + polynomial) or 'neither'}.",
            (name,))
    options = {key: table[key] for key in ("inputs", "sample_time", "tracking_time", "name")
               if key in table}
    try:
        if polynomial:
            inputs = options.pop("inputs", ("measured_payload_velocity",))
            if not isinstance(inputs, str) and len(inputs) != 1:
                raise ParameterError(
                    f"`inputs` names {len(inputs)} sensors ({inputs!r}) but `num`/`den` is "
                    "one input's transfer function; name one sensor, or give the matrices "
                    "(a, b, c, d) of a controller with several inputs.", ("inputs",))
            return LinearController.from_transfer_function(table["num"], table["den"],
                                                           inputs, **options)
        return LinearController(**{key: table[key] for key in matrices}, **options)
    except ParameterError as error:
        raise error.renamed(spelling) from None
    except TypeError as error:  # a value of the wrong kind for the library (a string)
        raise ParameterError(f"{prefix}[{name}]: {error}; give numbers.",
                             (name,)) from None


def save_config(path, isolator=None, controller=None, excitation=None, simulation=None):
    """Write parameters (and optional excitation/simulation tables) as TOML, atomically.

    Parameters
    ----------
    path : str or Path
        The file to write.
    isolator : IsolatorParameters, optional
        Plant parameters; defaults if omitted.
    controller : ControllerParameters, optional
        Controller parameters; defaults if omitted.
    excitation : dict, optional
        The ``[excitation]`` table.
    simulation : dict, optional
        The ``[simulation]`` table.
    """
    text = config_text(isolator, controller, excitation, simulation)
    with atomic_path(path) as tmp:
        Path(tmp).write_text(text, encoding="utf-8")
    return Path(path)


def spring_text(law, note=None):
    """A spring law as a TOML ``[spring]`` table: what ``qzs simulate --spring FILE.toml`` and
    :func:`load_spring` read (the law's fields in SI units, docs/model.md §3.1).

    Parameters
    ----------
    law : SpringLaw
        The law.
    note : str, optional
        A comment line under the header (where the law comes from).

    Returns
    -------
    str
        UTF-8 TOML text.
    """
    import tomli_w

    from qzs.model.springs import SpringLaw

    if not isinstance(law, SpringLaw):
        raise ParameterError(f"`law` must be a spring law (TanhSpring, ...), got {law!r}.",
                             ("law",))
    header = "# qzs spring law: SI units (m, N); read by `qzs simulate --spring FILE.toml`.\n"
    if note:
        header += f"# {note}\n"
    return header + tomli_w.dumps({"spring": law.to_dict()})


def config_text(isolator=None, controller=None, excitation=None, simulation=None, note=None):
    """A run configuration as TOML text (what :func:`save_config` writes; nothing is written).

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; defaults if omitted.
    controller : ControllerParameters, optional
        Controller parameters; defaults if omitted.
    excitation : dict, optional
        The ``[excitation]`` table.
    simulation : dict, optional
        The ``[simulation]`` table.
    note : str, optional
        A comment line under the header (where the file comes from).

    Returns
    -------
    str
        UTF-8 TOML text that ``qzs simulate --config`` reads.
    """
    import tomli_w

    controller = controller or ControllerParameters()
    document = {"isolator": (isolator or IsolatorParameters()).to_dict(),
                "controller": controller.to_dict()}
    spring = document["isolator"].pop("spring", None)  # its own table, [spring]
    if spring is not None:
        document["spring"] = spring
    for name in BLOCKS:  # a block's table: None is the plant's level, "none" in TOML
        block = getattr(controller, name)
        if block is not None:
            document["controller"][name] = {
                field.name: "none" if getattr(block, field.name) is None
                else getattr(block, field.name) for field in dataclasses.fields(block)
                if getattr(block, field.name) is not None or field.default is not None}
    linear = document["controller"].pop("linear", None)
    rest = {}
    if excitation:
        rest["excitation"] = dict(excitation)
    if simulation:
        rest["simulation"] = dict(simulation)
    header = "# qzs run configuration: units as in `qzs params` (SI).\n"
    if note:
        header += f"# {note}\n"
    text = header + tomli_w.dumps(document)
    if linear is not None:  # its matrices one line each, as they are read (rows of a, b)
        text += "\n[controller.linear]\n" + "".join(
            f"{key} = {_inline(value)}\n" for key, value in linear.items())
    return text + ("\n" + tomli_w.dumps(rest) if rest else "")


def _inline(value):
    """A TOML value on one line: a number, a string, or nested arrays of them."""
    import json

    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_inline(item) for item in value) + "]"
    if isinstance(value, str):
        return json.dumps(value)  # a JSON string is a TOML basic string
    return repr(float(value))
