"""The step cache (qzs.engine.step_cache): a repeated choice is read back, never made from a
stale or different question.

Properties that fail if the cache is wrong:

* the key changes with every input of the choice (a model parameter, the excitation, an
  array's content, the tolerance) and with the code that chooses: an edit to any source the
  choice runs (every file whose code a choice executes, traced in a fresh interpreter, is
  among them: the search, the Welch estimate, the single run, ...), and to a module it comes
  to import; not with an edit to a module it never runs;
* a choice read back equals the one made (every field), and reading it runs no probe: one
  that met its tolerance, a fallback that met none (still a fallback, its error still
  undefined), a batch's with its per-case fields;
* a damaged record, or a folder that cannot be written, costs a new choice, never an error,
  and no temporary file is left behind.
"""
import dataclasses
import math

import numpy as np
import pytest

from qzs import Chirp, DisplacementRecord, IsolatorParameters
from qzs.engine import step_cache
from qzs.engine.accuracy import choose_step

PROBE = 12.0
CHIRP = Chirp(duration=100.0, f1=5.0)


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv(step_cache.CACHE_ENV, str(tmp_path))
    return tmp_path / "steps"


def test_the_key_changes_with_every_input_and_with_the_code(monkeypatch):
    base = dict(excitation=CHIRP, isolator=IsolatorParameters(), tolerance=0.01, band=None)
    key = step_cache.cache_key(**base)
    assert key == step_cache.cache_key(**dict(base))  # equal inputs, equal keys
    changed = [
        dict(base, excitation=dataclasses.replace(CHIRP, f1=5.000000001)),
        dict(base, isolator=IsolatorParameters(stiction_force=10.000001)),
        dict(base, tolerance=0.02),
        dict(base, band=(1.0, 5.0)),
    ]
    assert len({step_cache.cache_key(**inputs) for inputs in changed} | {key}) == 5
    # an array by its content, not by numpy's abbreviated repr
    t = np.linspace(0.0, 10.0, 5001)
    displacement = 1e-3 * np.sin(t)
    nudged = displacement.copy()
    nudged[2500] += 1e-9  # numpy's repr of either array shows the same abbreviated values
    record = DisplacementRecord(time=t, displacement=displacement)
    other = DisplacementRecord(time=t, displacement=nudged)
    assert step_cache.cache_key(excitation=record) != step_cache.cache_key(excitation=other)
    # another version of the code: another key
    monkeypatch.setattr(step_cache, "_code_fingerprint", lambda: "another version")
    assert step_cache.cache_key(**base) != key


#: Runs a cold choice of each kind (a miss: the probe integrated, the record written) with
#: every Python frame of the process reported; prints the files whose code ran.
_TRACE = """
import json, sys, threading
ran = set()
def profile(frame, event, arg):
    if event == "call":
        ran.add(frame.f_code.co_filename)
sys.setprofile(profile)
threading.setprofile(profile)
from qzs import Chirp, ControllerParameters, IsolatorParameters
from qzs.engine.accuracy import choose_step
from qzs.engine.accuracy_batch import choose_batch_step
chirp = Chirp(duration=30.0, f1=5.0)
choose_step(chirp, tolerance=0.05, probe_duration=8.0, cache=True)
choose_step(chirp, tolerance_state=1e-15, probe_duration=2.0, max_halvings=2, fallback=True,
            cache=True)
cases = [(IsolatorParameters(), ControllerParameters(pi_kp=p)) for p in (50.0, 80.0)]
choose_batch_step(cases, chirp, tolerance=0.05, probe_duration=8.0, cache=True, workers=2)
sys.setprofile(None)
threading.setprofile(None)
print(json.dumps(sorted(ran)))
"""


