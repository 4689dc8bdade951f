"""Each leg's own controller of a six-axis platform: from a hexapod file's
``[legs.N.controller]`` tables, from ``--leg-controller N=FILE.toml``, or from Python; each
leg's own spring law from ``--spring FILE.toml`` and ``--leg-spring N=FILE.toml``.

The tables are read by the single axis's reader
(:func:`qzs.iotools.config.controller_from_table`), blocks included (docs/hexapod.md §9.5a);
:mod:`qzs.workflows.hexapod.setups` builds the set-up with them.
"""
from collections.abc import Mapping, Sequence

import numpy as np

from qzs.errors import ParameterError
from qzs.model.controller import ControllerParameters, refuse_blocks
from qzs.model.hexapod import LEG_COUNT
from qzs.model.isolator import IsolatorParameters
from qzs.model.registry import PARAMETERS, update_parameters
from qzs.model.springs import SpringLaw

__all__ = ["read_leg_controllers", "read_leg_springs", "with_springs"]


def read_leg_controllers(pairs: Sequence[str], argument: str = "--leg-controller"
                         ) -> tuple[dict[int, ControllerParameters], dict[str, str]]:
    """Each leg's own controller from ``N=FILE.toml`` pairs (``qzs hexapod simulate
    --leg-controller``), every leg number checked before any file is read.

    Parameters
    ----------
    pairs : sequence of str
        ``N=FILE.toml``: leg ``N`` (1 to 6) runs the controller of that controller file
        (:func:`qzs.iotools.config.load_controller`).
    argument : str
        How the caller names the option in messages.

    Returns
    -------
    legs : dict
        Leg number -> ControllerParameters (``hexapod_setup``'s and ``load_hexapod``'s
        ``legs``).
    names : dict
        ``"legs[N]"`` -> the pair as given, for messages (``load_hexapod``'s ``names``).

    Raises
    ------
    ParameterError
        A pair that is not ``N=FILE``, a leg number outside 1 to 6, a leg given twice (the
        message names the option and the pairs), or a file that is not a controller file.
    """
    from qzs.iotools.config import load_controller

    return _read_leg_files(pairs, argument, load_controller)


def read_leg_springs(pairs: Sequence[str], argument: str = "--leg-spring"
                     ) -> tuple[dict[int, SpringLaw], dict[str, str]]:
    """Each leg's own spring law from ``N=FILE.toml`` pairs (``qzs hexapod simulate
    --leg-spring``), every leg number checked before any file is read.

    Parameters
    ----------
    pairs : sequence of str
        ``N=FILE.toml``: leg ``N`` (1 to 6) has the law of that spring file
        (:func:`qzs.iotools.config.load_spring`, a ``[spring]`` table).
    argument : str
        How the caller names the option in messages.

    Returns
    -------
    legs : dict
        Leg number -> SpringLaw (:func:`with_springs`'s ``legs``).
    names : dict
        ``"legs[N]"`` -> the pair as given, for messages.

    Raises
    ------
    ParameterError
        A pair that is not ``N=FILE``, a leg number outside 1 to 6, a leg given twice, or a
        file that is not a spring file.
    """
    from qzs.iotools.config import load_spring

    return _read_leg_files(pairs, argument, load_spring)


def with_springs(isolator: IsolatorParameters, spring: SpringLaw | None = None,
                 legs: Mapping[int, SpringLaw] | None = None
                 ) -> IsolatorParameters | tuple[IsolatorParameters, ...]:
    """Each leg's plant with its spring law: ``spring`` on every leg, ``legs[N]`` on leg N.

    Parameters
    ----------
    isolator : IsolatorParameters
        Every leg's plant.
    spring : SpringLaw, optional
        Every leg's law (docs/model.md §3.1); default the plant's own.
    legs : dict, optional
        Leg number (1 to 6) -> that leg's own law (:func:`read_leg_springs`).

    Returns
    -------
    IsolatorParameters or tuple of six
        One plant when every leg has the same, else the six.
    """
    import dataclasses

    if spring is not None:
        isolator = dataclasses.replace(isolator, spring=spring)
    if not legs:
        return isolator
    return tuple(dataclasses.replace(isolator, spring=legs[n]) if n in legs else isolator
                 for n in range(1, LEG_COUNT + 1))


def _read_leg_files(pairs, argument, load):
    """``N=FILE`` pairs read by ``load``: ``({leg: value}, {"legs[N]": pair})``, every leg
    number checked before any file is read (:func:`read_leg_controllers`)."""
    files: dict[int, str] = {}
    given: dict[int, object] = {}
    for pair in pairs:
        number, _, path = str(pair).partition("=")
        number = _leg_number(number, f"{argument} {pair!r}",
                             f"give {argument} N=FILE.toml with N from 1 to {LEG_COUNT}")
        if not path.strip():
            raise ParameterError(f"{argument} {pair!r} names no file; give {argument} "
                                 f"{number}=FILE.toml.", (argument,))
        if number in files:
            raise ParameterError(f"{argument}: leg {number} is given twice ({given[number]!r} "
                                 f"and {pair!r}); give each leg once.", (argument,))
        files[number], given[number] = path.strip(), pair
    legs = {number: load(path) for number, path in files.items()}
    return legs, {f"legs[{n}]": f"{argument} {given[n]}" for n in files}


