"""Sweep definitions: reading and validating a sweep file, grids and sampling.

The TOML layout is described in :mod:`qzs.workflows.sweeps`. :func:`load_sweep` turns a file
(or a parsed document) into a frozen :class:`SweepDefinition`, with every mistake
reported the scipy way (what, the value, the fix); :func:`sample_cases` lists the
varied parameters of every case: grid points times random or Latin-hypercube
draws (``scipy.stats.qmc.LatinHypercube``) of the distributions.
"""
import hashlib
import itertools
import json
import math
import numbers
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any
import numpy as np

from qzs._validation import (integer, known_keys, positive_real, read_toml, real,
                             renamed_keyword)
from qzs._validation import seed as checked_seed
from qzs.analysis.spectral import required_duration, welch_average_count
from qzs.defaults import ACCURACY, ANALYSIS, REPORTED_FREQUENCIES, SIMULATION
from qzs.engine.batch import STATS
from qzs.engine.channels import run_channels
from qzs.engine.stability import SOLVERS
from qzs.errors import CountLimitError, ParameterError
from qzs.iotools.config import spring_from_table
from qzs.iotools.shipped import resolve_shipped, shipped_files
from qzs.model.controller import ControllerParameters
from qzs.model.excitation import build_excitation
from qzs.model.isolator import IsolatorParameters
from qzs.model import registry
from qzs.model.registry import ALL_PARAMETERS, dotted_names, update_parameters

__all__ = ["SweepDefinition", "load_sweep", "sample_cases", "draw_samples", "unit_draws",
           "shipped_sweeps", "parse_distribution", "frozen_distribution",
           "plan_text", "METHODS", "DISTRIBUTIONS", "EXCITATION_PARAMETERS", "MAX_CASES"]

METHODS = ("grid", "random", "lhs")
#: Most cases one sweep holds [-]: its case table lives in memory and every case is a
#: simulation of seconds; a larger study is several sweeps. Checked before any case is
#: built, so a grid of 1e8 points fails at once.
MAX_CASES = 1_000_000
_SPLIT = "split the study into several sweep files or coarsen the grid"
#: Distributions of uncertain parameters: name -> (required keys, optional keys).
DISTRIBUTIONS = {
    "uniform": (("low", "high"), ()),
    "normal": (("mean", "std"), ("low", "high")),  # optional bounds truncate it
    "lognormal": (("median", "sigma"), ()),        # sigma: standard deviation of ln(value)
    "loguniform": (("low", "high"), ()),
}
#: Excitation kinds a sweep can use and their parameters (``excitation.<name>`` in
#: [grid]/[distributions]); a recorded base motion has nothing to vary.
EXCITATION_PARAMETERS = {kind: parameters for kind, parameters
                         in registry.EXCITATION_PARAMETERS.items() if kind != "file"}
TABLES = ("sweep", "parameters", "excitation", "grid", "distributions", "simulation",
          "analysis", "outputs", "spring")
SWEEP_KEYS = ("name", "title", "description", "method", "samples", "seed", "batch_size")
#: ``dt`` None: the step is chosen for ``tolerance`` (kept as ``tolerance_db`` [dB], the
#: records' name) before the sweep runs
#: (:func:`qzs.workflows.sweeps.step.choose_sweep_step`); a ``dt`` in the file fixes it.
SIMULATION_DEFAULTS = {"dt": None, "solver": SIMULATION["solver"],
                       "tolerance_db": ACCURACY["tolerance_db"]}
#: Folder of the shipped sweep files, inside the package.
SHIPPED = "workflows/sweeps/sweep_files"
OUTPUT_KEYS = ("stats", "metrics", "transmissibility", "coherence", "time_series", "bands",
               "rms_bands")
METRICS = ("resonance_frequency", "resonance_peak", "isolation_onset", "minus_3db_frequency",
           "rolloff_db_per_decade")
_FORMAT = "qzs-sweep-1"