def test_every_source_a_choice_runs_is_in_the_key(tmp_path):
    """The sources of the key (computed from the imports) hold every file of the package whose
    code ran during cold choices, single and batch, met and fallback, in a fresh interpreter
    (sys.setprofile sees every Python frame, module bodies included): the search
    (step_search.py), the Welch estimate (analysis/welch.py), the single run (single.py)
    among them, as the kernels, the model and this cache."""
    import json
    import os
    import subprocess
    import sys
    from pathlib import Path

    env = dict(os.environ, **{step_cache.CACHE_ENV: str(tmp_path)})
    out = subprocess.run([sys.executable, "-c", _TRACE], env=env, capture_output=True,
                         text=True, timeout=600, check=True)
    root = Path(step_cache.__file__).resolve().parents[1]
    ran = {Path(name).resolve() for name in json.loads(out.stdout.splitlines()[-1])}
    ran = {path.relative_to(root).as_posix() for path in ran if root in path.parents}
    sources = set(step_cache.choice_sources())
    assert {"engine/step_search.py", "analysis/welch.py", "engine/single.py",
            "engine/kernels.py", "model/isolator.py", "engine/step_cache.py"} <= ran
    assert ran <= sources, sorted(ran - sources)


def _package_copy(tmp_path):
    """The package's Python sources copied to ``tmp_path/qzs``."""
    import shutil
    from pathlib import Path

    root = Path(step_cache.__file__).resolve().parents[1]
    copy = tmp_path / "qzs"
    shutil.copytree(root, copy, ignore=lambda folder, names: [
        n for n in names if not (n.endswith(".py") or (Path(folder) / n).is_dir())
        or n == "__pycache__"])
    return copy


def test_an_edit_to_any_source_the_choice_runs_changes_the_key(tmp_path):
    """Each source of the key edited in turn (in a copy of the package): another fingerprint,
    each time; an import added to one brings the imported module (and its imports) into the
    key; an edit to a module no choice runs (a command's parser) keeps the key."""
    copy = _package_copy(tmp_path)
    sources = step_cache.choice_sources(copy)
    assert sources == step_cache.choice_sources()
    base = step_cache._fingerprint(copy)
    assert base == step_cache._code_fingerprint()
    for name in sources:
        path = copy / name
        original = path.read_bytes()
        path.write_bytes(original + b"\nEDITED = 1\n")
        assert step_cache._fingerprint(copy) != base, name
        path.write_bytes(original)
    assert step_cache._fingerprint(copy) == base
    unrelated = copy / "cli" / "simulate.py"
    assert "cli/simulate.py" not in sources and unrelated.is_file()
    unrelated.write_bytes(unrelated.read_bytes() + b"\nEDITED = 1\n")
    assert step_cache._fingerprint(copy) == base
    single = copy / "engine" / "single.py"
    added = b"\n\ndef later():\n    from qzs.cli import simulate\n"
    single.write_bytes(single.read_bytes() + added)
    assert "cli/simulate.py" in step_cache.choice_sources(copy)
    assert step_cache._fingerprint(copy) != base


def _package(root, files):
    """A package of ``files`` ({path below root: text}) at ``root``."""
    for name, text in files.items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    return root


def test_every_package_above_a_source_is_in_the_key(tmp_path):
    """Importing qzs.engine.accuracy runs qzs/__init__.py and qzs/engine/__init__.py first:
    both are sources of the key, the top package too, also in a package where no module
    names ``qzs`` itself in an import."""
    root = _package(tmp_path / "qzs", {"__init__.py": "", "engine/__init__.py": "",
                                       "engine/accuracy.py": "X = 1\n"})
    assert step_cache.choice_sources(root) == ("__init__.py", "engine/__init__.py",
                                               "engine/accuracy.py")


def test_text_moved_across_the_boundary_of_two_sources_changes_the_key(tmp_path):
    """Each source is hashed with its name and its length: two packages whose sources,
    concatenated with their names between them, are the same bytes (text, a name's line
    among it, moved from one file into the next) have different keys."""
    header = "\nengine/helper.py\n"
    first = "from qzs.engine import helper\n"
    common = {"__init__.py": "", "engine/__init__.py": ""}
    one = _package(tmp_path / "one" / "qzs", {**common, "engine/accuracy.py": first,
                                              "engine/helper.py": "# c" + header + "# d\n"})
    two = _package(tmp_path / "two" / "qzs", {**common,
                                              "engine/accuracy.py": first + header + "# c",
                                              "engine/helper.py": "# d\n"})
    assert step_cache.choice_sources(one) == step_cache.choice_sources(two)
    assert step_cache._fingerprint(one) != step_cache._fingerprint(two)