def _leg_number(text, where, fix):
    """A leg's number (1 to 6) from its key or text; a ParameterError naming ``where``."""
    text = str(text).strip()
    if not (text.isascii() and text.isdigit() and 1 <= int(text) <= LEG_COUNT):
        raise ParameterError(f"{where}: {text!r} is not a leg: the legs are numbered 1 to "
                             f"{LEG_COUNT}; {fix}.", (where,))
    return int(text)

def _checked_legs(legs):
    """``legs`` (leg number -> ControllerParameters) checked: numbers 1 to 6."""
    if legs is None:
        return {}
    if not isinstance(legs, Mapping):
        raise ParameterError(f"`legs` must map leg numbers (1 to 6) to ControllerParameters, "
                             f"got {type(legs).__name__}.", ("legs",))
    for number, controller in legs.items():
        if isinstance(number, bool) or not isinstance(number, (int, np.integer)) or not (
                1 <= number <= LEG_COUNT):
            raise ParameterError(f"`legs` has the key {number!r}: the legs are numbered 1 to "
                                 f"{LEG_COUNT}; give each leg's controller under its number.",
                                 ("legs",))
        if not isinstance(controller, ControllerParameters):
            raise ParameterError(f"`legs[{number}]` must be a ControllerParameters, got "
                                 f"{type(controller).__name__}.", (f"legs[{number}]",))
    return {int(number): controller for number, controller in legs.items()}


def _file_legs(table, every, path):
    """The ``[legs.N]`` tables: leg number -> its own controller, from ``every``."""
    where = f"{str(path)!r}: "
    if not isinstance(table, dict):
        raise ParameterError(f"{where}`legs` must be tables [legs.N.controller] (N from 1 to "
                             f"{LEG_COUNT}), got {table!r}.", ("legs",))
    own, keys = {}, {}
    for key, leg in table.items():
        number = _leg_number(key, f"{where}[legs.{key}]",
                             f"name a leg's table [legs.N.controller] with N from 1 to "
                             f"{LEG_COUNT}")
        if number in own:
            raise ParameterError(f"{where}leg {number} is given twice ([legs.{keys[number]}] "
                                 f"and [legs.{key}]); give each leg one table.",
                                 (f"legs.{key}",))
        if not isinstance(leg, dict) or set(leg) != {"controller"}:
            raise ParameterError(f"{where}[legs.{key}] takes one table, [legs.{key}.controller] "
                                 f"(leg {number}'s controller), got "
                                 f"{sorted(leg) if isinstance(leg, dict) else leg!r}.",
                                 (f"legs.{key}",))
        own[number] = _controller(leg["controller"], f"legs.{key}.controller", path, every)
        keys[number] = key
    return own

def _controller(table, name, path, start=None):
    """A controller from a hexapod file's ``[name]`` table, blocks included (the single
    axis's reader, :func:`qzs.iotools.config.controller_from_table`)."""
    from qzs.iotools.config import controller_from_table

    _parameters(table, name, "controller", f"{str(path)!r}: ")
    return controller_from_table(table, path, start, name=name)

def _parameters(table, section, expected, where):
    """Refuse a key of ``[section]`` that is not a registry parameter of ``expected``'s
    (a block's table is left to :func:`qzs.iotools.config.controller_from_table`)."""
    from qzs.model.controller import BLOCKS

    if not isinstance(table, dict):
        raise ParameterError(f"{where}[{section}] must be a table, got {table!r}.")
    for name, value in table.items():
        if expected == "controller" and name in BLOCKS and isinstance(value, dict):
            continue
        if name not in PARAMETERS or PARAMETERS[name].section != expected:
            article = "an" if expected == "isolator" else "a"
            raise ParameterError(f"{where}[{section}] `{name}` is not {article} {expected} "
                                 "parameter; see `qzs params`.")

def _with_settings(isolator, controller, own, settings):
    """``(isolator, controller, leg_controllers)`` with the registry ``settings`` applied to
    the plant, every leg's controller and each leg's own (``own``: number -> controller);
    ``leg_controllers`` None when no leg has its own."""
    isolator, controller = update_parameters(isolator, controller, settings)
    if not own:
        return isolator, controller, None
    legs = tuple(update_parameters(isolator, own[number], settings)[1] if number in own
                 else controller for number in range(1, LEG_COUNT + 1))
    return isolator, controller, legs

def _sources(every, own, name):
    """How the caller names each leg's controller: ``every`` for all, ``name(n)`` for leg
    ``n``'s own (``own``: the legs that have one)."""
    return tuple(name(n) if n in own else every for n in range(1, LEG_COUNT + 1))

def _refuse_central_blocks(controller, leg_controllers, what, sources):
    """Refuse centralised control (``what``: how the caller names it) when a leg's controller
    has blocks: they act on a leg's own motor loop (docs/hexapod.md §9.5a). The message names
    the first such leg's controller as ``sources`` does, its blocks and the fix."""
    legs = leg_controllers or (controller,) * LEG_COUNT
    for one, source in zip(legs, sources):
        refuse_blocks(one, f"centralised control ({what})",
                      f"the blocks act on a leg's own motor loop (docs/hexapod.md §9.5a): "
                      f"leave out {what} for a loop per leg, or the blocks", argument=source)
