"""Design problems: decision variables, uncertain parameters, objectives and constraints,
read from a problem file into the types of :mod:`.problem_types` (re-exported here).

A problem file (TOML) says what a designer may change, what is uncertain, and what
is wanted::

    [problem]
    name = "isolation_vs_effort"
    title = "Transmissibility at 12 Hz against motor effort, any stiction 5-15 N"

    [variables]                  # registry parameters (qzs params) with bounds
    damping_gain = { low = 0.0, high = 300.0 }
    pi_kp = { low = 1.0, high = 1000.0, scale = "log" }    # searched on log10
    # integer = true rounds a variable to whole numbers

    [parameters]                 # held fixed (registry names)
    [excitation]                 # as in a sweep file: kind, amplitude, f0, f1, duration

    [uncertain]                  # robust design: a distribution per parameter, or a list
    stiction_force = { distribution = "uniform", low = 5.0, high = 15.0 }
    mass = { values = [6.2, 6.4, 6.6] }

    [robust]
    samples = 8                  # Monte Carlo draws, the same for every design
    seed = 1
    method = "lhs"               # or "random"

    [[objectives]]
    metric = "transmissibility_at"
    frequency = 12.0             # [Hz]
    statistic = "mean"           # mean (default), worst, quantile (with quantile = 0.9)
    # sense = "maximize" for a metric wanted large

    [[constraints]]
    metric = "peak_stroke"
    max = 0.020                  # [m]; or min = ...
    statistic = "worst"

    [optimizer]                  # qzs optimize: pymoo's NSGA-II
    population = 64
    generations = 20
    seed = 1

    [sensitivity]                # qzs sensitivity: SALib
    method = "sobol"             # or "morris"
    samples = 256

    [simulation]                 # as in a sweep file: solver, dt or tolerance
    [analysis]                   # as in a sweep file: sample_rate, fft_length, band, ...

Metrics are those of :data:`qzs.workflows.design_space.metrics.METRICS`. Every
mistake is reported before any run, as a :class:`~qzs.errors.ProblemError` naming
the table, the key, the value and the fix.
"""
import math
from collections.abc import Mapping
from functools import partial
from pathlib import Path
from typing import Any

from qzs._validation import Structured, integer, known_keys, read_toml, real
from qzs._validation import seed as checked_seed
from qzs.errors import CountLimitError, ParameterError, ProblemError
from qzs.iotools.shipped import resolve_shipped, shipped_files
from qzs.iotools.config import spring_from_table
from qzs.model.registry import (ALL_PARAMETERS, SPRING_PARAMETERS, check_law_parameters,
                                dotted_names)
from qzs.workflows.design_space.metrics import METRICS, STATISTICS, metric_column
from qzs.workflows.design_space.problem_types import (DesignProblem, Goal, Uncertainty, Variable,
                                                      _unit)
from qzs.workflows.sweeps.definition import (DISTRIBUTIONS, EXCITATION_PARAMETERS, load_sweep,
                                             parse_distribution)

__all__ = ["DesignProblem", "Variable", "Uncertainty", "Goal", "load_problem", "plan_text",
           "shipped_problems", "TABLES", "MAX_SAMPLES", "MIN_POPULATION"]

TABLES = ("problem", "variables", "parameters", "excitation", "uncertain", "robust",
          "objectives", "constraints", "optimizer", "sensitivity", "simulation", "analysis",
          "spring")
#: Folder of the shipped problem files, inside the package.
SHIPPED = "workflows/design_space/problem_files"
#: Fewest designs per generation NSGA-II works with (the file's and the flag's minimum).
MIN_POPULATION = 4
#: Most Monte Carlo draws per design: each is a simulation of every design.
MAX_SAMPLES = 1024
SCALES = ("linear", "log")
SENSES = ("minimize", "maximize")
OPTIMIZER_DEFAULTS = {"algorithm": "nsga2", "population": 64, "generations": 20, "seed": 1}
ALGORITHMS = ("nsga2",)
SENSITIVITY_DEFAULTS = {"method": "sobol", "samples": 256, "seed": 1, "confidence": 0.95,
                        "trajectories": 20, "levels": 4, "metrics": None}
SENSITIVITY_METHODS = ("sobol", "morris")
ROBUST_DEFAULTS = {"samples": 1, "seed": 1, "method": "lhs"}