def test_a_repeated_choice_is_read_back_whole_without_a_probe(cache, monkeypatch):
    first = choose_step(CHIRP, tolerance=0.05, probe_duration=PROBE, cache=True)
    assert not first.cached and len(list(cache.glob("*.json"))) == 1

    def no_run(*args, **kwargs):
        raise AssertionError("a cached choice ran a probe")

    import qzs.engine.single as simulate_module
    monkeypatch.setattr(simulate_module, "integrate", no_run)
    again = choose_step(CHIRP, tolerance=0.05, probe_duration=PROBE, cache=True)
    assert again.cached
    for field in dataclasses.fields(first):
        if field.name not in ("cached", "probe"):
            assert getattr(again, field.name) == getattr(first, field.name), field.name
    assert again.probe == first.probe
    # another tolerance is another question: it needs the probe (and so fails here)
    with pytest.raises(AssertionError, match="ran a probe"):
        choose_step(CHIRP, tolerance=0.04, probe_duration=PROBE, cache=True)
    # without cache=True the disk is neither read nor written
    with pytest.raises(AssertionError, match="ran a probe"):
        choose_step(CHIRP, tolerance=0.05, probe_duration=PROBE)


def test_a_damaged_record_or_an_unwritable_folder_costs_a_new_choice(cache, tmp_path,
                                                                      monkeypatch):
    first = choose_step(CHIRP, tolerance=0.05, probe_duration=PROBE, cache=True)
    (record,) = cache.glob("*.json")
    record.write_text('{"format": 1, "dt": "not a step"')
    again = choose_step(CHIRP, tolerance=0.05, probe_duration=PROBE, cache=True)
    assert not again.cached and again.dt == first.dt
    record.write_text('{"format": 1, "dt": -1.0}')
    assert step_cache.load(record.stem) is not None
    assert not choose_step(CHIRP, tolerance=0.05, probe_duration=PROBE, cache=True).cached
    # a file where the folder should be: nothing is written, the choice is still made
    blocked = tmp_path / "blocked"
    blocked.write_text("")
    monkeypatch.setenv(step_cache.CACHE_ENV, str(blocked))
    assert not step_cache.store("k", {"dt": 1.0})
    assert choose_step(CHIRP, tolerance=0.05, probe_duration=PROBE, cache=True).dt == first.dt
    assert not list(cache.glob("*.part")) and not list(cache.glob(".*"))


def _same(a, b):
    """Equal, NaN equal to NaN, element by element through tuples."""
    if isinstance(a, tuple) and isinstance(b, tuple):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return type(a) is type(b) and a == b


def _synthetic_choice(constant, cases=1, **options):
    """The search on runs ``C * dt**3`` (no probe integrated): a choice in a millisecond."""
    from engine.search_probe import search

    return search(run=lambda dt, members: [constant * dt ** 3 for _ in members],
                       compare=lambda coarse, fine: abs(coarse - fine), cases=cases, dt0=1e-3,
                       order=3, measure="transmissibility_db", tolerance=1e-3,
                       sample_rate=1000.0, solver="ode3", probe=CHIRP, probe_duration=PROBE,
                       band=(1.0, 5.0), stability_limit=0.005, **options)


@pytest.mark.parametrize("kind", ["met", "fallback", "batch"])
def test_every_field_of_a_choice_survives_the_cache(cache, kind):
    """Every field of the record (:class:`StepChoice`'s own list, not the cache's) read back as
    it was made, but ``cached`` (now True) and the probe (made again): a fallback stays a
    fallback, with no error estimate and its note."""
    choice = {"met": lambda: _synthetic_choice(1e6),
              "fallback": lambda: _synthetic_choice(1e30, fallback=True, finest=1e-3 / 16),
              "batch": lambda: _synthetic_choice(1e6, cases=3, fallback=True)}[kind]()
    assert choice.met == (kind != "fallback")
    assert step_cache.store_choice("key", choice)
    cases = 3 if kind == "batch" else None
    again = step_cache.load_choice("key", CHIRP, PROBE, cases=cases)
    assert again is not None and again.cached and again.probe == CHIRP
    for field in dataclasses.fields(choice):
        if field.name != "cached":
            assert _same(getattr(again, field.name), getattr(choice, field.name)), field.name
    assert _same(tuple(again.attributes().items()), tuple(choice.attributes().items()))
    assert dataclasses.replace(again, cached=False).summary() == choice.summary()


