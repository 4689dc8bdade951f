"""The compile notice: said at once when a qzs kernel compiles, seconds while it does, else nothing."""
import io
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from numba.core import event
from numba.core.registry import CPUDispatcher

from qzs.engine import compiling
from qzs.engine.compiling import (COMPILE_SECONDS, ENTRY_KERNELS, compile_notice, cold_kernels,
                                  estimate)

SOURCE = Path(__file__).resolve().parents[2] / "src"


class _Kernel:
    """Stands for a numba dispatcher in a compile event: only its function's module counts."""

    def __init__(self, module):
        def kernel():
            pass

        kernel.__module__ = module
        self.py_func = kernel


def _compile(module, seconds, nested=()):
    """Send numba's compile events as a compile of ``seconds`` would (``nested`` inside it)."""
    data = {"dispatcher": _Kernel(module)}
    event.start_event("numba:compile", data=data)
    for inner in nested:
        _compile(inner, 0.0)
    time.sleep(seconds)
    event.end_event("numba:compile", data=data)


@pytest.fixture
def fast_ticks(monkeypatch):
    monkeypatch.setattr(compiling, "TICK", 0.1)


def test_every_entry_kernel_is_a_cached_numba_kernel_with_an_estimate():
    for family, names in ENTRY_KERNELS.items():
        assert names, family
        for name in names:
            kernel = compiling._dispatcher(name)
            assert isinstance(kernel, CPUDispatcher), name
            assert kernel.targetoptions.get("cache") or kernel._cache is not None, name
            assert 0.0 < COMPILE_SECONDS[name] < 60.0, name
    assert set(COMPILE_SECONDS) == {n for names in ENTRY_KERNELS.values() for n in names}


def test_the_estimate_is_the_sum_rounded_as_said():
    assert estimate([]) == 5  # a kernel outside the table: still some seconds
    assert estimate(["qzs.engine.lanes.run_single"]) == round(COMPILE_SECONDS[
        "qzs.engine.lanes.run_single"])
    total = sum(COMPILE_SECONDS[n] for n in ENTRY_KERNELS["single"])
    assert estimate(ENTRY_KERNELS["single"]) % 5 == 0
    assert abs(estimate(ENTRY_KERNELS["single"]) - total) <= 2.5


def test_on_an_empty_cache_every_entry_kernel_is_cold_and_none_compiles(tmp_path):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path), PYTHONPATH=str(SOURCE))
    probe = ("from qzs.engine.compiling import cold_kernels, ENTRY_KERNELS\n"
             "from qzs.engine import lanes\n"
             "print(cold_kernels(['single', 'hexapod']) == [*ENTRY_KERNELS['single'], "
             "*ENTRY_KERNELS['hexapod']], cold_kernels([]), len(lanes.run_single.overloads))")
    out = subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True,
                         text=True, check=True, timeout=120)
    assert out.stdout.split() == ["True", "[]", "0"]


def test_a_kernel_loaded_in_this_process_is_not_cold():
    from qzs.engine import kernels as K

    K.params_tuple(np.zeros(K.N_PARAMS))  # compiles (or loads) it here
    assert compiling._dispatcher("qzs.engine.kernels.params_tuple").overloads
    ENTRY_KERNELS_WITH = {"probe": ("qzs.engine.kernels.params_tuple",)}
    original = dict(ENTRY_KERNELS)
    try:
        ENTRY_KERNELS.update(ENTRY_KERNELS_WITH)
        assert cold_kernels(["probe"]) == []
    finally:
        ENTRY_KERNELS.clear()
        ENTRY_KERNELS.update(original)


