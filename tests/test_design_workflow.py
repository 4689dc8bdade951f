"""``qzs design``: the searches' answers checked by independent simulation, the report, the CLI.

One small design (a 60 s chirp, two stiction values, one mass, one force step, a fixed step)
serves every test; its chosen smallest proportional gain must keep every case inside the
constant-force band and off the stops when re-simulated one by one with ``qzs.simulate``,
and the failing gain just below it must not.
"""
import dataclasses
import json
import math

import numpy as np
import pytest

import qzs
from qzs import Chirp, ControllerParameters, IsolatorParameters, ParameterError
from qzs.analysis import control_design as cd
from qzs.cli import main
from qzs.workflows import design as D

EXCITATION = Chirp(duration=60.0)
DT = 1e-3
OPTIONS = dict(excitation=EXCITATION, stiction_range=(8.0, 12.0), mass_range=(6.4, 6.4),
               force_steps=(2.0,), band=(1.0, 20.0), quick=True, dt=DT, damping_gain_max=300.0)


@pytest.fixture(scope="module")
def design():
    return D.design_controller(**OPTIONS)


def case_passes(case, kp, kd, result):
    """Simulate one case alone with qzs.simulate; is it inside the band and off the stops?"""
    settings = result.settings
    controller = ControllerParameters(pi_kp=kp, pi_ki=settings["integral_ratio"] * kp,
                                      damping_gain=kd)
    excitation, isolator, initial, duration = case.run_inputs(
        IsolatorParameters(), controller, EXCITATION, settings["duration"], quick=True)
    run = qzs.simulate(excitation, isolator, controller, duration=duration, dt=DT,
                       sample_rate=settings["sample_rate"], initial_state=initial)
    low, high = settings["stroke_band"]
    z = run.relative_position
    return bool(z.min() >= low and z.max() <= high and run.run["stop_contacts"] == 0)


def test_the_smallest_kp_keeps_every_case_in_the_band_and_a_slightly_smaller_one_does_not(
        design):
    pi = design.pi_search
    assert pi["found"]
    kp, failing, kd = pi["pi_kp"], pi["failing_kp"], pi["damping_gain"]
    assert failing < kp <= 1.2 * failing  # a bracket of at most 20 % (quick: three bisections)
    cases = D._cases((8.0, 12.0), (6.4, 6.4), (2.0,), True)
    assert len(cases) == pi["cases"] == 6
    assert all(case_passes(case, kp, kd, design) for case in cases)
    assert not all(case_passes(case, failing, kd, design) for case in cases)


def test_the_final_gains_pass_and_are_linearly_stable(design):
    assert design.verification["summary"]["passes"]
    g = design.gains
    assert g["pi_ki"] == pytest.approx(0.4 * g["pi_kp"])
    assert design.stability.stable and design.stability.agrees
    low, high = design.stability.damping_gain_limits
    assert low <= g["damping_gain"] < high
    assert design.margins["meets"]


def test_the_damping_gain_has_the_least_cost_of_those_tried(design):
    rows = [r for r in design.damping["rows"] if math.isfinite(r["cost"])]
    best = min(rows, key=lambda r: r["cost"])
    assert design.gains["damping_gain"] == best["damping_gain"]
    assert design.gains["damping_gain"] <= design.damping["bound"] + 1e-9
    costs = [r["cost"] for r in sorted(rows, key=lambda r: r["damping_gain"])]
    assert costs[-1] < costs[0]  # damping lowers the band RMS on the 60 s chirp


def test_hunting_of_the_pi_loop_alone_confirms_the_relay_and_refutes_the_friction_law(design):
    alone = [r for r in design.hunting["rows"] if r["damping_gain"] == 0.0]
    assert {r["stiction_force"] for r in alone} == {8.0, 10.0, 12.0}
    for row in alone:
        assert row["simulation"]["hunts"] and row["prediction"]["hunts"]
        assert row["relay_confirmed"] is True
        assert row["memoryless_confirmed"] is False  # it predicted no cycle
        assert row["simulation"]["amplitude"] == pytest.approx(row["prediction"]["amplitude"],
                                                               rel=0.15)


def test_more_damping_helps_more_on_the_papers_set_up(design):
    sweep = sorted((r for r in design.why["rows"] if r["factor"] == "baseline"),
                   key=lambda r: r["damping_gain"])
    changes = [r["change_db"] for r in sweep]
    assert len(changes) >= 4 and all(np.diff(changes) < 0)
    factors = {r["factor"] for r in design.why["rows"]}
    assert {"viscous friction", "high-pass", "controller rate"} <= factors
    assert "viscous friction" in design.why["answer"]


