#!/usr/bin/env python
"""The lane kernel against JAX on the same model (issue 11, target 6).

    .venv/bin/python benchmarks/bench_jax.py            # 1024 cases, 1e5 steps each, best of 3
    .venv/bin/python benchmarks/bench_jax.py --quick    # 2e4 steps each, best of 2
    .venv/bin/python benchmarks/bench_jax.py --repeats 5 --idle-wait 60 --extra

The peer a Python user would pick for a batch of ODEs is JAX: ``vmap`` over the cases,
``lax.scan`` over the steps, XLA compiling the lot. JAX has no events, so it cannot do
qzs' exact stick-slip; it integrates the regularised model that qzs offers as an option
(``IsolatorParameters(friction_regularisation=v_reg)``, docs/model.md §3), and both sides
then do the same work:

- the same equations: MagSpring, Stribeck/Coulomb/viscous friction with ``tanh(v/v_reg)``,
  compliant stops that only push, PI with anti-windup by conditional integration, active
  damping on the 1 Hz high-passed velocity, motor saturation, gravity, the 4-entry energy
  ledger (8 states in all), the linear chirp base motion evaluated at every stage;
- the same case: the packed parameters and the initial state (with the PI preload) of
  every case are taken from ``qzs.engine.prepare.prepare_run``, the constants of the chirp
  from its ``pack()``;
- the same scheme: ode3 (Bogacki-Shampine without its error stage) at dt = 1e-4 s;
- float64 (``jax_enable_x64``), on the CPU, statistics only (JAX carries the final state and
  each case's running maximum of |z - stop centre|; qzs its batch statistics from 100 Hz rows).

The JAX side is the usual idiom: the right-hand side written for one case, ``jax.vmap`` over
the cases with the state as a tuple of per-state arrays (structure of arrays), ``lax.scan``
over the steps, ``jax.jit``. Formulations tried and dropped because they ran slower: the
state as one (cases, 8) array (3-4x slower: XLA transposes), one (8, cases) array built with
``jnp.stack`` (3-4x slower: a concatenate fusion recomputes the right-hand side per row),
``scan(unroll=8)`` (3x slower).

Cores: every measurement runs in a fresh subprocess pinned with ``taskset`` (``-c 0`` for one
core, ``-c 0,1`` for two). JAX on two cores: two host devices
(``XLA_FLAGS=--xla_force_host_platform_device_count=2``) and ``jax.pmap`` over halves of the
cases; qzs: ``simulate_batch(..., workers=2)``, threads over halves of the cases. Compile time:
``jit(...).lower(...).compile()`` for JAX (every run compiles afresh); qzs' kernels come from
numba's cache (a cold compile is ``--cold``, an information row). Throughput: case-steps per
second of the integration only (JAX: the compiled call; qzs: ``BatchResult.elapsed``), best of
N, each run started after waiting up to ``--idle-wait`` s for the machine to go quiet.

Before timing, a check integrates a few cases (a faster chirp, short stops so that the
compliant stops are hit, a passive case) 0.5 s with both and prints the largest difference of
each final state relative to its largest value: rounding-level (qzs has its own ``exp`` and
``tanh`` and rotates the chirp's sine and cosine, JAX calls XLA's), which shows that both
integrate the same equations.

Targets: the lane kernel >= 1.5x JAX's throughput on one core and on two cores at 1024 cases,
with the regularised model (the same work) and with the exact stick-slip model, and >= 1.8x
from 1 to 2 cores. The script always exits 0; without jax it says "not measured".
"""
import argparse
import importlib.util
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import traceback
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from bench_simulate import _load, machine_info, report_only, wait_for_idle  # noqa: E402

DT = 1e-4
N_CASES = 1024
V_REG = 1e-3                # [m/s], the regularisation velocity of the comparison
CHIRP = dict(amplitude=0.010, f0=0.0, f1=20.0)   # over the whole run, as in bench_batch.py
TARGET_RATIO = 1.5          # qzs lanes / JAX, one core and two cores
TARGET_SCALING = 1.8        # qzs lanes, 1 -> 2 cores
CHECK_SECONDS = 0.5