def test_a_qzs_compile_is_announced_at_once_and_counted_until_it_ends(fast_ticks):
    stream = io.StringIO()
    with compile_notice(["single"], stream=stream):
        start = time.perf_counter()
        seen = []
        thread = threading.Thread(target=_compile, args=("qzs.engine.fake", 0.55,
                                                          ["numba.cpython.fake"]))
        thread.start()
        while thread.is_alive():
            seen.append((time.perf_counter() - start, stream.getvalue()))
            time.sleep(0.01)
        thread.join()
    text = stream.getvalue()
    assert text.startswith("qzs: compiling the kernels once (about ")
    assert "later runs start in about 1 s)" in text
    first = next(t for t, shown in seen if shown)
    assert first < 0.1  # at once, not when the compile ends
    ticks = text.split(":", 2)[-1].split()
    assert len(ticks) >= 4 and ticks[-1] == "s"  # a sign of life every TICK, then the unit
    assert text.endswith(" s\n") and text.count("\n") == 1


def test_a_compile_outside_qzs_or_no_compile_says_nothing(fast_ticks):
    stream = io.StringIO()
    with compile_notice(["single"], stream=stream):
        _compile("numba.np.fake", 0.3)
        time.sleep(0.3)
    assert stream.getvalue() == ""


def test_without_ticking_only_the_notice_line(fast_ticks):
    stream = io.StringIO()
    with compile_notice(["single"], stream=stream, ticking=False):
        _compile("qzs.engine.fake", 0.4)
        _compile("qzs.engine.fake", 0.3)  # a second compile: the notice is said once
    assert stream.getvalue().count("\n") == 1
    assert stream.getvalue().startswith("qzs: compiling the kernels once (about ")
    assert stream.getvalue().endswith("s)\n")


def test_under_a_progress_bar_the_seconds_go_into_its_postfix(fast_ticks):
    from tqdm.std import tqdm

    stream = io.StringIO()
    with compile_notice(["single"], stream=stream):
        bar = tqdm(total=10, file=stream, desc="simulating", mininterval=0)
        try:
            _compile("qzs.engine.fake", 0.5)
            assert bar.postfix in (None, "")  # the bar is the caller's again
        finally:
            bar.close()
    text = stream.getvalue()
    assert "qzs: compiling the kernels once (about " in text
    assert "compiling the kernels once, " in text.split("\n", 1)[1]  # in the bar's line
    assert text.count("qzs: compiling") == 1  # the notice, no own line fighting with the bar