def test_to_dict_is_strict_json_and_the_result_is_frozen(design):
    text = json.dumps(design.to_dict(), allow_nan=False)
    assert json.loads(text)["gains"]["pi_kp"] == pytest.approx(design.gains["pi_kp"])
    with pytest.raises(dataclasses.FrozenInstanceError):
        design.gains = {}


def test_save_writes_report_json_and_every_figure_atomically(design, tmp_path):
    written = design.save(tmp_path / "out")
    names = sorted(p.name for p in (tmp_path / "out").iterdir())
    assert "report.html" in names and "design.json" in names
    for figure in ("static_design", "pi_search", "hunting", "damping", "margins",
                   "damping_effect"):
        assert f"{figure}.png" in names and f"{figure}.svg" in names
    assert not [n for n in names if n.startswith(".")]  # no temporary file left
    record = json.loads(written["json"].read_text())
    assert record["gains"]["damping_gain"] == pytest.approx(design.gains["damping_gain"])
    html = written["report"].read_text()
    assert "Why active damping did not help much" in html and "pi_search.png" in html


@pytest.mark.parametrize("change, words", [
    (dict(stiction_range=(0.5, 2.0)), "stiction_range"),
    (dict(band=(1.0, 50.0)), "band"),
    (dict(band=(0.0, 20.0)), "band"),
    (dict(cost="mean"), "cost"),
    (dict(controller=ControllerParameters(pi_kp=0.0)), "pi_kp"),
    (dict(excitation=qzs.Sine()), "excitation"),
    (dict(force_steps=("a",)), "force_steps"),
    (dict(delay=-1.0), "delay"),
    (dict(controller_rate=300.0), "controller_rate"),
    (dict(excitation=Chirp(duration=15.0, f1=20.0)), "too short"),
    (dict(mass_range=(6.0,)), "mass_range"),
])
def test_bad_input_fails_before_any_simulation(monkeypatch, change, words):
    def forbidden(*args, **kwargs):
        raise AssertionError("simulated before checking the input")

    monkeypatch.setattr(D, "simulate", forbidden)
    monkeypatch.setattr(D, "simulate_batch", forbidden)
    with pytest.raises(ParameterError, match=words):
        D.design_controller(**{**OPTIONS, **change})


def test_cli_writes_the_report_and_prints_json(design, monkeypatch, tmp_path, capsys):
    seen = {}

    def fake(isolator, controller, **options):
        seen.update(options)
        return design

    monkeypatch.setattr(D, "design_controller", fake)
    out = tmp_path / "design"
    code = main(["design", "--out", str(out), "--json", "--quiet", "--stiction-range", "8,12",
                 "--mass-range", "6.4,6.4", "--force-steps", "2", "--cost", "peak",
                 "--delay", "0.001"])
    assert code == 0
    record = json.loads(capsys.readouterr().out)
    assert record["gains"]["pi_kp"] == pytest.approx(design.gains["pi_kp"])
    assert (out / "report.html").exists() and (out / "design.json").exists()
    assert seen["stiction_range"] == (8.0, 12.0) and seen["force_steps"] == (2.0,)
    assert seen["cost"] == "peak" and seen["delay"] == 0.001


@pytest.mark.parametrize("argv, words", [
    (["design", "--stiction-range", "5"], "--stiction-range"),
    (["design", "--band", "1,x"], "--band"),
    (["design", "--force-steps", "2,b"], "--force-steps"),
    (["design", "--set", "pi_kp=0"], "pi_kp"),
])
def test_cli_bad_input_is_exit_2_before_any_work(argv, words, monkeypatch, capsys, tmp_path):
    def forbidden(*args, **kwargs):
        raise AssertionError("simulated before checking the input")

    monkeypatch.setattr(D, "simulate", forbidden)
    monkeypatch.setattr(D, "simulate_batch", forbidden)
    monkeypatch.setattr(D, "choose_step", forbidden)
    assert main(argv + ["--quiet", "--out", str(tmp_path / "d")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("qzs: error:") and words in err


def test_cli_refuses_an_output_that_is_a_file(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(D, "design_controller",
                        lambda *a, **k: pytest.fail("designed before checking --out"))
    target = tmp_path / "taken"
    target.write_text("x")
    assert main(["design", "--out", str(target), "--quiet"]) == 2
    assert "--out" in capsys.readouterr().err


def test_the_design_hunting_case_starts_on_the_predicted_cycle():
    controller = ControllerParameters(pi_kp=200.0, pi_ki=80.0)
    case = D.DesignCase("hunting", 10.0, 6.4)
    excitation, isolator, initial, duration = case.run_inputs(
        IsolatorParameters(), controller, EXCITATION, 60.0)
    prediction = cd.predict_hunting(isolator, controller)
    assert excitation.amplitude == 0.0
    assert initial.relative_position - controller.position_setpoint == pytest.approx(
        prediction.amplitude)
    assert duration > 4 * prediction.relay_period