log = lambda msg="": print(msg, flush=True)  # noqa: E731


# --------------------------------------------------------------------------- the cases

def cases(n, v_reg, seed=0):
    """Stiction 5-15 N, PI gains 5-50 N/m (Ki = 0.4 Kp), active damping 0-50 N*s/m."""
    import qzs

    rng = np.random.default_rng(seed)
    fs, kp, kd = rng.uniform(5, 15, n), rng.uniform(5, 50, n), rng.uniform(0, 50, n)
    return [(qzs.IsolatorParameters(stiction_force=float(a), friction_regularisation=v_reg),
             qzs.ControllerParameters(pi_kp=float(b), pi_ki=0.4 * float(b),
                                      damping_gain=float(c)))
            for a, b, c in zip(fs, kp, kd)]


def check_cases(v_reg):
    """A few cases for the agreement check: the stops within reach, a passive one."""
    import qzs

    return [
        (qzs.IsolatorParameters(friction_regularisation=v_reg), qzs.ControllerParameters()),
        (qzs.IsolatorParameters(friction_regularisation=v_reg, stiction_force=5.0),
         qzs.ControllerParameters(damping_gain=30.0)),
        (qzs.IsolatorParameters(friction_regularisation=v_reg, stroke_half=0.004),
         qzs.ControllerParameters(pi_kp=20.0, pi_ki=8.0, damping_gain=10.0)),
        (qzs.IsolatorParameters(friction_regularisation=v_reg, stroke_half=0.003,
                                motor_force_max=2.0),
         qzs.ControllerParameters(pi_kp=500.0, pi_ki=200.0)),
        (qzs.IsolatorParameters(friction_regularisation=v_reg, stiction_force=15.0),
         qzs.ControllerParameters(pi_kp=0.0, pi_ki=0.0)),
    ]


def packed(pairs, excitation):
    """Every case packed by qzs itself: parameters (N_PARAMS, n), ODE states (8, n), scalars."""
    from qzs.engine import kernels as K
    from qzs.engine.prepare import prepare_run

    runs = [prepare_run(excitation, i, c, dt=DT, sample_rate=100.0) for i, c in pairs]
    params = np.stack([r.params for r in runs], axis=1)
    states = np.stack([r.state[:K.N_ODE] for r in runs], axis=1)
    return params, states, runs[0].packed[0]


# --------------------------------------------------------------------------- the JAX model