def test_a_cached_fallback_reads_back_as_a_fallback(cache, monkeypatch):
    """The fallback of choose_step (no step meets 1e-15 m) made, then read from the cache
    without a probe: ``met`` False, "fallback" in the run's attributes, error NaN, as made."""
    options = dict(tolerance_state=1e-15, probe_duration=PROBE, max_halvings=2, fallback=True,
                   cache=True)
    first = choose_step(CHIRP, **options)
    assert not first.met and not first.cached

    def no_run(*args, **kwargs):
        raise AssertionError("a cached choice ran a probe")

    import qzs.engine.single as single
    monkeypatch.setattr(single, "integrate", no_run)
    again = choose_step(CHIRP, **options)
    assert again.cached and not again.met and math.isnan(again.error)
    assert again.attributes()["step"] == "fallback" == first.attributes()["step"]
    assert again.attributes()["step_reason"] == first.attributes()["step_reason"]
    assert "no step tried meets" in again.summary()


def test_records_keep_infinite_and_missing_numbers(cache):
    assert step_cache.store("k", {"history": [[1e-3, 0.1, math.inf]], "error": math.nan})
    record = step_cache.load("k")
    assert record["history"][0][2] == math.inf and math.isnan(record["error"])


def test_without_a_step_meeting_the_tolerance_the_fallback_says_so():
    """The one fallback (fallback=True): the paper's step, or the caller's finest, met False,
    no error estimate, and a note with the smallest estimate."""
    choice = choose_step(CHIRP, tolerance_state=1e-15, probe_duration=PROBE, max_halvings=2,
                         fallback=True)
    assert not choice.met and math.isnan(choice.error)
    assert choice.dt == 1e-4
    finer = choose_step(CHIRP, tolerance_state=1e-15, probe_duration=PROBE, max_halvings=2,
                        fallback=True, finest=2.5e-4)
    assert finer.dt == 2.5e-4 and not finer.met
    assert "no step down to" in choice.notes[-1] and "not estimated" in choice.notes[-1]
    assert "no step tried meets" in choice.summary()


def test_a_repeated_batch_choice_is_read_back_whole_without_a_probe(cache, monkeypatch):
    """choose_batch_step(cache=True): every field, the per-case ones (a case no step meets
    among them) too, read back; other cases or other labels (they are in the notes) are
    another question; a record of another number of cases is not taken."""
    from qzs import ControllerParameters
    from qzs.engine import batch as batch_module
    from qzs.engine.accuracy_batch import choose_batch_step

    cases = [(IsolatorParameters(), ControllerParameters()),
             (IsolatorParameters(), ControllerParameters(pi_kp=0.0, pi_ki=0.0))]
    options = dict(tolerance=1e-3, probe_duration=PROBE, fallback=True,
                   labels=["table 1", "no PI"])
    first = choose_batch_step(cases, CHIRP, cache=True, **options)
    assert not first.cached and first.unmet == (1,) and len(list(cache.glob("*.json"))) == 1

    def no_run(*args, **kwargs):
        raise AssertionError("a cached choice ran a probe")

    monkeypatch.setattr(batch_module, "simulate_batch", no_run)
    again = choose_batch_step(cases, CHIRP, cache=True, workers=1, **options)  # same bits
    assert again.cached
    for field in dataclasses.fields(first):
        if field.name not in ("cached", "probe"):
            assert getattr(again, field.name) == getattr(first, field.name) or (
                field.name == "case_steps" and np.array_equal(
                    again.case_steps, first.case_steps, equal_nan=True)), field.name
    for other in (dict(options, labels=["a", "b"]), dict(options, tolerance=2e-3)):
        with pytest.raises(AssertionError, match="ran a probe"):
            choose_batch_step(cases, CHIRP, cache=True, **other)
    with pytest.raises(AssertionError, match="ran a probe"):
        choose_batch_step(cases[:1], CHIRP, cache=True, **dict(options, labels=["table 1"]))
    # the record read as a choice over another number of cases: refused, not misread
    (record,) = cache.glob("*.json")
    assert step_cache.load_choice(record.stem, first.probe, first.probe_duration,
                                  cases=2) is not None
    assert step_cache.load_choice(record.stem, first.probe, first.probe_duration,
                                  cases=3) is None
