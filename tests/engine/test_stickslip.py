"""The stick-slip decisions and event location (qzs.engine.stickslip), written once.

* each decision against a hand-worked or exact reference: the holding margin and release
  direction of a stuck leg and of one resting on either plastic stop, the zero-crossing
  test, the secant fraction of a linear event function (its exact root);
* the location loop on a known smooth event function finds its root to the tolerance
  :func:`~qzs.engine.stickslip.illinois_step` promises, in at most 6 trials;
* the single axis, its lanes and the six legs call these functions and keep no copy.
"""
import ast
import math
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from numba import njit

from qzs.engine import stickslip
from qzs.engine.stickslip import (LOCATE_ITERATIONS, MODE_STICK, MODE_WALL_HIGH, MODE_WALL_LOW,
                                  crossed_zero, hold_margin, illinois_step, locate,
                                  release_direction, secant_fraction, slip_event)

ENGINE = Path(__file__).resolve().parents[2] / "src" / "qzs" / "engine"
#: The kernels that step stick-slip, and what each must take from qzs.engine.stickslip.
USERS = {
    "kernels.py": {"slip_event", "hold_margin", "release_direction", "crossed_zero",
                   "secant_fraction", "locate"},
    "lanes.py": {"slip_event", "hold_margin"},
    "hexapod/stepping.py": {"release_direction", "crossed_zero", "secant_fraction", "locate"},
    "hexapod/dynamics.py": {"slip_event", "hold_margin"},
}


@pytest.mark.parametrize("direction, v, expected", [
    (1, 0.25, 0.25), (-1, 0.25, -0.25), (-1, -0.25, 0.25), (1.0, -1e-9, -1e-9), (-1.0, 0.0, 0.0),
])
def test_slip_event_is_positive_while_slipping_along_the_direction(direction, v, expected):
    assert slip_event(direction, v) == expected
    assert slip_event.py_func(direction, v) == expected


@pytest.mark.parametrize("mode, f_hold, expected", [
    (MODE_STICK, 4.0, 6.0),          # friction holds 4 N of its 10 N
    (MODE_STICK, -4.0, 6.0),         # either way
    (MODE_STICK, -12.5, -2.5),       # 2.5 N beyond the static friction: breaks away
    (MODE_STICK, 10.0, 0.0),         # just held
    (MODE_WALL_LOW, 50.0, 60.0),     # pressed onto the lower stop: the stop takes it all
    (MODE_WALL_LOW, -4.0, 6.0),      # pulled off it: friction holds
    (MODE_WALL_LOW, -12.5, -2.5),    # pulled off beyond friction: leaves the stop
    (MODE_WALL_HIGH, -50.0, 60.0),   # pressed onto the upper stop
    (MODE_WALL_HIGH, 12.5, -2.5),    # pulled off it beyond friction
    (1.0, -12.5, -2.5),              # the six legs' float mode (MODE_LOCK = 1.0)
])
def test_hold_margin_by_hand(mode, f_hold, expected):
    assert hold_margin(mode, f_hold, 10.0) == expected
    assert hold_margin.py_func(mode, f_hold, 10.0) == expected


@pytest.mark.parametrize("mode, f_hold, expected", [
    (MODE_STICK, 12.5, -1),          # the holding force pushed up: the net force is down
    (MODE_STICK, -12.5, 1),
    (MODE_STICK, 0.0, 1),
    (MODE_WALL_LOW, -12.5, 1),       # off the lower stop: upwards, whatever the force
    (MODE_WALL_HIGH, 12.5, -1),      # off the upper stop: downwards
])
def test_release_direction_is_towards_the_net_force(mode, f_hold, expected):
    assert release_direction(mode, f_hold) == expected
    assert release_direction.py_func(mode, f_hold) == expected


