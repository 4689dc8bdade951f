"""Every public callable of qzs documents its parameters, with units where physical.

In the style of python-control's ``control/tests/docstrings_test.py``: walk every
module of the package (``pkgutil.walk_packages``), take each name of its ``__all__``
that is a function (numba kernels through their ``py_func``) or a class defined in
qzs, and the public methods and properties of those classes, and check the
docstring against the signature:

* there is a docstring;
* every parameter (except ``self``, ``cls`` and ``*args``/``**kwargs`` catch-alls)
  is named in the numpydoc "Parameters" section; a class documents its
  ``__init__`` parameters (its dataclass fields) under "Parameters" or "Attributes";
* every documented entry has a description, and a function documents no parameter
  it does not have;
* every documented entry whose name is a physical quantity carries its unit in
  square brackets (``[s]``, ``[Hz]``, ``[N*s/m]``, ``[-]``, ``[samples]``). Model
  parameters (:data:`qzs.model.registry.PARAMETERS`) and the fields of parameter
  dataclasses declared with a unit (``qzs._validation.parameter``) must carry exactly
  that unit; the names of :data:`RUN_QUANTITIES` must carry some unit.

The sections are parsed with regular expressions (no numpydoc dependency). Run the
module directly to print every problem at once::

    .venv/bin/python tests/test_docstrings.py
"""
import dataclasses
import importlib
import inspect
import pkgutil
import re
from typing import NamedTuple

import pytest

import qzs
from qzs.model.registry import PARAMETERS

#: Argument, field and attribute names (beyond the model parameters) that are physical
#: quantities: wherever they are documented they must carry a unit in brackets. The
#: model parameters come from the registry, with the unit it gives them.
RUN_QUANTITIES = frozenset({
    # run and analysis settings, signals and excitation options
    "dt", "duration", "sample_rate", "frequency", "frequencies", "time",
    "relative_position", "relative_velocity", "displacement", "velocity", "force",
    "amplitude", "f0", "f1", "f_low", "f_high", "phase", "highpass_corner", "corner",
    "rate", "fft_length", "band", "at_frequencies", "motor_force", "stop_center",
    "stop_centers", "mass", "pi_integral", "exclude_below_velocity", "smoothing_window",
    # frequencies, bands, ratios and slopes of transmissibility curves and linear models
    "low", "high", "frequency_range", "rolloff_band", "untrusted_below",
    "resonance_frequency", "resonance_peak", "isolation_onset", "minus_3db_frequency",
    "rolloff_db_per_decade", "magnitude", "natural_frequency",
    "undamped_natural_frequency", "damping_ratio", "stiffness", "damping", "poles",
    # fit results and wall times
    "offset", "friction", "residual", "residual_rms", "elapsed", "seconds",
    "wall_seconds", "simulation_seconds",
    # the numba kernels' symbols (docs/model.md): time, state, gains and force levels
    "t", "z", "v", "z_ref", "z_low", "z_high", "v_measured", "integral", "f_max",
    "fs", "fc", "cbc", "cv", "kp", "ki", "kd",
})

#: Every name that must carry a unit in brackets.
PHYSICAL = frozenset(PARAMETERS) | RUN_QUANTITIES

#: True exceptions only: qualified name -> the checks (see CHECKS) it is exempt from.
ALLOWED = {}

#: What :func:`check_docstring` reports, by check.
CHECKS = ("docstring", "parameters", "unknown", "description", "units")

#: Numpydoc section titles (a title underlined with dashes starts a section).
_SECTION_NAMES = ("Parameters", "Attributes", "Other Parameters", "Returns", "Yields",
                  "Receives", "Raises", "Warns", "Warnings", "See Also", "Notes",
                  "References", "Examples", "Methods")
#: A parameter entry: ``name``, ``name : type`` or ``name1, name2 : type``.
_ENTRY = re.compile(r"^(?P<names>\*{0,2}\w+(?:\s*,\s*\*{0,2}\w+)*)\s*(?::\s*(?P<type>.*))?$")
#: Anything in square brackets.
_BRACKETS = re.compile(r"\[([^\[\]]+)\]")
#: What a unit in brackets may be: SI symbols with ``*``, ``/``, ``^n`` and
#: parentheses, ``-`` for dimensionless, ``samples`` for lengths in samples, or a
#: comma-separated list of those (``[Hz, Hz]``). ``list[float]`` or ``[0, 1]`` is not.
_ATOM = r"(?:kg|Hz|rad|deg|samples|decade|dB|m|s|N|W|J|V|A|g|1|-)(?:\^-?\d+)?"
_TERM = rf"(?:{_ATOM}|\({_ATOM}(?:\s*[*/]\s*{_ATOM})*\))"
_UNIT_EXPR = rf"{_TERM}(?:\s*[*/]\s*{_TERM})*"
_UNIT = re.compile(rf"^\s*{_UNIT_EXPR}(?:\s*,\s*{_UNIT_EXPR})*\s*$")


