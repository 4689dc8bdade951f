"""Ishigami's function as the metric of a design problem: its analytic Sobol indices are what
the sensitivity tests (test_sensitivity.py, test_sensitivity_result.py) measure against."""
import math

import numpy as np

#: Three registry parameters stand for Ishigami's x1, x2, x3 (each uniform on [-pi, pi]):
#: the problem only checks that low < high, and ``evaluate=`` replaces the simulator.
ISHIGAMI_NAMES = ("pi_kp", "pi_ki", "damping_gain")
ISHIGAMI_COLUMN = "linear_transmissibility_at_3_hz"
A, B = 7.0, 0.1


def ishigami_indices():
    """Analytic first-order and total indices (Ishigami & Homma 1990; Sobol' 1999)."""
    v1 = 0.5 * (1 + B * math.pi ** 4 / 5) ** 2
    v2 = A ** 2 / 8
    v13 = B ** 2 * math.pi ** 8 * (1 / 18 - 1 / 50)
    v = v1 + v2 + v13
    return np.array([v1, v2, 0.0]) / v, np.array([v1 + v13, v2, v13]) / v


def ishigami_problem(**sensitivity_table):
    return {"problem": {"name": "ishigami", "title": "Ishigami function"},
            # the gains cannot be negative: searched on [0, 2 pi], shifted by -pi below
            "variables": {n: {"low": 0.0, "high": 2 * math.pi} for n in ISHIGAMI_NAMES},
            "objectives": [{"metric": "linear_transmissibility_at", "frequency": 3.0}],
            "sensitivity": sensitivity_table}


def ishigami(settings):
    """The evaluator put in place of qzs: the same cases, Ishigami's function of them."""
    x = np.array([[case[name] for name in ISHIGAMI_NAMES] for case in settings]) - math.pi
    y = np.sin(x[:, 0]) + A * np.sin(x[:, 1]) ** 2 + B * x[:, 2] ** 4 * np.sin(x[:, 0])
    return {ISHIGAMI_COLUMN: y}