# ---------------------------------------------------------------- loading and validation
def shipped_problems():
    """Paths of the problem files shipped with qzs."""
    return shipped_files(SHIPPED)


def load_problem(source: str | Path | Mapping[str, Any]) -> DesignProblem:
    """Read and validate a design problem.

    Parameters
    ----------
    source : str, Path or dict
        A TOML file, the name of a shipped problem (``"isolation_vs_effort"``), or an
        already parsed document.

    Returns
    -------
    DesignProblem

    Raises
    ------
    ProblemError
        An unknown table, key, parameter or metric, empty bounds, a bad distribution or
        statistic, no objective, or a constraint set no design can meet (its ``table``,
        ``key``, ``value`` and ``fix`` attributes say which and what to do).
    """
    path = None
    if isinstance(source, Mapping):
        document, where, stem = dict(source), "problem definition", "problem"
    else:
        try:
            path = resolve_shipped(source, SHIPPED, "problem", "problems")
            document = read_toml(path, "problem file", empty=(
                "write the problem's tables into it (`qzs docs design-space` describes them; "
                "the shipped isolation_vs_effort is an example)"))
        except ProblemError:
            raise
        except ParameterError as error:
            raise ProblemError("file", "", str(source), str(error)) from None
        where, stem = repr(str(path)), path.stem
    return _problem(document, where, stem, path)


def _fail(table, key, value, fix):
    raise ProblemError(table, key, value, fix)


def _table(document, name, kind=dict):
    value = document.get(name, kind())
    if name in ("variables", "uncertain", "parameters"):  # `compensation.fraction = ...`
        value = dotted_names(value)
    if not isinstance(value, kind):
        shape = "table" if kind is dict else f"list of tables [[{name}]]"
        _fail(name, "", value, f"[{name}] must be a {shape}")
    return value


def _known(table, name, allowed):
    known_keys(table, allowed, f"[{name}]", error=Structured(build=partial(ProblemError, name)))


def _parameter_name(table, name, kind):
    excitation = [f"excitation.{k}" for k in EXCITATION_PARAMETERS[kind]]
    if name not in ALL_PARAMETERS and name not in excitation:
        close = [p for p in (*ALL_PARAMETERS, *excitation) if p.split("_")[0] in name]
        hint = f" (did you mean {', '.join(close[:4])}?)" if close else ""
        _fail(table, name, name, f"not a parameter{hint}; `qzs params` lists them: "
                                 f"{', '.join(sorted(ALL_PARAMETERS))}")
    from qzs.model.registry import unit_of

    return unit_of(name, kind)


def _in(table):
    """The checks' ``error`` for a key of ``table``: a :class:`ProblemError` naming both."""
    return Structured(build=lambda key, value, reason: ProblemError(table, key, value, reason))


def _number(table, key, value):
    return real(key, value, error=_in(table))


def _variables(document, kind, law=None):
    table = _table(document, "variables")
    if not table:
        _fail("variables", "", {}, "a problem needs at least one decision variable: add "
                                   "[variables] with e.g. pi_kp = { low = 1.0, high = 1000.0 }")
    variables = []
    for name, spec in table.items():
        units = _parameter_name("variables", name, kind)
        where = f"variables.{name}"
        if not isinstance(spec, dict):
            _fail("variables", name, spec, "must be a table { low = ..., high = ... } "
                                           "[the parameter's unit]")
        _known(spec, where, ("low", "high", "scale", "integer"))
        if "low" not in spec or "high" not in spec:
            _fail("variables", name, spec, "needs both `low` and `high`")
        low, high = _number(where, "low", spec["low"]), _number(where, "high", spec["high"])
        if not low < high:
            _fail("variables", name, [low, high], "empty bounds: `low` must be below `high`")
        _within_valid_range(name, low, high, law)
        scale = spec.get("scale", "linear")
        if scale not in SCALES:
            _fail(where, "scale", scale, f"must be one of {SCALES}")
        if scale == "log" and low <= 0:
            _fail(where, "low", low, "a log scale needs `low` > 0; use scale = \"linear\" to "
                                     "include zero")
        integer = spec.get("integer", False)
        if not isinstance(integer, bool):
            _fail(where, "integer", integer, "must be true or false")
        if integer and math.ceil(low) > math.floor(high):
            _fail("variables", name, [low, high], "holds no whole number; widen the bounds")
        variables.append(Variable(name=name, low=low, high=high, scale=scale, integer=integer,
                                  units=units))
    return tuple(variables)