def jax_model(ex, steps, ledger=True):
    """``run(S, P) -> (S, stroke)``: ``steps`` ode3 steps of the regularised model for a batch.

    ``S`` is a tuple of 8 state arrays (z, v, high-pass state, PI integral, then the ledger:
    base work, friction loss, motor work, stop loss), ``P`` the packed parameters, one row
    per ``qzs.engine.kernels.P_*`` and one column per case. ``ledger=False`` integrates the
    4 motion states only (an information row: what the ledger costs XLA).
    """
    import jax
    import jax.numpy as jnp

    from qzs.engine import kernels as K
    from qzs.model import excitation as X

    if int(ex[X.E_KIND]) != X.KIND_CHIRP_LINEAR or ex[X.E_FADE] != 0.0:
        raise ValueError("the JAX model has the linear chirp without fade-in only")
    amplitude, f0 = float(ex[X.E_AMPLITUDE]), float(ex[X.E_F0])
    rate = (float(ex[X.E_F1]) - f0) / float(ex[X.E_DURATION])
    two_pi, h = 2.0 * np.pi, DT
    n_states = 8 if ledger else 4

    def base(t):  # as qzs.engine.base_motion: y, yd, ydd of the linear chirp at t
        phase = two_pi * (f0 * t + 0.5 * rate * t * t)
        omega, omega_dot = two_pi * (f0 + rate * t), two_pi * rate
        s, c = jnp.sin(phase), jnp.cos(phase)
        return amplitude * s, amplitude * c * omega, amplitude * (c * omega_dot - s * omega * omega)

    def rhs(b, s, p):  # one case (vmapped): docs/model.md §2-§5 and §8, slipping
        y, yd, ydd = b
        z, v, w, integral = s[0], s[1], s[2], s[3]
        m = p[K.P_MASS]
        xd = yd + v
        f_spring = -p[K.P_SPRING_A] * jnp.tanh(p[K.P_SPRING_B] * z)
        z_low, z_high, k_stop, c_stop = p[K.P_Z_LOW], p[K.P_Z_HIGH], p[K.P_STOP_K], p[K.P_STOP_C]
        below, above = z < z_low, z > z_high
        f_elastic = jnp.where(below, k_stop * (z_low - z),
                              jnp.where(above, -k_stop * (z - z_high), 0.0))
        f_stop = jnp.where(below, jnp.maximum(f_elastic - c_stop * v, 0.0),
                           jnp.where(above, jnp.minimum(f_elastic - c_stop * v, 0.0), 0.0))
        v_measured = jnp.where(p[K.P_HP_OMEGA] > 0.0, xd - w, xd)
        error = p[K.P_ZREF] - z
        ki, f_max = p[K.P_KI], p[K.P_FMAX]
        command = (p[K.P_KP] * error + ki * integral) - p[K.P_KD] * v_measured
        frozen = ((command > f_max) & (error * ki > 0.0)) | ((command < -f_max) & (error * ki < 0.0))
        integral_rate = jnp.where(frozen, 0.0, error)
        f_motor = jnp.clip(command, -f_max, f_max)
        f_applied = f_spring + f_stop + f_motor - m * p[K.P_GRAVITY]
        level = p[K.P_FC] + (p[K.P_FS] - p[K.P_FC]) * jnp.exp(-p[K.P_CBC] * jnp.abs(v))
        f_friction = -level * jnp.tanh(v / p[K.P_VREG]) - p[K.P_CV] * v
        xdd = (f_applied + f_friction) * (1.0 / m)
        rates = (v, xdd - ydd, p[K.P_HP_OMEGA] * (xd - w), integral_rate,
                 (f_spring + f_friction + f_stop + f_motor) * yd, -f_friction * v,
                 f_motor * v, -(f_stop - f_elastic) * v)
        return rates[:n_states]

    def run(S, P):
        f = jax.vmap(rhs, in_axes=(None, 0, 1))
        center = 0.5 * (P[K.P_Z_LOW] + P[K.P_Z_HIGH])

        def step(carry, i):
            S, stroke = carry
            t = i.astype(jnp.float64) * h
            k1 = f(base(t), S, P)
            k2 = f(base(t + 0.5 * h), tuple(s + (0.5 * h) * k for s, k in zip(S, k1)), P)
            k3 = f(base(t + 0.75 * h), tuple(s + (0.75 * h) * k for s, k in zip(S, k2)), P)
            S = tuple(s + (h * (2.0 / 9.0)) * a + (h * (1.0 / 3.0)) * b + (h * (4.0 / 9.0)) * c
                      for s, a, b, c in zip(S, k1, k2, k3))
            return (S, jnp.maximum(stroke, jnp.abs(S[0] - center))), None

        (S, stroke), _ = jax.lax.scan(step, (S, jnp.zeros_like(S[0])),
                                      jnp.arange(steps, dtype=jnp.int64))
        return S, stroke

    return run


def _jax_setup():
    import jax

    jax.config.update("jax_enable_x64", True)
    jax.config.update("jax_platforms", "cpu")
    return jax