class Documented(NamedTuple):
    """One public callable and what its docstring must say."""

    name: str                   # qualified name
    doc: str | None             # its own docstring
    params: tuple               # parameter names that must be documented
    titles: tuple               # sections that may document them
    field_units: dict           # dataclass field -> unit of its metadata
    accepted: frozenset | None  # every name the signature takes (None: not checked)


# ---------------------------------------------------------------- parsing
def _indent(line):
    return len(line) - len(line.lstrip())


def sections(doc):
    """Split a docstring into its numpydoc sections: title -> [(base indent, line)]."""
    lines = inspect.cleandoc(doc or "").splitlines()
    headers = [i for i in range(len(lines) - 1)
               if lines[i].strip() in _SECTION_NAMES
               and re.fullmatch(r"\s*-{3,}\s*", lines[i + 1])]
    found = {}
    for k, start in enumerate(headers):
        end = headers[k + 1] if k + 1 < len(headers) else len(lines)
        found.setdefault(lines[start].strip(), []).extend(
            [(_indent(lines[start]), line) for line in lines[start + 2:end]])
    return found


def documented_parameters(doc, titles=("Parameters",)):
    """Entries of the sections ``titles``: name -> [type line, description lines...].

    An entry is a line at the section's base indentation of the form ``name``,
    ``name : type`` or ``name1, name2 : type`` (``*`` and ``**`` prefixes dropped);
    its description is the more indented lines below it.
    """
    entries = {}
    found = sections(doc)
    for title in titles:
        current = []
        for base, line in found.get(title, []):
            if not line.strip():
                continue
            if _indent(line) <= base:
                match = _ENTRY.match(line.strip())
                current = []
                if match:
                    for name in re.split(r"\s*,\s*", match.group("names")):
                        name = name.lstrip("*")
                        entries[name] = [match.group("type") or ""]
                        current.append(name)
            else:
                for name in current:
                    entries[name].append(line.strip())
    return entries


def units_in(text):
    """The unit-shaped contents of the square brackets in ``text``."""
    return [unit.strip() for unit in _BRACKETS.findall(text) if _UNIT.match(unit)]


def required_unit(name, field_units):
    """The unit a documented entry must carry: a string, ``True`` (any unit) or None."""
    if name not in PHYSICAL:
        return None
    if field_units.get(name):
        return field_units[name]
    if name in PARAMETERS:
        return PARAMETERS[name].unit
    return True


def check_docstring(doc, params, titles=("Parameters",), field_units=None, accepted=None):
    """Problems of one docstring against the parameters of its callable.

    Parameters
    ----------
    doc : str or None
        The docstring.
    params : sequence of str
        Parameter names that must be documented.
    titles : tuple of str
        Sections that may document them.
    field_units : dict, optional
        Dataclass field name -> unit of its ``parameter(default, unit, doc)`` metadata.
    accepted : set of str, optional
        Every name the signature takes; a documented name outside it is reported.

    Returns
    -------
    list of (str, str)
        ``(check, message)`` per problem, ``check`` one of :data:`CHECKS`; empty if
        the docstring is complete.
    """
    if not (doc and doc.strip()):
        return [("docstring", "no docstring")]
    field_units = field_units or {}
    entries = documented_parameters(doc, titles)
    problems = []
    missing = [name for name in params if name not in entries]
    if missing:
        problems.append(("parameters", f"not in its {' or '.join(titles)} section: "
                                       f"{', '.join(missing)}"))
    if accepted is not None:
        unknown = [name for name in entries if name not in accepted]
        if unknown:
            problems.append(("unknown", f"documents parameters it does not have: "
                                        f"{', '.join(unknown)}"))
    for name, (type_line, *description) in entries.items():
        if not description:
            problems.append(("description", f"`{name}` has no description"))
        unit = required_unit(name, field_units)
        found = units_in("\n".join([type_line, *description]))
        if unit is True and not found:
            problems.append(("units", f"`{name}` is physical but has no unit in brackets"))
        elif isinstance(unit, str) and unit not in found:
            problems.append(("units", f"`{name}` must carry its unit [{unit}] "
                                      f"(found {found or 'none'})"))
    return problems


