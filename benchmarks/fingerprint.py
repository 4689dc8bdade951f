#!/usr/bin/env python
"""Fingerprint of qzs's numerical results, to show that a refactor changes no bit.

Run from the repository root with the project's interpreter, once before a change and
once after, and compare the two files::

    .venv/bin/python benchmarks/fingerprint.py > before.txt
    ... the change ...
    .venv/bin/python benchmarks/fingerprint.py > after.txt
    diff before.txt after.txt        # empty: bit-identical

Each line is ``name  sha256-prefix  a few values``: the SHA-256 of the raw bytes of every
array a result holds (data, flags, statistics), so that one differing bit anywhere changes
the line. What is covered: single runs over several parameter sets and all three solvers
(exact and regularised friction, compliant and plastic stops, continuous and sampled
control, a random excitation), files written by streaming, a lockstep batch, a six-axis run
(per-leg and centralised control), a steady-state response sweep (both directions, with the
harmonic balance), the harmonic balance itself (its force laws, residual and Jacobian,
one periodic response and a frequency-response curve, for regularised friction and with
active damping) and the metrics of ``qzs paper --quick``. ``--skip-paper`` leaves the
last out (it takes a minute on a warm cache).
"""
import argparse
import hashlib
import json
import os
import re
import subprocess
import sys
import tempfile

import numpy as np


def digest(*arrays):
    """SHA-256 (first 16 hex digits) of the raw bytes of ``arrays``."""
    h = hashlib.sha256()
    for a in arrays:
        a = np.ascontiguousarray(np.asarray(a))
        h.update(str(a.dtype).encode())
        h.update(str(a.shape).encode())
        h.update(a.tobytes())
    return h.hexdigest()[:16]


def line(name, *arrays, show=()):
    values = " ".join(f"{v:.17g}" for v in show)
    print(f"{name:40s} {digest(*arrays)}  {values}", flush=True)


def single_runs():
    from qzs import (Chirp, ControllerParameters, InitialState, IsolatorParameters,
                     RandomExcitation, Sine, simulate)

    chirp = Chirp(duration=20.0, f1=20.0)
    cases = {
        "default-ode3": dict(excitation=chirp),
        "default-rk4": dict(excitation=chirp, solver="rk4"),
        "default-euler": dict(excitation=chirp, solver="euler", dt=2e-5, sample_rate=1e3),
        "passive": dict(excitation=chirp, controller=ControllerParameters(pi_kp=0.0, pi_ki=0.0)),
        "plastic": dict(excitation=Sine(amplitude=0.010, frequency=3.0), duration=10.0,
                        isolator=IsolatorParameters(stop_model="plastic"),
                        controller=ControllerParameters(pi_kp=0.0, pi_ki=0.0)),
        "sampled-damping": dict(excitation=chirp, controller=ControllerParameters(
            controller_rate=1000.0, damping_gain=20.0)),
        "regularised": dict(excitation=chirp, isolator=IsolatorParameters(
            friction_regularisation=1e-3)),
        "stiction-high": dict(excitation=chirp, isolator=IsolatorParameters(
            stiction_force=15.0, coulomb_force=5.0), controller=ControllerParameters(
            pi_kp=200.0, damping_gain=100.0)),
        "random": dict(excitation=RandomExcitation(duration=10.0, amplitude=0.002, seed=3)),
        "initial-state": dict(excitation=chirp, duration=5.0,
                              initial_state=InitialState(relative_position=0.004, relative_velocity=0.01)),
    }
    for name, options in cases.items():
        options = dict(options)
        options.setdefault("dt", 1e-4)
        options.setdefault("sample_rate", 1e4 if name != "random" else 1e3)
        excitation = options.pop("excitation")
        result = simulate(excitation, **options)
        stats = [result.statistics[k] for k in sorted(result.statistics)]
        line(f"simulate/{name}", result._data, result._flags, np.array(stats, dtype=float),
             show=(float(result._data[-1, 7]), result.run["steps"], result.run["stick_events"]))


def streamed_run(folder):
    import xarray as xr

    from qzs import Chirp
    from qzs.workflows.run import simulate_to_file

    path = os.path.join(folder, "run.nc")
    simulate_to_file(path, Chirp(duration=30.0, f1=20.0), dt=1e-4, sample_rate=1e4)
    with xr.open_dataset(path) as ds:
        names = sorted(n for n in ds.data_vars if ds[n].ndim)  # not the parameters' containers
        time = ds["elapsed_time" if "elapsed_time" in ds else "time"]  # its CF file name
        line("streamed/run.nc", *[ds[n].values for n in names], time.values,
             show=(float(ds["relative_position"].values[-1]),))