def jax_worker(n, steps, repeats, idle_wait, ledger=True):
    """Compile and time the JAX model on this process's devices (1: jit, 2+: pmap)."""
    jax = _jax_setup()
    import jax.numpy as jnp

    import qzs

    devices = jax.local_device_count()
    excitation = qzs.Chirp(duration=steps * DT, **CHIRP)
    params, states, ex = packed(cases(n, V_REG), excitation)
    run = jax_model(ex, steps, ledger)
    n_states = 8 if ledger else 4
    if devices == 1:
        S = tuple(jnp.asarray(states[i]) for i in range(n_states))
        P = jnp.asarray(params)
        start = time.perf_counter()
        compiled = jax.jit(run).lower(S, P).compile()
    else:
        share = n // devices
        S = tuple(jnp.asarray(states[i].reshape(devices, share)) for i in range(n_states))
        P = jnp.asarray(params.reshape(params.shape[0], devices, share).transpose(1, 0, 2))
        start = time.perf_counter()
        compiled = jax.pmap(run).lower(S, P).compile()
    compile_seconds = time.perf_counter() - start
    jax.block_until_ready(compiled(S, P))  # first call (buffers, thread pools), not timed
    runs = []
    for _ in range(repeats):
        busy = wait_for_idle(idle_wait)
        start = time.perf_counter()
        out = jax.block_until_ready(compiled(S, P))
        seconds = time.perf_counter() - start
        runs.append(dict(rate=n * steps / seconds, seconds=seconds, busy=busy))
    finite = bool(np.all(np.isfinite(np.asarray(out[0][0]))))
    return dict(side="jax", devices=devices, compile=compile_seconds, runs=runs,
                best=max(r["rate"] for r in runs), finite=finite, ledger=ledger,
                version=jax.__version__)


def qzs_worker(n, steps, repeats, idle_wait, threads, v_reg):
    """Time the lane kernel (``simulate_batch``, statistics only) on ``threads`` threads."""
    import qzs
    from qzs.engine.batch import simulate_batch

    pairs = cases(n, v_reg)
    excitation = qzs.Chirp(duration=steps * DT, **CHIRP)
    start = time.perf_counter()
    simulate_batch(pairs[:2], qzs.Chirp(duration=0.05, **CHIRP), sample_rate=100.0,
                   channels=(), workers=min(threads, 2))  # kernels from the cache (or compiled)
    load_seconds = time.perf_counter() - start
    runs = []
    for _ in range(repeats):
        busy = wait_for_idle(idle_wait)
        start = time.perf_counter()
        result = simulate_batch(pairs, excitation, dt=DT, sample_rate=100.0, channels=(),
                                workers=threads)
        wall = time.perf_counter() - start
        runs.append(dict(rate=n * steps / result.elapsed, seconds=result.elapsed, wall=wall,
                         busy=busy, sticks=float(result.stats["stick_events"].mean()),
                         failed=int(result.status.sum())))
    return dict(side="qzs", threads=threads, v_reg=v_reg, load=load_seconds, runs=runs,
                best=max(r["rate"] for r in runs))