def _analysis_defaults():
    """The studies' analysis settings, with their quick FFT length and averages."""
    a = ANALYSIS
    return {"sample_rate": a["sample_rate"], "fft_length": a["quick_fft_length"],
            "n_averages": a["quick_n_averages"], "overlap": a["overlap"],
            "band": list(a["band"]), "at_frequencies": list(REPORTED_FREQUENCIES)}


@dataclass(frozen=True)
class SweepDefinition:
    """A validated sweep (the TOML layout is described in :mod:`qzs.workflows.sweeps`).

    Attributes
    ----------
    name, title : str
        Short name (the default store is ``<name>.zarr``) and title.
    method : {"grid", "random", "lhs"}
        How the cases are drawn: full factorial only, or random or Latin-hypercube samples.
    samples : int
        Draws per grid point (1 for a pure grid).
    seed : int or None
        Seed of the draws; the same seed gives the same cases.
    batch_size : int
        Cases per batch [cases].
    parameters : dict
        Fixed model parameters (registry names).
    spring : SpringLaw or None
        The isolator's spring law from the file's ``[spring]`` table (docs/model.md §3.1;
        its ``spring.*`` parameters may be fixed or varied), None for the MagSpring's tanh.
    excitation_kind : str
        Kind of the excitation (``chirp``, ``sine``, ``random``).
    excitation : dict
        Fixed excitation values (without the ``excitation.`` prefix).
    grid : dict
        Name -> tuple of values, in case order (excitation parameters first).
    distributions : dict
        Name -> (distribution name, dict of its keys).
    simulation, analysis, outputs : dict
        Resolved settings (defaults filled in).
    document : dict
        The parsed TOML file; its hash identifies the sweep in a store.
    source : str
        The file it was read from.
    """

    name: str
    title: str
    method: str
    samples: int
    seed: int | None
    batch_size: int
    parameters: dict
    spring: Any
    excitation_kind: str
    excitation: dict
    grid: dict
    distributions: dict
    simulation: dict
    analysis: dict
    outputs: dict
    document: dict = field(repr=False)
    source: str = ""

    @property
    def varied(self) -> tuple[str, ...]:
        """Names of the parameters that vary, grid first."""
        return (*self.grid, *self.distributions)

    @property
    def n_cases(self) -> int:
        """Number of cases: grid points times samples."""
        return math.prod(len(v) for v in self.grid.values()) * self.samples

    @property
    def hash(self) -> str:
        """SHA-256 of the canonical sweep document (what a store must match to resume)."""
        text = json.dumps({"format": _FORMAT, "document": self.document}, sort_keys=True,
                          default=str)
        return hashlib.sha256(text.encode()).hexdigest()

    @property
    def frequency(self) -> np.ndarray:
        """Frequencies [Hz] kept for the transmissibility curve: the bins inside ``band``."""
        a = self.analysis
        f = np.fft.rfftfreq(a["fft_length"], 1.0 / a["sample_rate"])
        low, high = a["band"]
        return f[(f > low) & (f <= high)]


# ---------------------------------------------------------------- loading and validation
def shipped_sweeps():
    """Paths of the sweep definitions shipped with qzs."""
    return shipped_files(SHIPPED)


def load_sweep(source: str | Path | Mapping[str, Any]) -> SweepDefinition:
    """Read and validate a sweep definition.

    Parameters
    ----------
    source : str, Path or dict
        A TOML file, the name of a shipped sweep (e.g. ``"pi_vs_stiction"``), or an
        already parsed document.

    Returns
    -------
    SweepDefinition

    Raises
    ------
    ParameterError
        Unknown table, key or parameter (the valid names are listed), an empty
        range, a bad distribution (the allowed ones and their keys are listed), a
        bad sampling method, or an invalid fixed value.
    """
    path = None
    if isinstance(source, dict):
        document, where, stem = source, "sweep definition", "sweep"
    else:
        path = resolve_shipped(source, SHIPPED, "sweep", "sweeps")
        document = read_toml(path, "sweep file", empty=(
            "write the sweep's tables into it (`qzs docs sweeps` describes them; the shipped "
            "sweeps are examples)"))
        where, stem = repr(str(path)), path.stem
    try:
        return _definition(document, where, stem, path)
    except CountLimitError:  # names its table and key already; keeps its data
        raise
    except ParameterError as error:
        raise ParameterError(f"{where}: {error}") from None