def _within_valid_range(name, low, high, law=None):
    """Refuse bounds a model parameter cannot take (``mass`` below zero): the designs there
    would fail one by one instead of being refused before the search.

    Only the parameter's own range counts: a bound refused with the defaults of the others
    (``coulomb_force`` above the default ``stiction_force``) may be fine with their values
    in a design, which then fails alone as an infeasible case.
    """
    import re

    from qzs.model.controller import ControllerParameters
    from qzs.model.isolator import IsolatorParameters
    from qzs.model.registry import update_parameters

    if name not in ALL_PARAMETERS or not ALL_PARAMETERS[name].numeric:
        return
    _law_has("variables", name, {"low": low, "high": high}, law)
    for key, bound in (("low", low), ("high", high)):
        try:
            update_parameters(IsolatorParameters(spring=law), ControllerParameters(),
                              {name: bound})
        except ParameterError as error:
            if set(re.findall(r"`([a-z_]+)`", str(error))) - {name}:
                continue  # a relation between parameters, not this one's range
            _fail("variables", name, {"low": low, "high": high},
                  f"`{key}` = {bound!r} is outside the parameter's valid range "
                  f"({str(error).rstrip('.')}); choose bounds inside it")


def _law_has(table, name, spec, law):
    """Refuse a ``spring.*`` parameter the problem's spring law does not have."""
    if name in SPRING_PARAMETERS:
        try:
            check_law_parameters(law, [name])
        except ParameterError as error:
            _fail(table, name, spec, str(error).rstrip("."))


def _uncertain(document, kind, variables, law=None):
    table = _table(document, "uncertain")
    uncertain = []
    for name, spec in table.items():
        units = _parameter_name("uncertain", name, kind)
        _law_has("uncertain", name, spec, law)
        if name in variables:
            _fail("uncertain", name, spec, "is also a decision variable; a parameter is either "
                                           "searched or uncertain")
        if isinstance(spec, dict) and "values" in spec:
            _known(spec, f"uncertain.{name}", ("values",))
            values = spec["values"]
            if not isinstance(values, list) or not values:
                _fail(f"uncertain.{name}", "values", values, "must be a non-empty list")
            values = [_number(f"uncertain.{name}", "values", v) for v in values]
            uncertain.append(Uncertainty(name=name, distribution="values",
                                         settings={"values": values}, units=units))
            continue
        try:
            distribution, settings = parse_distribution(name, spec)
        except ParameterError as error:
            allowed = ", ".join(DISTRIBUTIONS) + ", or { values = [...] }"
            raise ProblemError("uncertain", name, spec, f"{error} (distributions: {allowed})") \
                from None
        uncertain.append(Uncertainty(name=name, distribution=distribution, settings=settings,
                                     units=units))
    return tuple(uncertain)


