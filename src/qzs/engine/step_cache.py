"""A cache of accuracy-driven step choices on disk, keyed by everything the choice reads.

:func:`qzs.engine.accuracy.choose_step` integrates a short probe of the excitation at three
or more steps and compares them: 0.1-0.2 s warm on the paper's chirp, plus about 0.5 s to
import the spectral analysis in a new process. A command run twice with the same model,
excitation and settings asks the same question twice; the answer is a pure function of its
inputs and of the code that computes it, so it is kept on disk under a key made of both:

- every input of the choice (excitation, isolator, controller, initial state, solver,
  output rate, tolerance and measure, band, probe length, Welch length, halvings, safety),
  each dataclass field by its exact ``repr`` (arrays by the SHA-256 of their bytes);
- the version of qzs and the SHA-256 of every source the choice runs: the modules that make
  it (:data:`_ROOTS`), every ``qzs`` module they import, at module level or inside a
  function, the modules those import in turn, and the packages above each
  (:func:`choice_sources`, computed from the sources themselves, so that a module the choice
  comes to import is in the key without a list to keep): an edited kernel, search, spectral
  estimate or run never reuses a choice made by the old one.

Records are small JSON files in ``$QZS_CACHE_DIR/steps`` (default
``$XDG_CACHE_HOME/qzs/steps``, else ``~/.cache/qzs/steps``), written atomically. The cache is
best effort: a folder that cannot be read or written, or a damaged record, means the choice
is made again, never an error (docs/model.md §7).
"""
import dataclasses
import functools
import hashlib
import json
import math
import os
import re
import tempfile
from pathlib import Path

import numpy as np

from qzs.engine.step_search import MEASURE_UNITS, StepChoice

__all__ = ["CACHE_ENV", "cache_folder", "cache_key", "choice_sources", "load", "store",
           "load_choice", "store_choice"]

#: Environment variable naming the folder of qzs's caches (the step choices go to ``steps/``).
CACHE_ENV = "QZS_CACHE_DIR"
#: The modules that make a step choice: :func:`qzs.engine.accuracy.choose_step`,
#: :func:`qzs.engine.accuracy_batch.choose_batch_step` and this record's reader.
_ROOTS = ("qzs.engine.accuracy", "qzs.engine.accuracy_batch", "qzs.engine.step_cache")
#: An import statement: ``from <module> import <names>`` (a parenthesised list may span
#: lines) or ``import <modules>``, at any indentation (inside a function too).
_IMPORT = re.compile(r"^[ \t]*(?:from[ \t]+([\w.]+)[ \t]+import[ \t]+(\([^)]*\)|[^\n]*)"
                     r"|import[ \t]+([^\n]*))", re.MULTILINE)
#: What no run executes: comments, and an ``if TYPE_CHECKING:`` block (its lines indented
#: deeper than the ``if``, blank lines among them).
_NOT_RUN = re.compile(r"#[^\n]*|^([ \t]*)if TYPE_CHECKING:[^\n]*\n(?:\1[ \t]+[^\n]*\n|[ \t]*\n)*",
                      re.MULTILINE)
#: Version of the record's layout; a record of another version is ignored.
_FORMAT = 1


def cache_folder():
    """The folder of the step cache (not created here).

    Returns
    -------
    Path
        ``$QZS_CACHE_DIR/steps``, else ``$XDG_CACHE_HOME/qzs/steps``, else
        ``~/.cache/qzs/steps``.
    """
    root = os.environ.get(CACHE_ENV)
    if not root:
        base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
        root = os.path.join(base, "qzs")
    return Path(root) / "steps"


def _imported(text):
    """The ``qzs`` module names an import statement of ``text`` may name (a superset: a name
    imported from a module is a candidate submodule; :func:`_module_file` keeps the files)."""
    found = set()
    for module, names, plain in _IMPORT.findall(_NOT_RUN.sub("", text)):
        if module:
            candidates = [module] + [f"{module}.{name.split()[0]}"
                                     for name in names.strip("()").split(",") if name.strip()]
        else:
            candidates = [name.split()[0] for name in plain.split(",") if name.strip()]
        found.update(c for c in candidates if c == "qzs" or c.startswith("qzs."))
    return found