def _keys(table, name, allowed):
    return known_keys(table, allowed, f"[{name}]")


def _simulation_table(table):
    """``[simulation]`` with its tolerance under the records' key ``tolerance_db`` [dB].

    The file writes ``tolerance`` (the one spelling); ``tolerance_db`` is its deprecated
    name, read one release more with a :class:`DeprecationWarning`
    (:func:`qzs._validation.renamed_keyword`).
    """
    table = dict(_keys(table, "simulation", (*SIMULATION_DEFAULTS, "tolerance")))
    tolerance = renamed_keyword("tolerance", table.pop("tolerance", None), "tolerance_db",
                                table.pop("tolerance_db", None), stacklevel=4)
    if tolerance is not None:
        table["tolerance_db"] = tolerance
    return table


def _check_name(name, kind):
    """A varied parameter must be a model parameter or ``excitation.<parameter of kind>``."""
    excitation = [f"excitation.{k}" for k in EXCITATION_PARAMETERS[kind]]
    if name not in ALL_PARAMETERS and name not in excitation:
        raise ParameterError(f"unknown parameter {name!r}; valid names are: "
                             f"{', '.join(sorted(ALL_PARAMETERS) + excitation)}.")


def _definition(document, where, stem, path=None):
    _keys(document, "top level", TABLES)
    spring = spring_from_table(document["spring"], path) if "spring" in document else None
    base = IsolatorParameters(spring=spring)
    head = _keys(document.get("sweep", {}), "sweep", SWEEP_KEYS)
    name = str(head.get("name", stem))
    method = head.get("method", "grid")
    if method not in METHODS:
        raise ParameterError(f"`method` must be one of {METHODS} (full grid, random sampling, "
                             f"Latin hypercube), got {method!r}.")
    seed = head.get("seed")
    if seed is not None:
        seed = checked_seed("seed", seed)
    batch_size = integer("batch_size", head.get("batch_size", 32), 1)

    excitation = dict(_keys(document.get("excitation", {}), "excitation",
                            ("kind",) + tuple({k for v in EXCITATION_PARAMETERS.values()
                                               for k in v})))
    kind = excitation.pop("kind", "chirp")
    if kind not in EXCITATION_PARAMETERS:
        raise ParameterError(f"excitation `kind` must be one of {tuple(EXCITATION_PARAMETERS)}, "
                             f"got {kind!r}.")
    _keys(excitation, "excitation", EXCITATION_PARAMETERS[kind])
    parameters = dict(_keys(dotted_names(document.get("parameters", {})), "parameters",
                            list(ALL_PARAMETERS)))
    update_parameters(base, ControllerParameters(), parameters)  # values

    grid_table = dotted_names(document.get("grid", {}))
    if not isinstance(grid_table, dict):
        raise ParameterError(f"[grid] must be a table, got {grid_table!r}.")
    grid = {}
    for key, spec in grid_table.items():
        _check_name(key, kind)
        grid[key] = _grid_values(key, spec)
    grid = dict(sorted(grid.items(), key=lambda item: not item[0].startswith("excitation.")))
    distributions = {}
    table = dotted_names(document.get("distributions", {}))
    if not isinstance(table, dict):
        raise ParameterError(f"[distributions] must be a table, got {table!r}.")
    for key, spec in table.items():
        _check_name(key, kind)
        distributions[key] = parse_distribution(key, spec)
    for key in (*grid, *distributions):
        if (key.split(".", 1)[1] in excitation if key.startswith("excitation.")
                else key in parameters):
            raise ParameterError(f"{key!r} is both fixed and varied; remove one of them.")
    registry.check_law_parameters(spring, [k for k in (*grid, *distributions)
                                           if k in registry.SPRING_PARAMETERS])
    both = sorted(set(grid) & set(distributions))
    if both:
        raise ParameterError(f"{both} appear in both [grid] and [distributions]; keep one.")
    if method == "grid":
        if distributions:
            raise ParameterError("[distributions] needs `method = \"random\"` or \"lhs\" in "
                                 "[sweep]; a grid takes explicit values in [grid].")
        if "samples" in head:
            raise ParameterError("`samples` applies to method \"random\" or \"lhs\", not "
                                 "\"grid\".")
        samples = 1
    else:
        if not distributions:
            raise ParameterError(f"method {method!r} needs a [distributions] table of the "
                                 "parameters to sample.")
        samples = integer("samples", head.get("samples", 0), 1)
        if samples > MAX_CASES:
            raise CountLimitError("[sweep] samples", samples, MAX_CASES, "cases",
                                  "draw fewer samples, or split the study into several sweep "
                                  "files (different seeds)")
    count = math.prod(len(v) for v in grid.values()) * samples
    if count > MAX_CASES:
        raise CountLimitError("[grid]" if grid else "[sweep] samples", count, MAX_CASES,
                              "cases", _SPLIT)
    if not grid and not distributions:
        raise ParameterError("nothing varies: add a [grid] or a [distributions] table.")

    given = _simulation_table(document.get("simulation", {}))
    simulation = {**SIMULATION_DEFAULTS, **given}
    if simulation["solver"] not in SOLVERS:
        raise ParameterError(f"`solver` must be one of {tuple(SOLVERS)}, got "
                             f"{simulation['solver']!r}.")
    if "dt" in given and "tolerance_db" in given:
        raise ParameterError("give either `dt` (a fixed step [s]) or `tolerance` (the "
                             "accuracy the step is chosen for [dB]) in [simulation], not both.",
                             ("dt", "tolerance"))
    if "dt" in given:
        simulation["dt"] = positive_real("dt", simulation["dt"])
        simulation["tolerance_db"] = None
    else:
        simulation["tolerance_db"] = positive_real("tolerance", simulation["tolerance_db"])
    analysis = _analysis(document.get("analysis", {}), simulation["dt"])
    top = excitation.get("f1")
    if (kind != "sine" and "band" not in document.get("analysis", {})
            and isinstance(top, (int, float)) and top > 0):
        analysis["band"][1] = min(analysis["band"][1], float(top))  # no excitation above
    outputs = _outputs(document.get("outputs", {}), analysis)
    definition = SweepDefinition(
        name=name, title=str(head.get("title", name)), method=method, samples=samples,
        seed=seed, batch_size=batch_size, parameters=parameters, spring=spring,
        excitation_kind=kind,
        excitation=excitation, grid=grid, distributions=distributions, simulation=simulation,
        analysis=analysis, outputs=outputs, document=document, source=where)
    if not any(k.startswith("excitation.") for k in definition.varied):
        case_excitation(definition.excitation_kind, definition.excitation,
                         definition.analysis)  # fixed excitation values are valid
    return definition