def _goal(table, index, spec, constraint, analysis):
    where = f"{table}[{index}]"
    if not isinstance(spec, dict):
        _fail(table, str(index), spec, "each entry must be a table with a `metric`")
    allowed = ["metric", "statistic", "quantile", "frequency", "band"]
    allowed += ["max", "min"] if constraint else ["sense", "scale"]
    _known(spec, where, allowed)
    metric = spec.get("metric")
    if metric not in METRICS:
        _fail(where, "metric", metric, "not a metric; metrics are: " + ", ".join(METRICS))
    definition = METRICS[metric]
    options = {}
    for option in ("frequency", "band"):
        if option in spec and option not in definition.options:
            _fail(where, option, spec[option], f"metric {metric!r} takes no `{option}`")
    if "frequency" in definition.options:
        if "frequency" not in spec:
            _fail(where, "frequency", None, f"metric {metric!r} needs `frequency` [Hz]")
        frequency = _number(where, "frequency", spec["frequency"])
        low, high = analysis["band"]
        if not low < frequency <= high:
            _fail(where, "frequency", frequency, f"must lie in the analysis band "
                                                 f"{low:g}-{high:g} Hz ([analysis] band)")
        options["frequency"] = frequency
    if "band" in definition.options:
        band = spec.get("band", list(analysis["band"]))
        if (not isinstance(band, list) or len(band) != 2
                or not 0 <= _number(where, "band", band[0]) < _number(where, "band", band[1])):
            _fail(where, "band", band, "must be [low, high] with 0 <= low < high [Hz]")
        options["band"] = [float(band[0]), float(band[1])]
    statistic = spec.get("statistic", "mean")
    if statistic not in STATISTICS:
        _fail(where, "statistic", statistic, f"must be one of {STATISTICS}")
    quantile = None
    if statistic == "quantile":
        if "quantile" not in spec:
            _fail(where, "quantile", None, "statistic \"quantile\" needs `quantile` in (0, 1)")
        quantile = real("quantile", spec["quantile"], _in(where), minimum=0.0, maximum=1.0,
                        strict=True)
    elif "quantile" in spec:
        _fail(where, "quantile", spec["quantile"], "applies to statistic = \"quantile\" only")
    bound = None
    if constraint:
        if ("max" in spec) == ("min" in spec):
            _fail(where, "max", spec.get("max"), "a constraint needs exactly one of `max` "
                                                 "(an upper bound) or `min` (a lower bound)")
        sense = "minimize" if "max" in spec else "maximize"
        bound = _number(where, "max" if "max" in spec else "min", spec.get("max", spec.get("min")))
    else:
        sense = spec.get("sense", "minimize")
        if sense not in SENSES:
            _fail(where, "sense", sense, f"must be one of {SENSES}")
        scale = spec.get("scale", "linear")
        if scale not in SCALES:
            _fail(where, "scale", scale, f"must be one of {SCALES}")
        if scale == "log" and definition.lowest is None:
            _fail(where, "scale", scale, f"{metric!r} can be negative; a log scale needs a "
                                         "metric that stays positive")
    return Goal(metric=metric, column=metric_column(metric, options), options=options,
                statistic=statistic, quantile=quantile, sense=sense, bound=bound,
                units=definition.units, title=definition.title(options),
                scale="linear" if constraint else scale)


def _settings(document, name, defaults):
    table = _table(document, name)
    _known(table, name, tuple(defaults))
    return {**defaults, **table}


def _positive_int(table, key, value, limit=None):
    integer(key, value, 1, _in(table))
    if limit is not None and value > limit:
        raise CountLimitError(f"[{table}] {key}", value, limit, "draws" if key == "samples"
                              else key, "use fewer")
    return value


def _infeasible(constraints):
    """Pairs of bounds on one statistic of one metric that no value meets."""
    for i, a in enumerate(constraints):
        for b in constraints[i + 1:]:
            if (a.label == b.label and a.sense != b.sense):
                upper, lower = (a, b) if a.sense == "minimize" else (b, a)
                if upper.bound < lower.bound:
                    _fail("constraints", upper.column, [lower.bound, upper.bound],
                          f"no design can meet both `min = {lower.bound:g}` and "
                          f"`max = {upper.bound:g}` on {upper.label}: the set is infeasible")
    for goal in constraints:
        floor = METRICS[goal.metric].lowest
        if goal.sense == "minimize" and floor is not None and goal.bound < floor:
            _fail("constraints", goal.column, goal.bound,
                  f"{goal.metric} is never below {floor:g}{_unit(goal.units)}: no design "
                  f"meets `max = {goal.bound:g}`")
        top = METRICS[goal.metric].highest
        if goal.sense == "maximize" and top is not None and goal.bound > top:
            _fail("constraints", goal.column, goal.bound,
                  f"{goal.metric} is never above {top:g}{_unit(goal.units)}: no design "
                  f"meets `min = {goal.bound:g}`")


def _spring(document, path):
    """The ``[spring]`` table's law (None: the MagSpring's tanh), as plain data for the sweep
    (a table's CSV read here, relative to the problem file)."""
    if "spring" not in document:
        return None
    try:
        return spring_from_table(document["spring"], path)
    except ParameterError as error:
        raise ProblemError("spring", "", None, str(error)) from None  # it names the key


