"""Run configuration files (TOML): model parameters, excitation and simulation tables."""
from pathlib import Path
from typing import Any

from qzs._validation import known_keys, read_toml
from qzs.errors import ParameterError
from qzs.iotools.files import atomic_path
from qzs.model.controller import ControllerParameters
from qzs.model.excitation import EXCITATION_OPTIONS
from qzs.model.isolator import IsolatorParameters
from qzs.model.registry import PARAMETERS, update_parameters

__all__ = ["load_config", "save_config", "config_text", "EXCITATION_KEYS",
           "SIMULATION_KEYS"]

#: Keys allowed in the ``[excitation]`` and ``[simulation]`` tables of a config file.
EXCITATION_KEYS = ("kind", *dict.fromkeys(o for v in EXCITATION_OPTIONS.values() for o in v))
SIMULATION_KEYS = ("dt", "sample_rate", "solver", "duration")
#: The fix of an empty config file.
EMPTY_CONFIG = ("write the parameters to change into it (`qzs params --toml > FILE.toml` writes "
                "every one with its default), or give no config file for the defaults")


def load_config(path: str | Path) -> dict[str, Any]:
    """Read a TOML run configuration.

    Tables ``[isolator]`` and ``[controller]`` take the registry's parameter names
    (``qzs params``, :data:`qzs.model.registry.PARAMETERS`); ``[excitation]`` (``kind``
    = chirp, sine, random or file, and its options) and ``[simulation]`` (``dt``,
    ``sample_rate``, ``solver``, ``duration``) are optional. Unknown tables or keys
    are errors.

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
        A missing, binary or malformed file, an unknown table or key, a bad value.
    """
    path = Path(path)
    document = read_toml(path, "config file", empty=EMPTY_CONFIG)
    allowed = {"isolator", "controller", "excitation", "simulation"}
    unknown = set(document) - allowed
    if unknown:
        raise ParameterError(f"{str(path)!r}: unknown table(s) {sorted(unknown)}; "
                             f"allowed are {sorted(allowed)}.")
    settings = {**document.get("isolator", {}), **document.get("controller", {})}
    for section in ("isolator", "controller"):
        other = "controller" if section == "isolator" else "isolator"
        misplaced = {name for name in document.get(section, {})
                     if name in PARAMETERS and PARAMETERS[name].section == other}
        if misplaced:
            raise ParameterError(f"{str(path)!r}: {sorted(misplaced)} belong in [{other}], "
                                 f"not [{section}].")
    isolator, controller = update_parameters(IsolatorParameters(), ControllerParameters(),
                                             settings)
    for section, keys in (("excitation", EXCITATION_KEYS), ("simulation", SIMULATION_KEYS)):
        known_keys(document.get(section, {}), keys, f"[{section}]", f"{str(path)!r}: ")
    return {"isolator": isolator, "controller": controller,
            "excitation": dict(document.get("excitation", {})),
            "simulation": dict(document.get("simulation", {}))}


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

    document = {"isolator": (isolator or IsolatorParameters()).to_dict(),
                "controller": (controller or ControllerParameters()).to_dict()}
    if excitation:
        document["excitation"] = dict(excitation)
    if simulation:
        document["simulation"] = dict(simulation)
    header = "# qzs run configuration: units as in `qzs params` (SI).\n"
    if note:
        header += f"# {note}\n"
    return header + tomli_w.dumps(document)
