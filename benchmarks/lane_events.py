"""Where the lockstep batch kernel's time goes: its event steps counted and timed.

``qzs.engine.lanes.run_lanes`` steps every lane in a vector loop (pass 1) and hands the
lanes with a transition in the step (a stick-slip event, a release, a stop) to the scalar
event step ``qzs.engine.kernels.grid_step`` (pass 2). :func:`measure_events` runs a
population through ``simulate_batch`` with an instrumented copy of ``run_lanes`` (its own
source, with counters and the CPU's cycle counter read around pass 2 added; the numbers
are the kernel's, checked bit for bit against the plain kernel) and reports how many event
steps each case takes and what share of the kernel's time they hold.

Benchmark code: it reads the engine's private names (``qzs.engine.lanes``), which the
package itself never exports.
"""
import inspect
import textwrap

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic


@intrinsic
def _cycles(typingctx):
    """The CPU's time-stamp counter (``llvm.readcyclecounter``, constant rate on x86-64)."""
    def codegen(context, builder, signature, args):
        function = cgutils.get_or_insert_function(
            builder.module, ir.FunctionType(ir.IntType(64), []), "llvm.readcyclecounter")
        return builder.call(function, [])
    return types.int64(), codegen


def _edit(source, old, new):
    if source.count(old) != 1:
        raise RuntimeError(f"run_lanes changed: {old.strip()!r} is not in its source once; "
                           "update benchmarks/lane_events.py")
    return source.replace(old, new)


def instrumented_kernel():
    """``run_lanes`` with ``counts`` (int64, n + 3) appended to its arguments: per lane the
    event steps (pass 2) it took; then the cycles spent in pass 2, in the whole step loop,
    and the steps in which any lane took one."""
    from qzs.engine import lanes

    source = textwrap.dedent(inspect.getsource(lanes.run_lanes.py_func))
    source = source[source.index("def run_lanes"):]
    source = _edit(source, "status, rows):", "status, rows, counts):")
    source = _edit(source, "    for _ in range(n_steps):\n",
                   "    began = _cycles()\n    for _ in range(n_steps):\n        entered = -1\n")
    source = _edit(source, "            for c in range(n):  # pass 2: the flagged lanes\n",
                   "            entered = _cycles()\n            counts[n + 2] += 1\n"
                   "            for c in range(n):  # pass 2: the flagged lanes\n")
    source = _edit(source, "                P = _params(PP, c)\n                s1, mode,",
                   "                counts[c] += 1\n                P = _params(PP, c)\n"
                   "                s1, mode,")
    source = _edit(source, "        step += 1\n",
                   "        if entered >= 0:\n            counts[n] += _cycles() - entered\n"
                   "        step += 1\n")
    source = _edit(source, "\n    for c in range(n):\n        if status[c] != K.STATUS_OK:",
                   "\n    counts[n + 1] += _cycles() - began\n    for c in range(n):\n"
                   "        if status[c] != K.STATUS_OK:")
    namespace = dict(vars(lanes), _cycles=_cycles)
    exec(compile(source, "<instrumented run_lanes>", "exec"), namespace)
    options = {k: v for k, v in lanes._JIT.items() if k != "cache"}
    return njit(**options, nogil=True)(namespace["run_lanes"])


def measure_events(cases, excitation, *, dt, sample_rate, channels, repeats=2):
    """Event steps of a population in one lockstep batch on one core.

    Returns a dict: ``events`` (per case, the event steps), ``lane_steps``, ``elapsed``
    (the instrumented kernel's best [s]), ``plain`` (the plain kernel's best [s], the same
    call), ``share`` (pass 2's share of the step loop's cycles), ``event_ns`` (ns per event
    step), ``ordinary_ns`` (ns per lane and ordinary step), ``steps_with_events`` (share of
    the steps in which some lane took an event step), ``identical`` (the channels are the
    plain kernel's, bit for bit).
    """
    from qzs.engine import lanes
    from qzs.engine.batch import simulate_batch

    kernel = instrumented_kernel()
    plain_kernel = lanes.run_lanes
    calls = []

    def counted(solver, step0, n_steps, decimation, states, flags, params, ex, table, columns,
                out, out_flags, lane0, row0, status, rows):
        counts = np.zeros(states.shape[0] + 3, dtype=np.int64)
        code = kernel(solver, step0, n_steps, decimation, states, flags, params, ex, table,
                      columns, out, out_flags, lane0, row0, status, rows, counts)
        calls.append((lane0, counts))
        return code

    options = dict(dt=dt, sample_rate=sample_rate, channels=channels, workers=1)
    best = {"elapsed": np.inf, "plain": np.inf}
    lanes.run_lanes = counted
    try:
        for _ in range(repeats):
            calls.clear()
            batch = simulate_batch(cases, excitation, **options)
            best["elapsed"] = min(best["elapsed"], batch.elapsed)
    finally:
        lanes.run_lanes = plain_kernel
    plain = None
    for _ in range(repeats):
        plain = simulate_batch(cases, excitation, **options)
        best["plain"] = min(best["plain"], plain.elapsed)
    identical = all(np.array_equal(batch.channels[name], plain.channels[name], equal_nan=True)
                    for name in channels)
    events = np.zeros(len(cases), dtype=np.int64)
    pass2 = total = with_events = 0
    for lane0, counts in calls:
        n = counts.size - 3
        events[lane0:lane0 + n] += counts[:n]
        pass2, total, with_events = (pass2 + counts[n], total + counts[n + 1],
                                     with_events + counts[n + 2])
    lane_steps = float(batch.stats["steps"].sum())
    steps = float(batch.stats["steps"].max())
    share = pass2 / total
    return dict(events=events, lane_steps=lane_steps, elapsed=best["elapsed"],
                plain=best["plain"], share=share,
                event_ns=share * best["elapsed"] / events.sum() * 1e9,
                ordinary_ns=(1 - share) * best["elapsed"] / (lane_steps - events.sum()) * 1e9,
                steps_with_events=with_events / steps, identical=identical)