@pytest.mark.parametrize("g0, g1, expected", [
    (1.0, -1.0, True),       # crossed inside the step
    (1.0, 0.0, True),        # ends exactly at the crossing
    (0.0, 0.0, False),       # at rest: no crossing
    (-0.0, 0.0, False),
    (1.0, 0.5, False),       # still slipping
    (0.0, -1.0, True),       # from zero, away: a crossing at the start
    (-1.0, -2.0, True),      # missed earlier (six legs: located at the start)
    (np.nan, 1.0, False),
    (1.0, np.nan, False),
])
def test_crossed_zero(g0, g1, expected):
    assert crossed_zero(g0, g1) == expected
    assert crossed_zero.py_func(g0, g1) == expected


def test_secant_fraction_of_a_linear_event_function_is_its_root():
    rng = np.random.default_rng(22)
    g0 = rng.uniform(1e-6, 10.0, 2000)
    g1 = -rng.uniform(1e-6, 10.0, 2000)
    for a, b in zip(g0, g1):
        root = Fraction(a) / (Fraction(a) - Fraction(b))  # g(x) = a + (b - a) x = 0
        fraction = secant_fraction(a, b)
        assert 0.0 < fraction < 1.0
        assert abs(Fraction(fraction) - root) <= Fraction(1.5 * math.ulp(float(root)))
    assert secant_fraction(3.0, -1.0) == 0.75               # exact where it can be
    assert secant_fraction(2.0, 0.0) == 1.0                  # ends on it
    assert secant_fraction(1.0, 2.0) == 0.0                  # not falling: at the start
    assert secant_fraction(1.0, 1.0) == 0.0
    assert secant_fraction(np.nan, -1.0) == 0.0


@njit(error_model="numpy")
def _trial_cosine(at, data):
    """``g(t0 + at) = cos(w (t0 + at)) - cos(w t*)``: positive before ``t*``; counts trials."""
    t0, w, t_star, count = data
    count[0] += 1
    return math.cos(w * (t0 + at)) - math.cos(w * t_star), t0 + at


@njit(error_model="numpy")  # not cached: it inlines the location loop with a test trial
def _locate_cosine(t0, h, w, t_star, count):
    data = (t0, w, t_star, count)
    g0 = _trial_cosine(0.0, data)[0]
    g1 = _trial_cosine(h, data)[0]
    count[0] = 0
    return locate(_trial_cosine, data, g0, g1, h, t0), g0


@pytest.mark.parametrize("t0, h, w, share", [
    (0.1, 1e-4, 2 * math.pi * 3.0, 0.37),       # a grid step of a 3 Hz cosine
    (0.013, 1e-4, 2 * math.pi * 20.0, 0.5),     # 20 Hz
    (0.013, 1e-4, 2 * math.pi * 20.0, 0.002),   # the event just after the step's start
    (0.013, 1e-4, 2 * math.pi * 20.0, 0.999),   # just before its end
    (0.05, 1e-3, 2 * math.pi * 5.0, 0.25),      # a coarser step
    (0.2, 1e-3, 2 * math.pi * 20.0, 0.91),      # more curvature: all 6 trials taken
])
def test_locate_finds_the_root_of_a_smooth_event_function(t0, h, w, share):
    root = share * h
    count = np.zeros(1, dtype=np.int64)
    (at, state), g0 = _locate_cosine(t0, h, w, t0 + root, count)
    assert 1 <= count[0] <= LOCATE_ITERATIONS
    # within what illinois_step's bracket test promises (1e-12 of the step)
    assert abs(at - root) <= 1e-12 * h
    trial = state - t0  # the last trial's time
    if count[0] < LOCATE_ITERATIONS:  # converged: the state is the trial at the time returned
        assert abs(trial - at) <= 4 * math.ulp(t0 + h)
    else:  # else the time is refined once more after the last trial
        assert abs(trial - root) <= 1e-6 * h


def test_locate_puts_an_event_whose_function_starts_non_positive_at_the_start():
    count = np.zeros(1, dtype=np.int64)
    # t* before the step: g0 < 0
    (at, state), g0 = _locate_cosine(0.1, 1e-4, 2 * math.pi, 0.05, count)
    assert g0 < 0.0 and at == 0.0 and state == 0.1 and count[0] == 0