def check_worker():
    """Final states of JAX and of qzs' own kernel after 0.5 s on the check cases."""
    jax = _jax_setup()
    import jax.numpy as jnp

    import qzs
    from qzs.engine import kernels as K
    from qzs.engine import lanes
    from qzs.engine.prepare import prepare_run

    excitation = qzs.Chirp(amplitude=0.02, f0=2.0, f1=20.0, duration=CHECK_SECONDS)
    steps = int(round(CHECK_SECONDS / DT))
    pairs = check_cases(V_REG)
    params, states, ex = packed(pairs, excitation)
    final_jax = np.array(jax.jit(jax_model(ex, steps))(
        tuple(jnp.asarray(s) for s in states), jnp.asarray(params))[0])
    final_qzs, contacts = [], 0
    for isolator, controller in pairs:
        run = prepare_run(excitation, isolator, controller, dt=DT, sample_rate=100.0)
        state, flags = run.state.copy(), run.flags.copy()
        out = np.empty((steps // run.decimation + 1, K.N_CHANNELS))
        out_flags = np.zeros((out.shape[0], 2), dtype=np.bool_)
        status, _ = lanes.single_kernel(run.model)(
            run.solver_code, steps, run.decimation, state, flags, run.params, run.model,
            *run.packed, out, out_flags, 0)
        assert status == K.STATUS_OK and flags[K.I_N_STICKS] == 0
        contacts += int(flags[K.I_N_CONTACTS])
        final_qzs.append(state[:K.N_ODE])
    final_qzs = np.array(final_qzs).T
    scale = np.maximum(np.abs(final_qzs).max(axis=1), 1e-300)
    relative = (np.abs(final_jax - final_qzs).max(axis=1) / scale).tolist()
    return dict(side="check", relative=relative, contacts=contacts, cases=len(pairs),
                steps=steps)


# --------------------------------------------------------------------------- driver

STATE_NAMES = ("z", "v", "high-pass", "PI integral", "W_base", "D_friction", "W_motor",
               "D_stop")


def _taskset(cores):
    if shutil.which("taskset") is None or (os.cpu_count() or 1) < cores:
        return []
    return ["taskset", "-c", ",".join(str(c) for c in range(cores))]


def _child(role, cores, args, extra=(), env=None):
    """Run this script as a worker pinned to ``cores`` cores; returns its JSON answer."""
    command = (_taskset(cores) + [sys.executable, str(Path(__file__).resolve()), "--worker",
                                  role, "--cases", str(args.cases), "--steps", str(args.steps),
                                  "--repeats", str(args.repeats), "--idle-wait",
                                  str(args.idle_wait)] + list(extra))
    proc = subprocess.run(command, capture_output=True, text=True, env=env, timeout=7200)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(command)} failed (exit {proc.returncode}):\n"
                           f"{proc.stderr[-3000:]}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def _jax_env(devices):
    env = dict(os.environ)
    flags = [f for f in env.get("XLA_FLAGS", "").split()
             if not f.startswith("--xla_force_host_platform_device_count")]
    if devices > 1:
        flags.append(f"--xla_force_host_platform_device_count={devices}")
    env["XLA_FLAGS"] = " ".join(flags)
    return env


def _runs_note(result):
    return ", ".join(f"{r['rate'] / 1e6:.1f}{'*' if (r['busy'] or 0) > 0.3 else ''}"
                     for r in result["runs"])


def cold_compile_seconds():
    """First ``simulate_batch`` of 2 cases with an empty, private numba cache [s]."""
    code = ("import time, qzs; from qzs.engine.batch import simulate_batch; "
            "c=(qzs.IsolatorParameters(), qzs.ControllerParameters()); t=time.perf_counter(); "
            "simulate_batch([c, c], qzs.Chirp(duration=0.05), sample_rate=100.0, channels=(), "
            "workers=1); print(time.perf_counter()-t)")
    with tempfile.TemporaryDirectory() as tmp:
        env = dict(os.environ, NUMBA_CACHE_DIR=tmp)
        proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                              env=env, timeout=3600)
        if proc.returncode != 0:
            raise RuntimeError(proc.stderr[-2000:])
        return float(proc.stdout.strip().splitlines()[-1])


