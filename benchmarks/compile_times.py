"""What a first run compiles, kernel by kernel: process CPU of numba's compile events.

    python benchmarks/compile_times.py [--duration S] [--hexapod]

Runs ``qzs.simulate(duration=S)`` (default 5 s of the paper's chirp, PI + damping), or with
``--hexapod`` ``simulate_setup`` of the shipped six-leg platform (``paper_legs_cubic``: PI +
damping per leg, no blocks; its ``dt``, S default 0.1 s), in this process with an empty,
private ``NUMBA_CACHE_DIR`` and reports the total CPU time of the run and, per compiled
function, the CPU time of its compile events (numba's ``numba:compile`` events; inclusive of
the functions it compiles on the way, so the rows overlap). Issue 40's measure of the first
run's compile (22.1 s before the controller's blocks existed, 116.5 s with their code inlined
into every caller of the right-hand side, 46.8 s with it called). CPU time, not wall time, so
that a shared machine's load moves it less; ``benchmarks/run_all.py`` rows 6 and 6b are the
wall-time targets against the C reference. Exits 0: a benchmark reports.
"""
import argparse
import os
import tempfile
import time


def _simulate(hexapod, duration):
    """The first run: the single axis's ``qzs.simulate`` or the shipped six-leg platform's."""
    if hexapod:
        from qzs.workflows.hexapod.setups import SHIPPED_DEFAULT, load_hexapod, simulate_setup

        setup = load_hexapod(SHIPPED_DEFAULT)
        simulate_setup(setup, duration=0.1 if duration is None else duration,
                       dt=setup.simulation.get("dt"))
    else:
        import qzs

        qzs.simulate(duration=5.0 if duration is None else duration)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=None,
                        help="simulated time [s] (default 5, with --hexapod 0.1)")
    parser.add_argument("--hexapod", action="store_true",
                        help="the six-leg platform's first run instead of the single axis's")
    parser.add_argument("--top", type=int, default=15, help="rows to show")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        os.environ["NUMBA_CACHE_DIR"] = folder  # before numba is imported
        os.environ["QZS_CACHE_DIR"] = os.path.join(folder, "steps")
        from numba.core import event

        times, started = {}, {}

        class Compiles(event.Listener):
            def on_start(self, ev):
                started[id(ev.data["dispatcher"]), str(ev.data.get("args"))] = time.process_time()

            def on_end(self, ev):
                key = (id(ev.data["dispatcher"]), str(ev.data.get("args")))
                function = getattr(ev.data["dispatcher"], "py_func", ev.data["dispatcher"])
                name = f"{function.__module__}.{function.__qualname__}"
                times[name] = times.get(name, 0.0) + time.process_time() - started.pop(
                    key, time.process_time())

        event.register("numba:compile", Compiles())
        import qzs

        start = time.process_time()
        _simulate(args.hexapod, args.duration)
        total = time.process_time() - start
    run = "qzs hexapod (paper_legs_cubic)" if args.hexapod else "qzs.simulate"
    print(f"# compile_times  qzs {qzs.__version__}  {run}  load {os.getloadavg()[0]:.2f}")
    print(f"first run, empty cache: {total:.1f} s of CPU (the run itself a fraction of it)")
    print("CPU [s]  function compiled (inclusive)")
    for name, seconds in sorted(times.items(), key=lambda item: -item[1])[:args.top]:
        print(f"{seconds:7.1f}  {name}")


if __name__ == "__main__":
    main()