def test_illinois_step_halves_the_end_kept_twice():
    # g > 0 twice: lo moves, and the second time the kept hi's value is halved
    done, at, lo, hi, g_lo, g_hi, side = illinois_step(0.5, 0.4, 1.0, 1.0, 0.0, 1.0, 1.0, -1.0, 0)
    assert not done and (lo, hi, g_lo, g_hi, side) == (0.5, 1.0, 0.4, -1.0, 1)
    assert at == 0.5 + 0.5 * 0.4 / 1.4
    done, at, lo, hi, g_lo, g_hi, side = illinois_step(at, 0.1, 1.0, 1.0, lo, hi, g_lo, g_hi,
                                                       side)
    assert not done and g_hi == -0.5 and g_lo == 0.1 and side == 1
    # converged: |g| below 1e-15 |g0|, or the bracket below 1e-12 h
    assert illinois_step(0.3, 1e-16, 1.0, 1.0, 0.0, 1.0, 1.0, -1.0, 0)[0]
    assert illinois_step(0.3, 0.1, 1.0, 1.0, 0.3, 0.3 + 1e-13, 1.0, -1.0, 0)[0]


def _calls(tree):
    return {node.func.attr if isinstance(node.func, ast.Attribute) else
            getattr(node.func, "id", None)
            for node in ast.walk(tree) if isinstance(node, ast.Call)}


def _names(node):
    return {n.id for n in ast.walk(node) if isinstance(n, ast.Name)}


def _copies(tree):
    """Lines that write a shared decision out again instead of calling it."""
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef) and node.name.lstrip("_") in stickslip.__all__ \
                and node.name.lstrip("_") not in _calls(node):  # (a wrapper delegates)
            found.append((node.lineno, f"defines {node.name}"))
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Div) \
                and isinstance(node.right, ast.BinOp) and isinstance(node.right.op, ast.Sub) \
                and isinstance(node.right.left, ast.Name) \
                and node.right.left.id in _names(node.left):
            found.append((node.lineno, "a secant g0 / (g0 - g1)"))
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Mult) and any(
                (isinstance(x, ast.Name) and x.id == "direction")
                or (isinstance(x, ast.Subscript) and "V_DIR" in _names(x))
                for x in (node.left, node.right)):
            found.append((node.lineno, "a slip event d * v"))
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Sub) \
                and isinstance(node.right, ast.Call) and getattr(node.right.func, "id", "") == "abs":
            found.append((node.lineno, "a margin Fs - |F|"))
        if isinstance(node, ast.IfExp) and isinstance(node.test, ast.Compare) \
                and isinstance(node.body, ast.UnaryOp) and isinstance(node.body.op, ast.USub) \
                and isinstance(node.orelse, ast.Constant) and node.orelse.value == 1:
            found.append((node.lineno, "a release direction -1 if F > 0 else 1"))
    return found


@pytest.mark.parametrize("name", sorted(USERS))
def test_the_kernels_call_the_shared_decisions_and_keep_no_copy(name):
    tree = ast.parse((ENGINE / name).read_text())
    assert USERS[name] <= _calls(tree), name
    assert not _copies(tree), (name, _copies(tree))
    # the Illinois iteration is reached through locate only
    assert "illinois_step" not in _calls(tree), name


def test_the_copy_detector_finds_the_copies_it_looks_for():
    source = """
def _hold_margin(mode, f_hold, fs):
    return fs - abs(f_hold)
theta = g0 / (g0 - g1)
at = h * g0 / (g0 - g1)
g = direction * s[1]
e = V[V_DIR + i] * V[V_VR + i]
d = -1 if f_hold > 0.0 else 1
"""
    kinds = sorted(kind for _, kind in _copies(ast.parse(source)))
    assert kinds == sorted(["defines _hold_margin", "a margin Fs - |F|",
                            "a secant g0 / (g0 - g1)", "a secant g0 / (g0 - g1)",
                            "a slip event d * v", "a slip event d * v",
                            "a release direction -1 if F > 0 else 1"])