def case_excitation(kind, values, analysis):
    """The excitation of a case and its duration [s] (:func:`qzs.model.build_excitation`).

    Parameters
    ----------
    kind : {"chirp", "sine", "random"}
        Excitation kind.
    values : dict
        Excitation options (``amplitude`` [m], ``f0``/``f1``/``frequency`` [Hz],
        ``duration`` [s], ...); missing ones take the excitation's defaults.
    analysis : dict
        Resolved analysis settings; its ``duration`` [s] is the default length.
    """
    values = dict(values)
    duration = float(values.pop("duration", analysis["duration"]))
    if kind != "sine":  # a sine runs as long as the run; the others are that long
        values["duration"] = duration
    return build_excitation(kind, values), duration


def _grid_values(name, spec):
    """Values of one grid axis: a non-empty list, or {start, stop, num[, scale]} or {..., step}."""
    if isinstance(spec, list):
        if not spec:
            raise ParameterError(f"empty range for {name!r}: give at least one value.")
        return tuple(spec)
    if not isinstance(spec, dict):
        raise ParameterError(f"grid entry {name!r} must be a list of values or a table "
                             f"{{start, stop, num[, scale]}} or {{start, stop, step}}, got "
                             f"{spec!r}.")
    _keys(spec, f"grid.{name}", ("start", "stop", "num", "step", "scale"))
    if "start" not in spec or "stop" not in spec or ("num" in spec) == ("step" in spec):
        raise ParameterError(f"range {name!r} needs `start`, `stop` and one of `num` or "
                             f"`step`, got {spec!r}.")
    start = real(f"{name}.start", spec["start"])
    stop = real(f"{name}.stop", spec["stop"])
    scale = spec.get("scale", "linear")
    if scale not in ("linear", "log"):
        raise ParameterError(f"`{name}.scale` must be 'linear' or 'log', got {scale!r}.")
    if "num" in spec:
        num = spec["num"]
        if isinstance(num, bool) or not isinstance(num, numbers.Integral) or num < 1:
            raise ParameterError(f"empty range for {name!r}: `num` must be an integer >= 1, "
                                 f"got {num!r}.")
        if num > MAX_CASES:
            raise CountLimitError(f"[grid] {name}.num", num, MAX_CASES, "cases", _SPLIT)
        if scale == "log":
            if start <= 0 or stop <= 0:
                raise ParameterError(f"a log range for {name!r} needs `start` > 0 and "
                                     f"`stop` > 0, got {start!r} and {stop!r}.")
            return tuple(float(v) for v in np.geomspace(start, stop, int(num)))
        return tuple(float(v) for v in np.linspace(start, stop, int(num)))
    step = positive_real(f"{name}.step", spec["step"])
    if scale == "log":
        raise ParameterError(f"range {name!r}: `step` is for linear ranges; use `num` with "
                             "scale = 'log'.")
    if stop < start:
        raise ParameterError(f"empty range for {name!r}: `stop` ({stop!r}) is below `start` "
                             f"({start!r}).")
    count = int(math.floor((stop - start) / step * (1 + 1e-12))) + 1
    if count > MAX_CASES:
        raise CountLimitError(f"[grid] {name}.step", count, MAX_CASES, "cases",
                              f"{_SPLIT} (a larger `step`)")
    return tuple(float(start + i * step) for i in range(count))