def _problem(document, where, stem, path=None):
    try:
        _known(document, "top level", TABLES)
        law = _spring(document, path)
        if law is not None:
            document = {**document, "spring": law.to_dict()}
        head = _table(document, "problem")
        _known(head, "problem", ("name", "title", "description"))
        name = str(head.get("name", stem))
        excitation = _table(document, "excitation")
        kind = excitation.get("kind", "chirp")
        if kind not in EXCITATION_PARAMETERS:
            _fail("excitation", "kind", kind, f"must be one of {tuple(EXCITATION_PARAMETERS)}")
        variables = _variables(document, kind, law)
        names = [v.name for v in variables]
        uncertain = _uncertain(document, kind, names, law)
        fixed = _table(document, "parameters")
        for key in fixed:
            if key in names or key in [u.name for u in uncertain]:
                _fail("parameters", key, fixed[key], "is also searched or uncertain; remove it "
                                                     "from [parameters]")
        robust = _settings(document, "robust", ROBUST_DEFAULTS)
        if uncertain:
            samples = _positive_int("robust", "samples", robust["samples"], MAX_SAMPLES)
        else:
            if "samples" in _table(document, "robust"):
                _fail("robust", "samples", robust["samples"], "draws apply to [uncertain] "
                                                              "parameters; there are none")
            samples = 1
        if robust["method"] not in ("lhs", "random"):
            _fail("robust", "method", robust["method"], "must be \"lhs\" or \"random\"")
        checked_seed("seed", robust["seed"], _in("robust"))
        base = _sweep(document, name, variables, uncertain)
        objectives = tuple(_goal("objectives", i, spec, False, base.analysis)
                           for i, spec in enumerate(_table(document, "objectives", list)))
        if not objectives:
            _fail("objectives", "", [], "a problem needs at least one objective: add "
                                        "[[objectives]] with metric = \"...\"")
        constraints = tuple(_goal("constraints", i, spec, True, base.analysis)
                            for i, spec in enumerate(_table(document, "constraints", list)))
        sweep = _sweep(document, name, variables, uncertain, (*objectives, *constraints),
                       base.analysis)
        _infeasible(constraints)
        if not uncertain:
            for goal in (*objectives, *constraints):
                if goal.statistic != "mean":
                    _fail("objectives" if goal.bound is None else "constraints", goal.column,
                          goal.statistic, "a statistic over draws needs [uncertain] "
                                          "parameters; leave `statistic` out")
        optimizer = _settings(document, "optimizer", OPTIMIZER_DEFAULTS)
        if optimizer["algorithm"] not in ALGORITHMS:
            _fail("optimizer", "algorithm", optimizer["algorithm"], f"must be one of {ALGORITHMS}"
                                                                    " (pymoo's NSGA-II)")
        for key in ("population", "generations"):
            _positive_int("optimizer", key, optimizer[key], 100_000)
        if optimizer["population"] < MIN_POPULATION:
            _fail("optimizer", "population", optimizer["population"], "NSGA-II needs at least "
                  f"{MIN_POPULATION} designs per generation")
        checked_seed("seed", optimizer["seed"], _in("optimizer"))
        sensitivity = _sensitivity(document, objectives, constraints)
    except ProblemError as error:
        if error.source:
            raise
        raise ProblemError(error.table, error.key, error.value, error.fix, source=where) \
            from None
    return DesignProblem(name=name, title=str(head.get("title", name)), variables=variables,
                         uncertain=uncertain, samples=samples, seed=int(robust["seed"]),
                         sampling=robust["method"], objectives=objectives,
                         constraints=constraints, optimizer=optimizer, sensitivity=sensitivity,
                         sweep=sweep, document=document, source=where)


def _sensitivity(document, objectives, constraints):
    settings = _settings(document, "sensitivity", SENSITIVITY_DEFAULTS)
    if settings["method"] not in SENSITIVITY_METHODS:
        _fail("sensitivity", "method", settings["method"],
              f"must be one of {SENSITIVITY_METHODS} (SALib's Saltelli/Sobol or Morris)")
    for key in ("samples", "trajectories", "levels"):
        _positive_int("sensitivity", key, settings[key], 1_000_000)
    checked_seed("seed", settings["seed"], _in("sensitivity"))
    if not 0 < _number("sensitivity", "confidence", settings["confidence"]) < 1:
        _fail("sensitivity", "confidence", settings["confidence"], "must lie in (0, 1)")
    columns = [g.column for g in (*objectives, *constraints)]
    chosen = settings["metrics"]
    if chosen is None:
        settings["metrics"] = list(dict.fromkeys(columns))
    elif not isinstance(chosen, list) or not chosen or any(c not in columns for c in chosen):
        _fail("sensitivity", "metrics", chosen, "must list metric columns of the objectives "
                                                f"or constraints: {', '.join(columns)}")
    return settings