def measure(args):
    """Every measurement of target 6; returns a dict of results (``None`` without jax)."""
    if importlib.util.find_spec("jax") is None:
        return None
    results = dict(cases=args.cases, steps=args.steps, repeats=args.repeats, v_reg=V_REG)
    log(f"  {args.cases} cases x {args.steps:,} ode3 steps (dt = {DT:g} s, a "
        f"{CHIRP['amplitude'] * 1e3:g} mm {CHIRP['f0']:g}-{CHIRP['f1']:g} Hz chirp over the "
        f"run), regularised v_reg = {V_REG:g} m/s; best of {args.repeats}")
    check = _child("check", 1, args)
    results["check"] = check
    worst = max(check["relative"])
    log(f"  check, JAX vs qzs' kernel, {check['cases']} regularised cases, "
        f"{check['steps']:,} steps of a 20 mm 2-20 Hz chirp ({check['contacts']} stop "
        f"contacts in qzs): largest final-state difference / largest value:")
    log("    " + ", ".join(f"{name} {value:.1g}"
                           for name, value in zip(STATE_NAMES, check["relative"])))
    results["check_ok"] = worst < 1e-8
    log(f"    -> {'agree to rounding' if results['check_ok'] else 'DO NOT AGREE'} "
        f"(largest {worst:.2g}, threshold 1e-8)")
    two = 2 if (os.cpu_count() or 1) >= 2 else 1
    plan = [("jax1", "jax", 1, [], _jax_env(1)), ("jax2", "jax", two, [], _jax_env(two)),
            ("reg1", "qzs", 1, ["--threads", "1", "--v-reg", str(V_REG)], None),
            ("reg2", "qzs", two, ["--threads", str(two), "--v-reg", str(V_REG)], None),
            ("exact1", "qzs", 1, ["--threads", "1", "--v-reg", "0"], None),
            ("exact2", "qzs", two, ["--threads", str(two), "--v-reg", "0"], None)]
    if args.extra:
        plan.append(("jax1_no_ledger", "jax", 1, ["--no-ledger"], _jax_env(1)))
    labels = {"jax1": "JAX vmap + lax.scan, 1 core (jit)",
              "jax2": f"JAX vmap + lax.scan, {two} cores (pmap over {two} host devices)",
              "reg1": "qzs lanes, regularised, 1 thread",
              "reg2": f"qzs lanes, regularised, {two} threads",
              "exact1": "qzs lanes, exact stick-slip, 1 thread",
              "exact2": f"qzs lanes, exact stick-slip, {two} threads",
              "jax1_no_ledger": "JAX, 4 motion states only (no energy ledger), 1 core"}
    for key, role, cores, extra, env in plan:
        result = _child(role, cores, args, extra, env)
        results[key] = result
        note = (f"compile {result['compile']:.2f} s" if role == "jax"
                else f"kernels loaded in {result['load']:.2f} s, "
                     f"{result['runs'][-1]['sticks']:.2f} stick events per case")
        log(f"  {labels[key]} [taskset {cores} core(s)]: best {result['best'] / 1e6:.2f} M "
            f"case-steps/s (runs: {_runs_note(result)} M/s; {note})")
    if args.cold:
        results["cold"] = cold_compile_seconds()
        log(f"  qzs cold compile (empty private NUMBA_CACHE_DIR, first simulate_batch): "
            f"{results['cold']:.1f} s")
    results["two"] = two
    results["busy_runs"] = sum(1 for key in ("jax1", "jax2", "reg1", "reg2", "exact1", "exact2")
                               for r in results[key]["runs"] if (r["busy"] or 0) > 0.3)
    results["timed_runs"] = sum(len(results[key]["runs"])
                                for key in ("jax1", "jax2", "reg1", "reg2", "exact1", "exact2"))
    return results


def verdicts(results):
    """Rows ``(key, description, value, baseline, ratio, target, verdict)`` of target 6."""
    two = results["two"]
    jax1, jax2 = results["jax1"]["best"], results["jax2"]["best"]
    rows = []
    for model, key in (("regularised", "reg"), ("exact stick-slip", "exact")):
        one, both = results[f"{key}1"]["best"], results[f"{key}2"]["best"]
        for cores, mine, theirs in ((1, one, jax1), (two, both, jax2)):
            ratio = mine / theirs
            rows.append((f"lanes {model}, {cores} core{'s' if cores > 1 else ''} / JAX",
                         f"{mine / 1e6:.1f} M/s", f"JAX {theirs / 1e6:.1f} M/s",
                         f"{ratio:.2f}x", f">= {TARGET_RATIO:g}x",
                         "PASS" if ratio >= TARGET_RATIO else "FAIL"))
        scaling = both / one
        rows.append((f"lanes {model}, 1 -> {two} cores", f"{scaling:.2f}x",
                     f"(JAX {jax2 / jax1:.2f}x)", "-", f">= {TARGET_SCALING:g}x",
                     "PASS" if scaling >= TARGET_SCALING else "FAIL"))
    rows.append(("JAX compile (jit / pmap)", "-",
                 f"{results['jax1']['compile']:.2f} / {results['jax2']['compile']:.2f} s", "-",
                 "-", "info"))
    rows.append(("JAX vs qzs, final states after 0.5 s (regularised)", "-",
                 f"{max(results['check']['relative']):.1g} rel", "-", "< 1e-8",
                 "PASS" if results["check_ok"] else "FAIL"))
    if "jax1_no_ledger" in results:
        rows.append(("JAX without the energy ledger (4 states), 1 core", "-",
                     f"{results['jax1_no_ledger']['best'] / 1e6:.1f} M/s", "-", "-", "info"))
    if "cold" in results:
        rows.append(("qzs lane kernel cold compile (private cache)",
                     f"{results['cold']:.1f} s", "-", "-", "-", "info"))
    return rows