def parse_distribution(name, spec):
    """A distribution table of a sweep or problem file, checked: its kind and its values.

    Parameters
    ----------
    name : str
        The parameter it is of, for the messages.
    spec : dict
        The table: ``distribution`` (a name of :data:`DISTRIBUTIONS`; ``log-normal`` is
        taken for ``lognormal``) and that distribution's keys.

    Returns
    -------
    kind : str
        The distribution's name in :data:`DISTRIBUTIONS`.
    values : dict of str to float
        Its keys' values, finite, in the parameter's unit.

    Raises
    ------
    ParameterError
        Not a table, an unknown distribution, missing or unknown keys, a non-positive
        spread, ``low`` not below ``high``, a loguniform range not above zero.
    """
    allowed = "; ".join(f"{d} {{{', '.join(r + tuple(f'[{o}]' for o in opt))}}}"
                        for d, (r, opt) in DISTRIBUTIONS.items())
    if not isinstance(spec, dict) or "distribution" not in spec:
        raise ParameterError(f"distribution of {name!r} must be a table with a `distribution` "
                             f"key; allowed are: {allowed}. Got {spec!r}.")
    kind = spec["distribution"]
    if kind == "log-normal":
        kind = "lognormal"
    if kind not in DISTRIBUTIONS:
        raise ParameterError(f"unknown distribution {kind!r} for {name!r}; allowed are: "
                             f"{allowed}.")
    required, optional = DISTRIBUTIONS[kind]
    keys = known_keys({k: v for k, v in spec.items() if k != "distribution"}, optional,
                      f"distribution {kind!r} of {name!r}", required=required)
    values = {k: real(f"{name}.{k}", v) for k, v in keys.items()}
    for key in ("std", "sigma", "median"):
        if key in values and values[key] <= 0:
            raise ParameterError(f"`{name}.{key}` must be positive, got {values[key]!r}.")
    if "low" in values and "high" in values and not values["low"] < values["high"]:
        raise ParameterError(f"distribution of {name!r} needs `low` < `high`, got "
                             f"{values['low']!r} and {values['high']!r}.")
    if kind == "loguniform" and values["low"] <= 0:
        raise ParameterError(f"a loguniform {name!r} needs `low` > 0, got {values['low']!r}.")
    return kind, values