def _sweep(document, name, variables, uncertain, goals=None, resolved=None):
    """The problem's evaluation as a sweep: everything but what is searched or drawn.

    Without ``goals``, the sweep that resolves the analysis settings the goals are checked
    against; with them and that sweep's ``resolved`` analysis, the one that records what
    they need.
    """
    from qzs.workflows.design_space.metrics import sweep_outputs

    grid = {v.name: [v.low, v.high] for v in variables}
    grid.update({u.name: [u.nominal] for u in uncertain})
    analysis = dict(_table(document, "analysis"))
    sweep = {"sweep": {"name": name}, "parameters": _table(document, "parameters"),
             **({"spring": document["spring"]} if "spring" in document else {}),
             "excitation": _table(document, "excitation"), "grid": grid,
             "simulation": _table(document, "simulation"), "analysis": analysis,
             "outputs": {"transmissibility": False}}
    if goals is not None:
        extra, outputs = sweep_outputs(goals, resolved)
        sweep["analysis"] = {**analysis, **extra}
        if "band" not in analysis:
            sweep["analysis"]["band"] = resolved["band"]
        sweep["outputs"] = outputs
    try:
        return load_sweep(sweep)
    except CountLimitError:
        raise
    except ParameterError as error:
        raise ProblemError("parameters, excitation, simulation or analysis", "", "",
                           str(error).removeprefix("sweep definition: ")) from None


def _spread_text(uncertain):
    """An uncertain parameter's spread in words: ``values 5, 10, 15 kg``,
    ``uniform 5 .. 15 N``, ``normal mean 6.4, sigma 0.2 kg``."""
    settings, unit = dict(uncertain.settings), uncertain.units or "-"
    if uncertain.distribution == "values":
        return f"values {', '.join(f'{v:g}' for v in settings['values'])} {unit}"
    if {"low", "high"} <= set(settings) and len(settings) == 2:
        return f"{uncertain.distribution} {settings['low']:g} .. {settings['high']:g} {unit}"
    shown = ", ".join(f"{k} {v:g}" if isinstance(v, (int, float)) else f"{k} {v}"
                      for k, v in settings.items())
    return f"{uncertain.distribution} {shown} {unit}"


def plan_text(problem: DesignProblem) -> str:
    """What a search will evaluate: variables, uncertainty, goals, cases and steps.

    Parameters
    ----------
    problem : DesignProblem
        The problem.

    Returns
    -------
    str
        A few lines of text (``qzs optimize --dry-run``).
    """
    o, a, s = problem.optimizer, problem.sweep.analysis, problem.sweep.simulation
    per_generation = o["population"] * problem.samples
    simulates = any(METRICS[g.metric].source != "linear" for g in problem.goals)
    lines = [f"problem {problem.name!r}: {problem.title}",
             f"  NSGA-II: {o['population']} designs x {o['generations']} generations, seed "
             f"{o['seed']}; {problem.samples} draw(s) per design -> {per_generation} cases "
             "per generation, " + ("one lockstep batch each" if simulates else
                                   "each from the linearised loop's closed forms")]
    if simulates:
        lines.append(f"  {problem.sweep.excitation_kind} excitation, {a['duration']:g} s per "
                     f"case, {a['sample_rate']:g} Hz output")
    lines += [f"  variable  {v.name:<22} {v.low:g} .. {v.high:g} {v.units or '-'} ({v.scale}"
              f"{', integer' if v.integer else ''})" for v in problem.variables]
    lines += [f"  uncertain {u.name:<22} {_spread_text(u)}" for u in problem.uncertain]
    lines += [f"  objective {g.describe()}" for g in problem.objectives]
    lines += [f"  constraint {g.describe()}" for g in problem.constraints]
    if not simulates:
        lines.append("  linear metrics only: no simulation (neither an excitation nor an "
                     "integration step)")
    elif s["dt"] is not None:
        steps = o["generations"] * per_generation * a["duration"] / s["dt"]
        lines.append(f"  dt = {s['dt']:g} s: about {steps:.3g} integration steps in all")
    else:
        lines.append(f"  dt chosen before the first generation for {s['tolerance_db']:g} dB")
    return "\n".join(lines)
