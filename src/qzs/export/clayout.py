"""The C model's copies of the numba side, checked before anything is exported.

The C model (``csrc/``) packs its inputs as the kernels do: the indices of the packed
parameters, state, flags, excitation, channels and controller blocks (``QZS_P_*``,
``QZS_S_*``, ``QZS_M_*``, ... in its headers) are those of :mod:`qzs.engine.kernels`,
:mod:`qzs.model.excitation` and :mod:`qzs.model.springs`, and the FMU's parameter checks
(``REQUIRE`` in ``qzs_fmu.c``) are those of the parameter classes. Both are written by hand in
C; :func:`check_c_model` reads them from the shipped sources and compares them with the
Python side, so that a parameter or an index added (or moved) in Python and not in C stops
``qzs export fmu`` and ``qzs export controller`` with a :class:`~qzs.errors.CModelMismatchError`
naming each difference, instead of exporting a C model that reads the wrong numbers.
"""
import re

from qzs.engine import kernels
from qzs.errors import CModelMismatchError, ParameterError
from qzs.export.csource import source_text
from qzs.model import excitation, springs

__all__ = ["C_HEADERS", "c_constants", "python_constants", "check_c_model"]

#: The headers that define the packed layout, in the order they include one another.
C_HEADERS = ("qzs_controller.h", "qzs_spring.h", "qzs_plant.h")
#: The kernels' constants the C model copies (a packed index, a width, a code): the packed
#: parameters, ODE and persistent state, flags, channels, output flags, controller blocks,
#: the widths, the modes, solvers and statuses.
_KERNELS = re.compile(r"(P|S|A|I|C|O|M|X)_\w+|N_(PARAMS|ODE|X|STATE|HELD|FLAGS|CHANNELS|SENSORS"
                      r"|MODEL|BASE_CHANNELS)|NX_(MAX|SHORT)|PHASE_PERIOD|(SOLVER|STATUS|MODE)_\w+")
#: Kernels' constants of that form that the C model has no use for: the spring law after the
#: blocks (the C model takes the law on its own, qzs_spring.h) and the linear controller's
#: first state (offset 0 in C).
_KERNELS_ONLY = ("M_SPRING", "X_X0")
#: C names whose family is the packing's: a C constant of these with no Python one is a
#: leftover of a removed index.
_PACKED_C = re.compile(r"QZS_(P|S|A|I|E|C|M)_\w+")


def _python(module, pattern, c_name=lambda name: f"QZS_{name}", skip=()):
    """``{C name: (Python name, value)}`` of ``module``'s integer constants matching
    ``pattern``."""
    label = module.__name__.rsplit(".", 1)[-1]
    return {c_name(name): (f"{label}.{name}", value) for name, value in vars(module).items()
            if re.fullmatch(pattern, name) and name not in skip
            and isinstance(value, int) and not isinstance(value, bool)}


def python_constants():
    """The Python side's constants the C model copies, by their C name.

    Returns
    -------
    dict of str to (str, int)
        ``QZS_P_MASS`` -> (``kernels.P_MASS``, 0), ...
    """
    spring_codes = {"TANH", "OBLIQUE", "POLYNOMIAL", "TABLE"}
    return {**_python(kernels, _KERNELS, skip=_KERNELS_ONLY),
            **_python(excitation, r"(E|KIND)_\w+|N_EXCITATION"),
            **_python(springs, "|".join(spring_codes), lambda name: f"QZS_SPRING_{name}"),
            **_python(springs, r"TABLE_\w+"),
            **_python(springs, r"STATUS_\w+", lambda name: f"QZS_SPRING_{name[7:]}")}