def batch():
    from qzs import Chirp, ControllerParameters, IsolatorParameters, simulate_batch

    cases = [(IsolatorParameters(stiction_force=fs), ControllerParameters(pi_kp=kp,
                                                                           damping_gain=kd))
             for fs in (5.0, 10.0, 15.0) for kp, kd in ((0.0, 0.0), (50.0, 0.0), (50.0, 100.0))]
    cases.append((IsolatorParameters(friction_regularisation=1e-3), ControllerParameters()))
    channels = ("relative_position", "payload_acceleration", "motor_force", "locked")
    result = simulate_batch(cases, Chirp(duration=20.0, f1=20.0), dt=1e-4, sample_rate=1e3,
                            channels=channels, workers=2)
    line("batch/channels", result.time, *[result.channels[c] for c in channels])
    line("batch/stats", *[result.stats[k] for k in sorted(result.stats)], result.status)


def population():
    """A design population as the optimiser runs it: 256 lanes, many chunks, both steps."""
    from qzs import Chirp, ControllerParameters, IsolatorParameters, simulate_batch

    rng = np.random.default_rng(26)
    n = 256
    kp, ki = np.exp(rng.uniform(np.log(2.0), np.log(1000.0), n)), rng.uniform(0.0, 20.0, n)
    kd, fs = rng.uniform(0.0, 100.0, n), rng.uniform(5.0, 15.0, n)
    cases = [(IsolatorParameters(stiction_force=float(fs[i]),
                                 stop_model=("compliant", "plastic")[i % 7 == 3]),
              ControllerParameters(pi_kp=float(kp[i]), pi_ki=float(ki[i]),
                                   damping_gain=float(kd[i]),
                                   controller_rate=(0.0, 1000.0)[i % 11 == 5]))
             for i in range(n)]
    channels = ("base_acceleration", "payload_acceleration", "relative_position", "locked",
                "stop_contact", "friction_force", "spring_energy")
    for dt, duration in ((1e-3, 40.0), (1e-4, 6.0)):
        result = simulate_batch(cases, Chirp(duration=duration, amplitude=0.03), dt=dt,
                                sample_rate=1e3, channels=channels, workers=2)
        line(f"population/dt={dt:g}/channels", result.time,
             *[result.channels[c] for c in channels])
        line(f"population/dt={dt:g}/stats", *[result.stats[k] for k in sorted(result.stats)],
             result.status, show=(int(result.stats["stick_events"].sum()),
                                  int(result.stats["stop_contacts"].sum())))


def hexapod():
    from qzs import Chirp, ControllerParameters, Sine, simulate_hexapod
    from qzs.model.hexapod import PlatformParameters, cubic_geometry

    geometry = cubic_geometry(cube_edge=0.3, cube_center_height=0.3)
    platform = PlatformParameters(mass=22.17, inertia=np.diag([0.3, 0.3, 0.5]))
    controller = ControllerParameters(pi_kp=2000.0, pi_ki=800.0)
    runs = {
        "chirp-z": dict(excitation={"z": Chirp(duration=5.0)}, duration=5.0),
        "sine-xrx": dict(excitation={"x": Sine(amplitude=0.005, frequency=3.0),
                                     "rx": Sine(amplitude=0.01, frequency=2.0)}, duration=3.0,
                         solver="rk4"),
    }
    for name, options in runs.items():
        result = simulate_hexapod(geometry, platform, controller=controller, dt=1e-4,
                                  sample_rate=1e3, **options)
        line(f"hexapod/{name}", result._data, result._flags,
             show=(result.run["steps"], result.run["events"]))
        stats = result.statistics
        line(f"hexapod/{name}/statistics",
             *[np.asarray(stats[k], dtype=float) for k in sorted(stats)])
    from qzs.model.hexapod import CartesianController

    cartesian = CartesianController(position_gain=[2000.0] * 6, integral_gain=[800.0] * 6,
                                    damping_gain=[50.0] * 6)
    result = simulate_hexapod(geometry, platform, controller=controller, dt=1e-4,
                              sample_rate=1e3, excitation={"z": Sine(amplitude=0.005,
                                                                     frequency=4.0)},
                              duration=2.0, cartesian=cartesian)
    line("hexapod/cartesian", result._data, result._flags, show=(result.run["events"],))