def _timed_stderr(argv, env, timeout):
    """Run ``argv``; return ``[(seconds since start, bytes)]`` of its stderr, and stdout."""
    start = time.perf_counter()
    process = subprocess.Popen(argv, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    chunks = []

    def read():
        while True:
            chunk = os.read(process.stderr.fileno(), 4096)
            if not chunk:
                return
            chunks.append((time.perf_counter() - start, chunk))

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    stdout = process.stdout.read()  # stderr is the reader's alone (communicate would read it)
    process.wait(timeout=timeout)
    reader.join(timeout=5)
    assert process.returncode == 0, b"".join(c for _, c in chunks).decode()
    return chunks, stdout, time.perf_counter() - start


#: The kernels only the general path calls (controller blocks, a spring law other than the
#: tanh): a default run compiles none of them (qzs.engine.kernels.kernel_model).
GENERAL_PATH = ("block_forces", "block_rates", "sample_blocks", "linear_sample",
                "sample_linear", "general_spring", "general_spring_energy", "_saturated")
#: The six legs' kernels only a platform with controller blocks or a spring law other than
#: the tanh calls (besides the single axis's general kernels): a run without compiles none
#: of them (``models`` None).
HEXAPOD_BLOCKS = ("_leg_blocks", "_leg_block_rates", "_sample_blocks", "_linear_due",
                  "_sample_linear", "_leg_springs")


def _compiled(cache):
    """The kernels a run compiled into the numba cache ``cache``, as ``module.function``
    (the name of each function's cache index: ``module.function-line.pyXY.nbi``)."""
    return {path.name.split("-")[0] for path in cache.rglob("*.nbi")}


@pytest.mark.slow
def test_a_first_run_says_it_compiles_at_once_and_is_never_silent_long(tmp_path):
    """A cold ``qzs simulate``: the notice within seconds, then no silence over a few seconds.

    The bounds are generous for a busy 2-core machine (the ticker writes every second) and
    still fail when the compile is silent: it takes 10-20 s on a quiet machine.
    """
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"), PYTHONPATH=str(SOURCE))
    env.pop("NUMBA_DISABLE_JIT", None)
    # the same moment's start-up without any kernel: how long a warm run stays silent anyway
    started = time.perf_counter()
    subprocess.run([sys.executable, "-c", "import qzs.cli, qzs.engine.simulate"], env=env,
                   check=True, timeout=120)
    startup = time.perf_counter() - started
    argv = [sys.executable, "-m", "qzs", "simulate", "--duration", "0.2", "--plot", "none"]
    chunks, stdout, _ = _timed_stderr(argv, env, timeout=900)
    assert b"qzs simulation" in stdout
    # the default model compiled none of the general path's code (its functions would have
    # cache files): no controller blocks, no spring law but the tanh of the parameters
    compiled = _compiled(tmp_path / "cache")
    assert "lanes.run_single" in compiled, compiled
    general = {f"kernels.{name}" for name in GENERAL_PATH} | {"lanes.run_single_blocks"}
    assert not compiled & general, sorted(compiled & general)
    text = b"".join(c for _, c in chunks).decode()
    assert "qzs: compiling the kernels once (about " in text
    first = chunks[0][0]
    assert first <= startup + 4.0, (first, startup)
    notice_at = next(t for t, c in chunks if b"compiling the kernels once" in c)
    # nothing visible before it but the start notice (a busy machine); a bar cleared to
    # write the notice above it sends a bare carriage return
    before = [c for t, c in chunks if t < notice_at and c.strip()]
    assert all(b"qzs simulate: starting" in c for c in before), before
    # until the last sign of compiling, no gap longer than the bound: the ticker writes every
    # second; a busy machine starves it now and then, as much as it slows the start-up
    last = max(t for t, c in chunks if b"compiling" in c or c.strip(b" s\n").isdigit())
    told = [(t, c) for t, c in chunks if t <= last]
    assert len(told) >= 5  # it compiled for seconds, and said so more than once
    gap, where = max((b[0] - a[0], (a, b)) for a, b in zip(told, told[1:]))
    assert gap <= max(4.0, 2.0 * startup), (gap, startup, where)

    # the same cache again: everything is loaded, nothing is said about compiling
    chunks, stdout, _ = _timed_stderr(argv, env, timeout=300)
    assert b"qzs simulation" in stdout
    assert b"compiling" not in b"".join(c for _, c in chunks)


@pytest.mark.slow
def test_a_first_six_leg_run_without_blocks_compiles_none_of_the_blocks_code(tmp_path):
    """A cold six-leg run, PI + damping on every leg, the tanh: none of the blocks' or the
    spring laws' functions, the six legs' nor the single axis's they call, has a cache index;
    the six legs' kernels have.

    Failed when the switch was a value in ``plat``: numba compiled the blocks' code into every
    run (35.8 s against 24.2 s of compile CPU, benchmarks/compile_times.py --hexapod).
    """
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path), PYTHONPATH=str(SOURCE))
    env.pop("NUMBA_DISABLE_JIT", None)
    run = ("from qzs import ControllerParameters, Sine\n"
           "from qzs.engine.hexapod import simulate_hexapod\n"
           "from qzs.model.hexapod import PlatformParameters, cubic_geometry\n"
           "result = simulate_hexapod(cubic_geometry(cube_edge=0.3, cube_center_height=0.3),\n"
           "    PlatformParameters(mass=22.17, inertia=[[0.3, 0, 0], [0, 0.3, 0], [0, 0, 0.5]]),\n"
           "    controller=ControllerParameters(pi_kp=2000.0, pi_ki=800.0),\n"
           "    excitation={'z': Sine(amplitude=0.002, frequency=5.0)}, duration=0.01)\n"
           "print(result.has_blocks, result.run['steps'])")
    out = subprocess.run([sys.executable, "-c", run], env=env, capture_output=True, text=True,
                         check=True, timeout=900)
    assert out.stdout.split() == ["False", "100"]
    compiled = _compiled(tmp_path)
    assert {"dynamics._evaluate", "stepping._start", "stepping._run"} <= compiled, compiled
    blocks = ({f"kernels.{name}" for name in GENERAL_PATH}
              | {f"dynamics.{name}" for name in HEXAPOD_BLOCKS})
    assert not compiled & blocks, sorted(compiled & blocks)