def _analysis(table, dt):
    allowed = tuple(_analysis_defaults()) + ("duration",)
    given = _keys(table, "analysis", allowed)
    analysis = {**_analysis_defaults(), **given}
    if "duration" in given and "n_averages" in given:
        raise ParameterError("give either `n_averages` or `duration` in [analysis], not both.")
    rate = analysis["sample_rate"] = positive_real("sample_rate", analysis["sample_rate"])
    ratio = 1.0 / (rate * dt) if dt is not None else 1.0  # a chosen step divides it
    if abs(ratio - round(ratio)) > 1e-6 * ratio or round(ratio) < 1:
        raise ParameterError(f"`sample_rate` ({rate!r} Hz) must divide the integration rate "
                             f"1/dt = {1 / dt:g} Hz into a whole number of steps.")
    fft_length = analysis["fft_length"] = integer("fft_length", analysis["fft_length"], 8)
    overlap = analysis["overlap"] = real("overlap", analysis["overlap"])
    if "duration" in given:
        analysis["duration"] = positive_real("duration", given["duration"])
        samples = int(analysis["duration"] * rate)
        analysis["n_averages"] = welch_average_count(samples, fft_length, overlap)
        if analysis["n_averages"] < 1:
            raise ParameterError(f"`duration` ({analysis['duration']!r} s) is shorter than "
                                 f"one FFT segment ({fft_length / rate:g} s).")
    else:
        analysis["n_averages"] = integer("n_averages", analysis["n_averages"], 1)
        analysis["duration"] = required_duration(fft_length, analysis["n_averages"], rate,
                                                 overlap)
    band = analysis["band"]
    if (not isinstance(band, list) or len(band) != 2
            or not 0 <= real("band", band[0]) < real("band", band[1])):
        raise ParameterError(f"`band` must be [low, high] with 0 <= low < high [Hz], got "
                             f"{band!r}.")
    analysis["band"] = [float(band[0]), float(min(band[1], rate / 2))]
    spots = analysis["at_frequencies"]
    if not isinstance(spots, list):
        raise ParameterError(f"`at_frequencies` must be a list of frequencies [Hz], got "
                             f"{spots!r}.")
    analysis["at_frequencies"] = [positive_real("at_frequencies", f) for f in spots]
    return analysis