def response():
    from qzs.workflows.response import steady_state_response

    result = steady_state_response([1.0, 2.0, 3.5, 6.0], 0.010, direction="both", dt=1e-3,
                                   workers=1, harmonic_balance=True)
    ds = result.to_xarray()
    skip = {"seconds"}
    names = sorted(n for n in ds.data_vars if n not in skip and ds[n].dtype.kind in "fiub")
    line("response/points", *[ds[n].values for n in names],
         show=tuple(float(v) for v in np.ravel(ds["transmissibility"].values)[:4]))
    # the same, split: the stepped-sine points, and the harmonic balance's curve beside them
    stepped = [n for n in names if not n.startswith("balance")]
    line("response/stepped-sine", *[ds[n].values for n in stepped])
    line("response/balance", *[ds[n].values for n in names if n.startswith("balance")])


def _balance_residual():
    """The harmonic balance's private residual, wherever the package keeps it."""
    import importlib

    for name in ("qzs.analysis.harmonic_balance.residual", "qzs.analysis.harmonic_balance"):
        try:
            module = importlib.import_module(name)
        except ImportError:
            continue
        if hasattr(module, "_residual"):
            return module._residual, module
    raise ImportError("no harmonic-balance residual found")


def balance():
    from qzs import ControllerParameters
    from qzs.analysis.harmonic_balance import (SmoothModel, floquet_exponents,
                                               frequency_response_curve, periodic_response)

    residual, module = _balance_residual()
    basis_of = getattr(module, "_basis", None)
    if basis_of is None:
        from qzs.analysis.harmonic_balance.fourier import _basis as basis_of
    models = {
        "regularised": SmoothModel.from_parameters(amplitude=0.010),
        "damping": SmoothModel.from_parameters(
            controller=ControllerParameters(damping_gain=30.0), amplitude=0.005,
            friction_velocity=2e-3),
    }
    z = np.linspace(-0.2, 0.2, 257)
    v = np.concatenate([np.linspace(-0.3, 0.3, 257), np.geomspace(1e-9, 1e-1, 40)])
    for name, model in models.items():
        line(f"balance/{name}-laws", *model.spring(z), *model.friction(v),
             show=(model.peak_friction,))
        arrays = []
        rng = np.random.default_rng(7)
        for harmonics, omega in ((5, 2.0), (12, 15.0), (40, 31.0)):
            basis = basis_of(harmonics, max(64, 8 * harmonics))
            q = rng.normal(scale=model.amplitude, size=basis.size)
            q[0] += model.position_setpoint
            arrays.extend(residual(q, omega, model, basis))
        line(f"balance/{name}-residual", *arrays)
        solution = periodic_response(4.0, model, harmonics=20)
        series = solution.time_series()
        line(f"balance/{name}-periodic", solution.coefficients,
             np.array([solution.integral_mean, solution.residual, solution.iterations]),
             floquet_exponents(solution), *[series[k] for k in sorted(series)],
             show=(solution.transmissibility,))
        curve = frequency_response_curve(model, (1.0, 8.0), harmonics=20)
        line(f"balance/{name}-curve", curve.frequency, curve.transmissibility, curve.phase,
             curve.relative_amplitude, curve.harmonic_ratios, curve.relative_range,
             curve.motor_force_peak, curve.stable, curve.largest_exponent, curve.valid,
             np.array(curve.folds, dtype=float), curve.coefficients, curve.integral_mean,
             show=(curve.frequency.size, float(curve.transmissibility.max())))


def paper(folder):
    out = os.path.join(folder, "paper")
    subprocess.run([sys.executable, "-m", "qzs", "paper", "--quick", "--out", out],
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                   env={**os.environ, "QZS_CACHE_DIR": folder})  # steps chosen anew
    with open(os.path.join(out, "metrics.json"), encoding="utf-8") as handle:
        metrics = json.load(handle)
    drop = {"wall_seconds", "generated", "elapsed", "seconds", "version", "qzs_version",
            "created", "date", "timestamp", "runs_seconds", "steps_per_second", "cached"}

    def clean(value):
        if isinstance(value, dict):
            return {k: clean(v) for k, v in value.items() if k not in drop}
        if isinstance(value, list):
            return [clean(v) for v in value]
        if isinstance(value, str):  # the step's statement quotes the seconds its choice took
            return re.sub(r"[0-9.]+ s to choose", "(time) to choose", value)
        return value

    text = json.dumps(clean(metrics), sort_keys=True)
    print(f"{'paper/metrics.json':40s} {hashlib.sha256(text.encode()).hexdigest()[:16]}",
          flush=True)


_TIMING = re.compile(r"(second|elapsed|wall|generated|version|created|date|timestamp|"
                     r"steps_per_second|path|folder|file|store|out|command|cached)", re.I)