def _module_file(root, module):
    """The source of ``module`` below the package folder ``root``, or None (not a module)."""
    path = root.joinpath(*module.split(".")[1:])
    for candidate in (path.with_name(path.name + ".py"), path / "__init__.py"):
        if candidate.name != ".py" and candidate.is_file():
            return candidate
    return None


def _source_texts(root):
    """Path below ``root`` -> bytes of every source a choice runs (:func:`choice_sources`)."""
    texts, seen, todo = {}, set(), list(_ROOTS)
    while todo:
        module = todo.pop()
        if module in seen:
            continue
        seen.add(module)
        path = _module_file(root, module)
        if path is None:
            continue
        data = path.read_bytes()
        texts[path.relative_to(root).as_posix()] = data
        parts = module.split(".")
        todo += [".".join(parts[:i]) for i in range(1, len(parts))]  # its packages run too
        todo += sorted(_imported(data.decode("utf-8")))
    return dict(sorted(texts.items()))


def choice_sources(root=None):
    """The sources a step choice runs, whose SHA-256 is in every key (:func:`cache_key`).

    The modules of :data:`_ROOTS`, every ``qzs`` module they import (at module level or
    inside a function), the modules those import in turn, and the packages above each,
    read from the sources themselves.

    Parameters
    ----------
    root : path-like, optional
        The package folder (default this installation's ``qzs``).

    Returns
    -------
    tuple of str
        Paths below ``root`` (``engine/accuracy.py``), sorted.
    """
    root = Path(__file__).resolve().parents[1] if root is None else Path(root)
    return tuple(_source_texts(root))


def _fingerprint(root):
    """SHA-256 of qzs's version and of the sources a choice runs below ``root``."""
    from qzs._version import __version__

    digest = hashlib.sha256(__version__.encode())
    for name, data in _source_texts(root).items():
        digest.update(f"\n{name} {len(data)}\n".encode())
        digest.update(data)
    return digest.hexdigest()


@functools.lru_cache(maxsize=1)
def _code_fingerprint():
    """:func:`_fingerprint` of this installation, once per process."""
    return _fingerprint(Path(__file__).resolve().parents[1])