def c_constants(texts=None):
    """The integer constants of the C headers: their enumerators and ``#define``\\ s.

    Parameters
    ----------
    texts : sequence of str, optional
        The headers' texts, each after those it uses; default :data:`C_HEADERS` shipped.

    Returns
    -------
    dict of str to int
        ``QZS_P_MASS`` -> 0, ...
    """
    if texts is None:
        texts = [source_text(name) for name in C_HEADERS]
    values = {}

    def value(expression):
        """An enumerator's or a macro's integer expression of those before it."""
        expression = re.sub(r"QZS_\w+", lambda m: str(values[m.group(0)]), expression)
        if not re.fullmatch(r"[\d\s+*()-]*\d[\d\s+*()-]*", expression):
            raise ValueError(f"not an integer expression: {expression!r}")
        return int(eval(expression, {"__builtins__": {}}))  # digits and + - * ( ) only

    for text in texts:
        text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
        items = [(m.start(), "define", m.group(1), m.group(2)) for m in re.finditer(
            r"^#define[ \t]+(QZS_\w+)[ \t]+([^\n]+?)[ \t]*$", text, re.M)]
        items += [(m.start(), "enum", None, m.group(1)) for m in re.finditer(
            r"\benum\s*\{(.*?)\}\s*;", text, re.S)]
        for _, kind, name, body in sorted(items):
            if kind == "define":
                try:
                    values[name] = value(body)
                except (KeyError, ValueError, SyntaxError):  # not an integer constant
                    pass
                continue
            following = 0
            for item in filter(None, (part.strip() for part in body.split(","))):
                name, _, expression = (part.strip() for part in item.partition("="))
                values[name] = following = value(expression) if expression else following
                following += 1
    return values


def _index_mismatches(c, python):
    """(name, C side, Python side) of every index that differs or is on one side only."""
    found = []
    for c_name, (py_name, py_value) in sorted(python.items()):
        if c.get(c_name) != py_value:
            found.append((c_name, c.get(c_name), f"{py_name} = {py_value}"))
    found += [(c_name, value, None) for c_name, value in sorted(c.items())
              if c_name not in python and _PACKED_C.fullmatch(c_name)]
    return found


def _python_bound(name, base):
    """The lower bound the parameter classes put on ``name`` alone: ``>`` (positive), ``>=``
    (non-negative) or None (any real), from whether they refuse 0 and -1."""
    from qzs.model.registry import update_parameters

    def accepted(value):
        try:
            update_parameters(*base, {name: value})
        except ParameterError:
            return False
        return True

    return ">" if not accepted(0.0) else ">=" if not accepted(-1.0) else None


def _check_mismatches(fmu_source):
    """(name, C side, Python side) of every registry parameter that ``qzs_fmu.c`` does not
    read, or checks with another lower bound than the parameter classes."""
    from qzs.model.controller import ControllerParameters
    from qzs.model.isolator import IsolatorParameters
    from qzs.model.registry import PARAMETERS

    # a frictionless guide: the stiction force's own bound, not the stiction >= Coulomb one
    base = (IsolatorParameters(stiction_force=0.0, coulomb_force=0.0), ControllerParameters())
    found = []
    for name, info in PARAMETERS.items():
        macro = f"{info.section}_{name}".upper()
        label = f"{info.section}.{name}"
        if not re.search(rf"\bV\({macro}\)", fmu_source):
            found.append((label, "not read by qzs_fmu.c", "a registry parameter"))
            continue
        if info.unit == "-":  # a choice: its codes are checked by the FMU's variables
            continue
        required = re.search(rf"REQUIRE\({macro},\s*V\({macro}\)\s*(>=?)\s*0\.0\b", fmu_source)
        if required is None and re.search(rf"REQUIRE\({macro},", fmu_source):
            continue  # a rule of another form (e.g. a choice of codes)
        c_bound = required.group(1) if required else None
        py_bound = _python_bound(name, base)
        if c_bound != py_bound:
            shown = {">": "> 0", ">=": ">= 0", None: "any real"}
            found.append((label, f"REQUIRE {shown[c_bound]}", f"checked {shown[py_bound]}"))
    return found


def check_c_model():
    """Refuse a C model whose packed indices or parameter checks are not the Python side's.

    Every kernel, excitation and spring-law constant that the C headers copy must have its C
    twin with the same value (and no packed C index may be left over), and every registry
    parameter (:data:`qzs.model.registry.PARAMETERS`) must be read by ``qzs_fmu.c`` and
    checked there with the lower bound the parameter classes give it.

    Raises
    ------
    CModelMismatchError
        Naming each difference: the index or parameter, the C side and the Python side.
    """
    mismatches = (_index_mismatches(c_constants(), python_constants())
                  + _check_mismatches(source_text("qzs_fmu.c")))
    if mismatches:
        raise CModelMismatchError(tuple(mismatches))