# ---------------------------------------------------------------- the walk
def _signature_names(function, skip_first=False):
    """``(documentable, accepted)``: named parameters, and every name the signature takes.

    Documentable leaves out ``self``/``cls`` and the ``*args``/``**kwargs`` catch-alls;
    accepted keeps the catch-alls, which a docstring may document.
    """
    params = list(inspect.signature(function).parameters.values())
    if skip_first and params and params[0].name in ("self", "cls"):
        params = params[1:]
    named = tuple(p.name for p in params if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD))
    return named, frozenset(p.name for p in params)


def _in_qzs(obj):
    return (getattr(obj, "__module__", None) or "").split(".")[0] == "qzs"


def _unwrap(obj):
    """The Python function behind a numba dispatcher (``@njit``), else ``obj``."""
    function = getattr(obj, "py_func", None)
    return function if inspect.isfunction(function) else obj


def _class_doc(cls):
    """The class's own docstring (not the ``Name(field=...)`` that dataclass makes up)."""
    doc = cls.__dict__.get("__doc__")
    if doc and dataclasses.is_dataclass(cls) and doc.startswith(cls.__name__ + "("):
        return None
    return doc


def _class_parameters(cls):
    """What a class's docstring must document: its dataclass fields or ``__init__`` args."""
    if dataclasses.is_dataclass(cls):
        fields = [f for f in dataclasses.fields(cls) if f.init]
        return (tuple(f.name for f in fields),
                {f.name: f.metadata["unit"] for f in fields if f.metadata.get("unit")})
    for klass in cls.__mro__:
        if "__init__" in vars(klass):
            if not _in_qzs(klass):  # object's or a built-in exception's
                return (), {}
            return _signature_names(klass.__init__, skip_first=True)[0], {}
    return (), {}  # pragma: no cover - object defines __init__


def _function(name, function, skip_first=False):
    params, accepted = _signature_names(function, skip_first)
    return Documented(name, function.__doc__, params, ("Parameters",), {}, accepted)


def _members(cls):
    """Public methods and properties of ``cls`` and of its bases defined in qzs."""
    for klass in cls.__mro__:
        if not _in_qzs(klass):
            continue
        for attr, member in vars(klass).items():
            if attr.startswith("_"):
                continue
            name = f"{klass.__module__}.{klass.__qualname__}.{attr}"
            if isinstance(member, (staticmethod, classmethod)):
                yield _function(name, member.__func__, isinstance(member, classmethod))
            elif inspect.isfunction(member):
                yield _function(name, member, skip_first=True)
            elif isinstance(member, property):
                yield Documented(name, member.__doc__, (), ("Parameters",), {}, frozenset())


def public_modules():
    """qzs and every module below it (not ``__main__``, which runs the command)."""
    yield qzs
    for info in pkgutil.walk_packages(qzs.__path__, qzs.__name__ + "."):
        if info.name.rsplit(".", 1)[-1] != "__main__":
            yield importlib.import_module(info.name)


def public_callables():
    """Every public function, class, method and property of qzs, once each.

    Returns
    -------
    checked : list of Documented
        Sorted by qualified name.
    skipped : list of str
        Callables of an ``__all__`` that are neither functions nor classes (not checked).
    """
    found, skipped = {}, []
    for module in public_modules():
        for name in getattr(module, "__all__", ()):
            obj = _unwrap(getattr(module, name))
            if not (inspect.isfunction(obj) or inspect.isclass(obj)):
                if callable(obj):
                    skipped.append(f"{module.__name__}.{name}")
                continue
            if not _in_qzs(obj):
                continue
            qualified = f"{obj.__module__}.{obj.__qualname__}"
            if qualified in found:  # re-exported
                continue
            if inspect.isfunction(obj):
                found[qualified] = _function(qualified, obj)
                continue
            params, units = _class_parameters(obj)
            found[qualified] = Documented(qualified, _class_doc(obj), params,
                                          ("Parameters", "Attributes"), units, None)
            found.update((member.name, member) for member in _members(obj))
    return sorted(found.values()), skipped


CALLABLES, SKIPPED = public_callables()


def problems_of(entry):
    """The problems of one callable, less those its allow-list entry exempts."""
    exempt = ALLOWED.get(entry.name, set())
    return [(check, message) for check, message in check_docstring(
        entry.doc, entry.params, entry.titles, entry.field_units, entry.accepted)
        if check not in exempt]


# ---------------------------------------------------------------- the tests
def test_walk_finds_the_api():
    """The walk is not vacuous: it sees the flat API, subpackages, kernels and methods."""
    names = {entry.name for entry in CALLABLES}
    assert len(CALLABLES) > 150
    for expected in ("qzs.engine.simulate.simulate", "qzs.model.excitation.Chirp",
                     "qzs.model.excitation.Chirp.frequency_at", "qzs.engine.laws.spring_law",
                     "qzs.analysis.spectral.transmissibility", "qzs.cli.params.add_parser",
                     "qzs.errors.CaseError"):
        assert expected in names
    assert not SKIPPED, f"public callables the checker cannot inspect: {SKIPPED}"