@pytest.mark.parametrize("load, cores, factor", [(0.0, 2, 1.0), (1.0, 2, 1.0), (6.0, 2, 3.5),
                                                 (3.0, 1, 4.0), (0.5, 8, 1.0)])
def test_the_slowdown_is_one_core_shared_with_the_runnable_processes(load, cores, factor):
    assert compiling.slowdown(load, cores) == pytest.approx(factor)


def test_the_estimate_scales_with_the_machine_s_slowdown():
    kernels = ENTRY_KERNELS["single"] + ENTRY_KERNELS["batch"]
    total = sum(COMPILE_SECONDS[n] for n in kernels)
    for factor in (1.0, 2.0, 3.5):
        assert abs(estimate(kernels, factor=factor) - factor * total) <= 2.5


def test_the_rest_is_estimated_from_compile_time_alone_not_the_run_between(monkeypatch):
    """Kernels A and B (1 s each in the table) compile in 0.2 s each with 0.6 s of running
    between them: the rest (C, 10 s in the table) is about 10 * 0.4 / 2 = 2 s, not the 5 s
    the whole elapsed time would say."""
    done = set()

    class Dispatcher:
        def __init__(self, name):
            self.overloads = {1: 1} if name in done else {}

    names = ["fake.A", "fake.B", "fake.C"]
    for name, seconds in zip(names, (1.0, 1.0, 10.0)):
        monkeypatch.setitem(COMPILE_SECONDS, name, seconds)
    monkeypatch.setattr(compiling, "cold_kernels", lambda families: list(names))
    monkeypatch.setattr(compiling, "_dispatcher", Dispatcher)
    monkeypatch.setattr(compiling, "slowdown", lambda: 2.0)
    notice = compiling._Notice(["single"], io.StringIO(), ticking=False)
    assert notice.seconds is None
    for name, gap in (("fake.A", 0.6), ("fake.B", 0.0)):
        notice.on_start(SimpleEvent({"dispatcher": _Kernel("qzs.fake")}))
        time.sleep(0.2)
        done.add(name)
        notice.on_end(SimpleEvent({}))
        time.sleep(gap)
    assert notice.seconds == estimate(names, factor=2.0)  # the machine's state at the notice
    elapsed = time.perf_counter() - notice.first
    assert 0.4 <= notice.compiled < 0.6
    assert elapsed + 10.0 * 0.4 / 2 - 0.5 <= notice.about <= elapsed + 10.0 * 0.6 / 2 + 0.5


class SimpleEvent:
    def __init__(self, data):
        self.data = data


def test_on_an_empty_cache_the_blocks_kernel_is_cold_and_counted_once(tmp_path):
    """A first run of a controller with blocks compiles ``run_single_blocks`` (not
    ``run_single``): its family's estimate is its kernels', each counted once."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path), PYTHONPATH=str(SOURCE))
    probe = ("from qzs.engine.compiling import cold_kernels\n"
             "print(*cold_kernels(['single_blocks', 'single']), sep='\\n')")
    out = subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True,
                         text=True, check=True, timeout=120)
    assert out.stdout.split() == [*ENTRY_KERNELS["single_blocks"], "qzs.engine.lanes.run_single"]
    assert "qzs.engine.lanes.run_single" not in ENTRY_KERNELS["single_blocks"]
    assert estimate(ENTRY_KERNELS["single_blocks"]) >= estimate(ENTRY_KERNELS["single"])