def print_table(rows):
    widths = (52, 12, 18, 7, 8, 6)
    for row in [("configuration", "qzs", "baseline", "ratio", "target", "result")] + rows:
        log("  ".join(str(c).ljust(w) if i in (0, 5) else str(c).rjust(w)
                      for i, (c, w) in enumerate(zip(row, widths))))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="2e4 steps per case, best of 2")
    parser.add_argument("--cases", type=int, default=N_CASES)
    parser.add_argument("--steps", type=int, default=None, help="steps per case (default 1e5)")
    parser.add_argument("--repeats", type=int, default=None, help="best-of-N (default 3)")
    parser.add_argument("--idle-wait", type=float, default=20.0, metavar="S",
                        help="wait up to S s before each timed run for the machine to go quiet")
    parser.add_argument("--extra", action="store_true",
                        help="also JAX without the energy ledger (information)")
    parser.add_argument("--cold", action="store_true",
                        help="also qzs' cold compile of the lane kernel (about 1.5 min)")
    parser.add_argument("--worker", choices=("jax", "qzs", "check"), help=argparse.SUPPRESS)
    parser.add_argument("--threads", type=int, default=1, help=argparse.SUPPRESS)
    parser.add_argument("--v-reg", type=float, default=V_REG, help=argparse.SUPPRESS)
    parser.add_argument("--no-ledger", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    args.steps = args.steps or (20_000 if args.quick else 100_000)
    args.repeats = args.repeats or (2 if args.quick else 3)
    if args.worker == "jax":
        print(json.dumps(jax_worker(args.cases, args.steps, args.repeats, args.idle_wait,
                                    ledger=not args.no_ledger)))
        return 0
    if args.worker == "qzs":
        print(json.dumps(qzs_worker(args.cases, args.steps, args.repeats, args.idle_wait,
                                    args.threads, args.v_reg)))
        return 0
    if args.worker == "check":
        print(json.dumps(check_worker()))
        return 0

    log("issue 11 target 6: the lane kernel against JAX (vmap + lax.scan) on the same model")
    for key, value in machine_info():
        log(f"  {key:13s} {value}")
    if importlib.util.find_spec("jax") is None:
        log("not measured: jax is not installed (pip install -e '.[bench]')")
        return 0
    try:
        results = measure(args)
    except Exception:  # a benchmark reports, it never fails the caller
        log(traceback.format_exc())
        return 0
    log("")
    if results["busy_runs"]:
        log(f"WARNING: {results['busy_runs']} of {results['timed_runs']} timed runs started "
            f"while other processes kept more than 0.3 CPUs busy (marked * above): noisy.")
    log(f"RESULTS ({results['cases']} cases x {results['steps']:,} steps, best of "
        f"{results['repeats']}; case-steps per second of the integration)")
    print_table(verdicts(results))
    log(f"load average at end: {_load()}")
    return 0


if __name__ == "__main__":
    report_only(main)