def test_allow_list_is_needed():
    """Every exemption still hides a problem; otherwise remove it."""
    by_name = {entry.name: entry for entry in CALLABLES}
    for name, exempt in ALLOWED.items():
        assert name in by_name, f"{name} is allow-listed but not a public callable"
        entry = by_name[name]
        reported = {check for check, _ in check_docstring(
            entry.doc, entry.params, entry.titles, entry.field_units, entry.accepted)}
        assert exempt <= reported, f"{name} no longer needs {exempt - reported}"


@pytest.mark.parametrize("entry", CALLABLES, ids=[entry.name for entry in CALLABLES])
def test_docstring(entry):
    problems = problems_of(entry)
    assert not problems, f"{entry.name}: " + "; ".join(message for _, message in problems)


# ---------------------------------------------------------------- self-test
# The checker must be able to fail: deliberately bad docstrings are reported.

def _undocumented_gain(duration, gain, *args, **options):
    """Run for a while.

    Parameters
    ----------
    duration : float
        How long, but no unit.
    """


def _complete(duration, f0, f1, stiction_force, method="linear", *, dt=None, **options):
    """Run for a while.

    Parameters
    ----------
    duration : float
        How long [s].
    f0, f1 : float
        Start and end frequency [Hz].
    stiction_force : float
        Breakaway force [N].
    method : str
        How.
    dt : float, optional
        Time step [s]; default from the settings.
    **options
        Anything else.

    Returns
    -------
    gain : float
        Not a parameter [-].
    """


def _stale(duration):
    """Run for a while.

    Parameters
    ----------
    duration : float
    seed : int
        Gone from the signature.
    """


@dataclasses.dataclass
class _Excitation:
    """A made-up excitation.

    Parameters
    ----------
    amplitude : float
        Displacement amplitude [Hz] (the wrong unit).
    """

    amplitude: float = dataclasses.field(default=1.0, metadata={"unit": "m"})
    frequency: float = dataclasses.field(default=1.0, metadata={"unit": "Hz"})


def _check(function):
    return check_docstring(function.__doc__, *_signature_names(function)[:1],
                           accepted=_signature_names(function)[1])


def test_checker_reports_a_missing_parameter_and_unit():
    assert _check(_undocumented_gain) == [
        ("parameters", "not in its Parameters section: gain"),
        ("units", "`duration` is physical but has no unit in brackets")]


def test_checker_accepts_a_complete_function():
    assert _check(_complete) == []
    assert set(documented_parameters(_complete.__doc__)) == {
        "duration", "f0", "f1", "stiction_force", "method", "dt", "options"}


def test_checker_reports_stale_and_bare_entries():
    assert _check(_stale) == [
        ("unknown", "documents parameters it does not have: seed"),
        ("description", "`duration` has no description"),
        ("units", "`duration` is physical but has no unit in brackets")]


def test_checker_reports_wrong_units_and_missing_docstrings():
    # A registry parameter must carry the registry's unit, not just any unit.
    doc = "Do.\n\nParameters\n----------\nstiction_force : float\n    Force [m].\n"
    assert check_docstring(doc, ["stiction_force"]) == [
        ("units", "`stiction_force` must carry its unit [N] (found ['m'])")]
    # A type in brackets is not a unit.
    doc = "Do.\n\nParameters\n----------\nband : list[float]\n    Band edges.\n"
    assert check_docstring(doc, ["band"]) == [
        ("units", "`band` is physical but has no unit in brackets")]
    assert check_docstring(None, []) == [("docstring", "no docstring")]
    # A dataclass's fields must be documented, each with the unit of its metadata.
    params, units = _class_parameters(_Excitation)
    assert check_docstring(_class_doc(_Excitation), params, ("Parameters", "Attributes"),
                           units) == [
        ("parameters", "not in its Parameters or Attributes section: frequency"),
        ("units", "`amplitude` must carry its unit [m] (found ['Hz'])")]


def test_unit_grammar():
    for good in ("s", "Hz", "N*s/m", "N/(m*s)", "m/s^2", "1/m", "-", "samples", "Hz, Hz",
                 "dB/decade"):
        assert units_in(f"x [{good}]") == [good]
    for bad in ("float", "0, 1", "str", "i", "grid"):
        assert units_in(f"x [{bad}]") == []


if __name__ == "__main__":
    count = 0
    for entry in CALLABLES:
        for _, message in problems_of(entry):
            count += 1
            print(f"{entry.name}: {message}")
    print(f"{count} problems in {len(CALLABLES)} callables; not inspected: {SKIPPED or 'none'}")