def _canonical(value):
    """A text that differs whenever ``value`` differs: exact reprs, arrays by their bytes."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        fields = ", ".join(f"{f.name}={_canonical(getattr(value, f.name))}"
                           for f in dataclasses.fields(value))
        return f"{type(value).__name__}({fields})"
    if isinstance(value, np.ndarray):
        array = np.ascontiguousarray(value)
        return (f"array({array.dtype.str}, {array.shape}, "
                f"{hashlib.sha256(array.tobytes()).hexdigest()})")
    if isinstance(value, (list, tuple)):
        return "(" + ", ".join(_canonical(v) for v in value) + ")"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k!r}: {_canonical(v)}" for k, v in sorted(value.items())) + "}"
    if isinstance(value, (float, np.floating)):
        return repr(float(value))
    return repr(value)


def cache_key(**inputs):
    """The key of a step choice: SHA-256 of its inputs and of the code that makes it.

    Parameters
    ----------
    **inputs
        Every input of the choice, by name (dataclasses, arrays, numbers, strings, None).

    Returns
    -------
    str
        64 hexadecimal digits.
    """
    text = _code_fingerprint() + "\n" + "\n".join(f"{name}={_canonical(value)}"
                                                   for name, value in sorted(inputs.items()))
    return hashlib.sha256(text.encode()).hexdigest()


def _encode(value):
    """JSON for floats that may be inf or NaN (stored as strings)."""
    if isinstance(value, float) and not math.isfinite(value):
        return repr(value)
    if isinstance(value, (list, tuple)):
        return [_encode(v) for v in value]
    return value


def _decode(value):
    if value in ("inf", "-inf", "nan"):
        return float(value)
    if isinstance(value, list):
        return [_decode(v) for v in value]
    return value


def load(key):
    """The record stored under ``key``, or None (absent, unreadable or of another layout).

    Parameters
    ----------
    key : str
        From :func:`cache_key`.

    Returns
    -------
    dict or None
    """
    try:
        with open(cache_folder() / f"{key}.json", encoding="utf-8") as handle:
            record = json.load(handle)
    except (OSError, ValueError):
        return None
    if not isinstance(record, dict) or record.get("format") != _FORMAT:
        return None
    return {name: _decode(value) for name, value in record.items()}


def store(key, record):
    """Keep ``record`` under ``key`` (atomically; silently skipped where it cannot be written).

    Parameters
    ----------
    key : str
        From :func:`cache_key`.
    record : dict
        JSON-serialisable values (floats may be inf or NaN).

    Returns
    -------
    bool
        Whether the record was written.
    """
    folder = cache_folder()
    tmp = None
    try:
        folder.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{key}.", suffix=".part", dir=folder)
        with os.fdopen(fd, "w", encoding="utf-8") as handle:
            json.dump({"format": _FORMAT, **{k: _encode(v) for k, v in record.items()}}, handle)
        os.replace(tmp, folder / f"{key}.json")
        return True
    except (OSError, TypeError, ValueError):
        if tmp is not None:
            Path(tmp).unlink(missing_ok=True)
        return False


#: The fields of a :class:`StepChoice` a cache record keeps (the probe is made again).
_RECORD_FIELDS = ("dt", "error", "measure", "tolerance", "reference_dt", "stability_limit",
                  "sample_rate", "solver", "probe_duration", "band", "history", "notes", "met")
#: The fields a batch's choice adds (:func:`qzs.engine.accuracy_batch.choose_batch_step`).
_BATCH_FIELDS = ("case_errors", "case_steps", "unmet")


def store_choice(key, choice):
    """Keep a step choice under ``key`` (:func:`store` of its record; the probe is not kept).

    Parameters
    ----------
    key : str
        From :func:`cache_key`.
    choice : StepChoice
        The choice (:func:`qzs.engine.accuracy.choose_step`,
        :func:`qzs.engine.accuracy_batch.choose_batch_step`).

    Returns
    -------
    bool
        Whether the record was written.
    """
    return store(key, {name: getattr(choice, name) for name in _RECORD_FIELDS + _BATCH_FIELDS})


def load_choice(key, probe, duration, cases=None):
    """The step choice kept under ``key``, or None (none, damaged, or not of this question).

    Parameters
    ----------
    key : str
        From :func:`cache_key`.
    probe : object
        The choice's probe excitation (made again, not kept).
    duration : float
        The probe's length [s]; a record of another length is not taken.
    cases : int, optional
        A batch's choice over this many cases: its per-case fields are read back too, and a
        record of another number of cases is not taken.

    Returns
    -------
    StepChoice or None
        With ``cached`` True.
    """
    record = load(key)
    if record is None:
        return None
    try:
        values = {name: record[name] for name in _RECORD_FIELDS}
        band = values["band"]
        values.update(band=None if band is None else (float(band[0]), float(band[1])),
                      history=tuple(tuple(float(x) for x in row) for row in values["history"]),
                      notes=tuple(str(note) for note in values["notes"]))
        if cases is not None:
            values.update(case_errors=tuple(float(x) for x in record["case_errors"]),
                          case_steps=tuple(float(x) for x in record["case_steps"]),
                          unmet=tuple(int(c) for c in record["unmet"]))
        choice = StepChoice(probe=probe, cached=True, **values)
    except (KeyError, TypeError, ValueError, IndexError):
        return None
    if not (isinstance(choice.dt, float) and choice.dt > 0 and choice.measure in MEASURE_UNITS
            and math.isclose(choice.probe_duration, duration)):
        return None
    if cases is not None and not (len(choice.case_errors) == len(choice.case_steps) == cases
                                  and all(0 <= c < cases for c in choice.unmet)):
        return None
    return choice