def _outputs(table, analysis):
    given = _keys(table, "outputs", OUTPUT_KEYS)
    metrics = list(METRICS) + [f"transmissibility_at_{f:g}_hz"
                               for f in analysis["at_frequencies"]]
    outputs = {"stats": list(STATS), "metrics": metrics, "transmissibility": True,
               "coherence": False, "time_series": [], "bands": {}, "rms_bands": {}, **given}
    for key, valid in (("stats", list(STATS)), ("metrics", metrics),
                       ("time_series", [c for c in run_channels(every_block=True)
                                        if c != "time"])):
        chosen = outputs[key]
        if not isinstance(chosen, list):
            raise ParameterError(f"`outputs.{key}` must be a list of names, got {chosen!r}.")
        unknown = [c for c in chosen if c not in valid]
        if unknown:
            raise ParameterError(f"unknown {key} {unknown}; valid names are: "
                                 f"{', '.join(valid)}.")
    for key in ("transmissibility", "coherence"):
        if not isinstance(outputs[key], bool):
            raise ParameterError(f"`outputs.{key}` must be true or false, got "
                                 f"{outputs[key]!r}.")
    resolution = analysis["sample_rate"] / analysis["fft_length"]
    f = np.fft.rfftfreq(analysis["fft_length"], 1.0 / analysis["sample_rate"])
    for key in ("bands", "rms_bands"):
        bands = outputs[key]
        if not isinstance(bands, dict):
            raise ParameterError(f"`outputs.{key}` must be a table name = [low, high], got "
                                 f"{bands!r}.")
        for label, edges in bands.items():
            if not label.isidentifier():
                raise ParameterError(f"band name {label!r} must be a plain identifier "
                                     "(letters, digits, underscore).")
            if (not isinstance(edges, list) or len(edges) != 2
                    or not 0 <= real(f"{key}.{label}", edges[0])
                    < real(f"{key}.{label}", edges[1])):
                raise ParameterError(f"band {label!r} must be [low, high] with 0 <= low < "
                                     f"high [Hz], got {edges!r}.")
            if not np.any((f > 0) & (f >= edges[0]) & (f <= edges[1])):
                raise ParameterError(f"band {label!r} {edges} Hz holds no frequency bin "
                                     f"(resolution {resolution:.3g} Hz); widen it or raise "
                                     "`fft_length`.")
    return outputs


# ---------------------------------------------------------------- sampling
def frozen_distribution(kind, p):
    """The scipy distribution of a checked distribution table (its ``ppf`` draws from it).

    Parameters
    ----------
    kind : str
        The distribution's name in :data:`DISTRIBUTIONS`.
    p : dict of str to float
        Its keys' values (:func:`parse_distribution`).

    Returns
    -------
    scipy.stats.rv_continuous_frozen
        A normal with ``low``/``high`` is truncated there.
    """
    from scipy import stats

    if kind == "uniform":
        return stats.uniform(loc=p["low"], scale=p["high"] - p["low"])
    if kind == "normal":
        if "low" in p or "high" in p:
            low, high = p.get("low", -np.inf), p.get("high", np.inf)
            return stats.truncnorm((low - p["mean"]) / p["std"], (high - p["mean"]) / p["std"],
                                   loc=p["mean"], scale=p["std"])
        return stats.norm(loc=p["mean"], scale=p["std"])
    if kind == "lognormal":
        return stats.lognorm(s=p["sigma"], scale=p["median"])
    return stats.loguniform(p["low"], p["high"])


def draw_samples(distributions, n, method="lhs", seed=None):
    """Draw ``n`` samples of independent parameters by inverse-CDF transform.

    Parameters
    ----------
    distributions : dict
        Name -> (distribution name, its keys), as in :data:`DISTRIBUTIONS`.
    n : int
        Number of samples.
    method : {"random", "lhs"}
        Independent uniform draws, or a Latin hypercube (``scipy.stats.qmc``): each
        parameter's range split into ``n`` equally likely strata, one sample in each.
    seed : int, optional
        Seed of ``numpy.random.default_rng``; the same seed gives the same samples.

    Returns
    -------
    dict of str to ndarray, shape (n,)
    """
    u = unit_draws(len(distributions), n, method, seed)
    return {name: frozen_distribution(kind, p).ppf(u[:, j])
            for j, (name, (kind, p)) in enumerate(distributions.items())}