def _clean(value):
    """A JSON summary without what differs from run to run (times, paths, versions)."""
    if isinstance(value, dict):
        return {k: _clean(v) for k, v in value.items() if not _TIMING.search(k)}
    if isinstance(value, list):
        return [_clean(v) for v in value]
    if isinstance(value, str):
        value = re.sub(r"[0-9.]+ s to choose", "(time) to choose", value)
        value = re.sub(r", [0-9.]+ s\)", ", (time))", value)
        return re.sub(r"/tmp/[^ ,;'\"]+", "(path)", value)
    return value


def cli_json(name, folder, *args, suffix=""):
    """Hash of the cleaned ``--json`` summary of ``qzs ARGS --json --quiet``."""
    out = os.path.join(folder, name.replace("/", "_") + suffix)
    done = subprocess.run([sys.executable, "-m", "qzs", *args, "--out", out, "--json",
                           "--quiet"], check=True, capture_output=True, text=True,
                          cwd=folder,  # a default figure lands there, not in the checkout
                          env={**os.environ, "QZS_CACHE_DIR": folder})  # steps chosen anew
    text = json.dumps(_clean(json.loads(done.stdout)), sort_keys=True)
    print(f"{name:40s} {hashlib.sha256(text.encode()).hexdigest()[:16]}", flush=True)
    import xarray as xr
    files = [out] if out.endswith(".nc") else sorted(
        os.path.join(out, f) for f in os.listdir(out) if f.endswith(".nc"))
    for path in files:
        with xr.open_dataset(path) as data:
            line(f"{name}/{os.path.basename(path)}",
                 *[data[k].values for k in sorted(data.data_vars)
                   if data[k].dtype.kind in "fiub" and not _TIMING.search(k)])


SWEEP = """
[sweep]
name = "fingerprint"
method = "grid"
batch_size = 4
[grid]
pi_kp = [5.0, 50.0]
stiction_force = [5.0, 15.0]
[excitation]
kind = "chirp"
amplitude = 0.010
f0 = 0.0
f1 = 20.0
[simulation]
solver = "ode3"
tolerance_db = 0.05
[analysis]
sample_rate = 1000.0
fft_length = 4096
n_averages = 3
band = [0.0, 20.0]
at_frequencies = [2.0, 12.0]
[outputs]
stats = ["peak_stroke", "steps"]
metrics = ["resonance_frequency", "transmissibility_at_2_hz"]
transmissibility = true
"""


def workflows(folder):
    """The walks above the engine: a six-axis study, an optimisation, the gain design, a
    response sweep and a sweep whose steps are chosen for a tolerance, a study with one."""
    cli_json("cli/hexapod-study", folder, "hexapod", "study", "--quick")
    cli_json("cli/optimize", folder, "optimize", "isolation_vs_effort", "--generations", "2",
             "--population", "6")
    cli_json("cli/response", folder, "response", "--range", "1,6,4", "--tolerance", "0.02",
             "--compare-chirp", suffix=".nc")
    cli_json("cli/study-stiction", folder, "study", "stiction", "--quick", "--tolerance",
             "0.05")
    sweep = os.path.join(folder, "fingerprint.toml")
    with open(sweep, "w", encoding="utf-8") as handle:
        handle.write(SWEEP)
    out = os.path.join(folder, "sweep.zarr")
    subprocess.run([sys.executable, "-m", "qzs", "sweep", sweep, "--out", out, "--quiet"],
                   check=True, capture_output=True, cwd=folder,
                   env={**os.environ, "QZS_CACHE_DIR": folder})
    import xarray as xr
    data = xr.open_zarr(out).load()
    line("cli/sweep", *[data[k].values for k in sorted(data.data_vars)
                        if data[k].dtype.kind in "fiub" and not _TIMING.search(k)])
    cli_json("cli/design", folder, "design", "--quick")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--skip-paper", action="store_true")
    parser.add_argument("--only", default="", help="comma-separated parts to run")
    args = parser.parse_args()
    parts = dict(single=single_runs, batch=batch, population=population, hexapod=hexapod,
                 response=response,
                 balance=balance)
    with tempfile.TemporaryDirectory() as folder:
        parts["streamed"] = lambda: streamed_run(folder)
        parts["workflows"] = lambda: workflows(folder)
        if not args.skip_paper:
            parts["paper"] = lambda: paper(folder)
        only = [p for p in args.only.split(",") if p]
        for name, part in parts.items():
            if not only or name in only:
                part()


if __name__ == "__main__":
    main()