def unit_draws(dimensions, n, method="lhs", seed=None):
    """``n`` points of the unit hypercube, the probabilities inverse CDFs turn into draws.

    Parameters
    ----------
    dimensions : int
        Parameters drawn.
    n : int
        Number of samples.
    method : {"random", "lhs"}
        Independent uniform draws, or a Latin hypercube (``scipy.stats.qmc``).
    seed : int, optional
        Seed of ``numpy.random.default_rng``; the same seed gives the same points.

    Returns
    -------
    ndarray, shape (n, dimensions)
        In ``[1e-12, 1 - 1e-12]``, so that unbounded inverse CDFs stay finite.
    """
    from scipy.stats import qmc

    rng = np.random.default_rng(seed)
    if method == "lhs":
        try:
            sampler = qmc.LatinHypercube(d=dimensions, rng=rng)
        except TypeError:  # scipy < 1.15 names it `seed`
            sampler = qmc.LatinHypercube(d=dimensions, seed=rng)
        u = sampler.random(n)
    else:
        u = rng.random((n, dimensions))
    return np.clip(u, 1e-12, 1 - 1e-12)


def sample_cases(definition):
    """The varied parameters of every case, in case order.

    Grid points (the last [grid] axis fastest, excitation axes slowest) times the
    samples (fastest): each grid point sees the same draws.

    Parameters
    ----------
    definition : SweepDefinition
        The sweep.

    Returns
    -------
    dict of str to ndarray, shape (n_cases,)
        One array per varied parameter, plus ``sample`` (the draw's index) for
        random and Latin-hypercube sweeps.
    """
    points = list(itertools.product(*definition.grid.values())) or [()]
    n_samples = definition.samples
    columns = {name: np.repeat(np.asarray([p[i] for p in points]), n_samples)
               for i, name in enumerate(definition.grid)}
    if definition.distributions:
        draws = draw_samples(definition.distributions, n_samples, definition.method,
                             definition.seed)
        columns.update({name: np.tile(v, len(points)) for name, v in draws.items()})
        columns["sample"] = np.tile(np.arange(n_samples), len(points))
    return columns


def plan_text(definition: SweepDefinition) -> str:
    """What a sweep will run: cases, batches, varied parameters and simulated steps.

    Parameters
    ----------
    definition : SweepDefinition
        The sweep.

    Returns
    -------
    str
        A few lines of text (``qzs sweep --dry-run``).
    """
    a, s = definition.analysis, definition.simulation
    columns = sample_cases(definition)
    lines = [f"sweep {definition.name!r}: {definition.title}",
             f"  {definition.n_cases} cases ({definition.method}), "
             f"{-(-definition.n_cases // definition.batch_size)} batches of "
             f"{definition.batch_size}",
             f"  {definition.excitation_kind} excitation, {a['duration']:g} s per case, "
             f"{_step_text(s)} ({s['solver']}), {a['sample_rate']:g} Hz output, "
             f"{a['fft_length']}-point FFT x {a['n_averages']} averages"]
    for name in definition.varied:
        values = columns[name]
        if values.dtype.kind in "fi":
            lines.append(f"  {name:<24} {values.min():g} .. {values.max():g} "
                         f"({np.unique(values).size} distinct)")
        else:
            lines.append(f"  {name:<24} {sorted(set(values.tolist()))}")
    if s["dt"] is not None:
        steps = definition.n_cases * a["duration"] / s["dt"]
        lines.append(f"  about {steps:.3g} integration steps in all")
    return "\n".join(lines)


def _step_text(simulation):
    if simulation["dt"] is not None:
        text = f"dt = {simulation['dt']:g} s"
        if simulation.get("tolerance_db") is not None:
            text += f" (chosen for {simulation['tolerance_db']:g} dB)"
        return text
    return (f"dt chosen at run time for the transmissibility within "
            f"{simulation['tolerance_db']:g} dB")
