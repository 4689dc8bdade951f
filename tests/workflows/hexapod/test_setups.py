"""Six-axis set-ups read from hexapod files (qzs.workflows.hexapod.setups): bad numbers named
by table and key, and a set-up's simulated run with its step; the names of the set-up object
and the linear report still import from here."""
import pytest

from qzs import ParameterError
from qzs.workflows.hexapod import linear_report, platform_setup, setups
from qzs.workflows.hexapod.setups import SHIPPED_DEFAULT, load_hexapod


def test_the_set_up_object_and_the_linear_report_import_from_setups_as_before():
    for module in (platform_setup, linear_report):
        for name in module.__all__:
            if name in setups.__all__:
                assert getattr(setups, name) is getattr(module, name), name
    assert {"HexapodSetup", "hexapod_setup", "default_platform", "linear_record",
            "plot_linear_transmissibility", "centralised"} <= set(setups.__all__)


@pytest.mark.parametrize("tables, message", [
    ('[platform]\nmass = "heavy"\n', r"`\[platform\] mass` must be a number, got 'heavy'; "
                                      r"give a number in kg, e.g. mass = 21.5"),
    ('[platform]\ngravity = "g"\n', r"`\[platform\] gravity` must be a number, got 'g'"),
    ('[platform]\nprincipal_inertia = ["a", "b", "c"]\n', r"`principal_inertia` must be 3"),
])
def test_a_hexapod_file_with_text_for_a_number_names_the_table_and_key(tmp_path, tables,
                                                                       message):
    from qzs.errors import ParameterError

    path = tmp_path / "bad.toml"
    path.write_text('[geometry]\nkind = "cubic"\ncube_edge = 0.15\n' + tables)
    with pytest.raises(ParameterError, match=message) as caught:
        load_hexapod(path)
    assert str(path) in str(caught.value)


@pytest.mark.parametrize("geometry, message", [
    ('kind = "cubic"\ncube_edge = "big"\n', r"`\[geometry\] cube_edge` must be a number"),
    ('kind = "radial"\nbase_radius = 0.1\ntop_radius = 0.1\nheight = 0.1\n'
     'base_angle = "x"\ntop_angle = 10\n', r"`\[geometry\] base_angle` must be a number"),
])
def test_a_geometry_with_text_for_a_number_names_the_key(tmp_path, geometry, message):
    from qzs.errors import ParameterError

    path = tmp_path / "bad.toml"
    path.write_text("[geometry]\n" + geometry)
    with pytest.raises(ParameterError, match=message):
        load_hexapod(path)


@pytest.mark.parametrize("excitation, options, measure", [
    ({"z": {"kind": "chirp", "duration": 4.0}}, {}, "transmissibility_db"),
    ({"z": {"kind": "sine", "frequency": 3.0}}, {}, "state_m"),
    ({"x": {"kind": "chirp", "duration": 4.0}}, {}, "state_m"),  # with the file's z: two axes
    ({"z": {"kind": "sine", "frequency": 3.0}}, {"tolerance": 0.1}, "transmissibility_db"),
])
def test_simulate_setup_measures_the_step_by_what_the_run_answers(monkeypatch, excitation,
                                                                  options, measure):
    """A chirp along one axis answers a transmissibility (dB), anything else a motion (m);
    the tolerance defaults to ACCURACY's and the choice is what the run's record says."""
    import qzs.engine.step_choice as step_choice
    from qzs.defaults import ACCURACY
    from qzs.workflows.hexapod.setups import simulate_setup

    seen = {}

    def chooser(request, probe, **kwargs):
        seen.update(kwargs, resolved=request.resolved(probe.default_measure))
        raise RuntimeError("stop")  # the choice is all this test looks at

    monkeypatch.setattr(step_choice, "choose", chooser)
    with pytest.raises(RuntimeError, match="stop"):
        simulate_setup(load_hexapod(SHIPPED_DEFAULT), excitation=excitation, duration=2.0,
                       **options)
    key = "tolerance_db" if measure == "transmissibility_db" else "tolerance_state"
    given = options.get("tolerance", options.get("tolerance_state"))
    assert seen["resolved"] == (measure, ACCURACY[key] if given is None else given)
    assert seen["finest"] == 1e-4 and seen["fallback"] is True  # the file's dt: the fallback


@pytest.mark.parametrize("options, match", [
    (dict(dt=1e-3, tolerance=0.01), "one of `dt`.*got `dt` and `tolerance`"),
    (dict(dt=1e-3, tolerance_state=1e-5), "one of `dt`.*got `dt` and `tolerance_state`"),
    (dict(tolerance=0.01, tolerance_state=1e-5), "got `tolerance` and `tolerance_state`"),
    (dict(tolerance_state=-1.0), "`tolerance_state` must be positive, got -1"),
    (dict(tolerance=float("inf")), "`tolerance`.*inf"),
    (dict(duration=-1.0), "`duration`"),  # the run's own settings, before any probe
])
def test_simulate_setup_refuses_bad_steps_before_any_run(monkeypatch, options, match):
    import qzs.engine.hexapod.simulate as simulate
    from qzs.errors import ParameterError
    from qzs.workflows.hexapod.setups import simulate_setup

    def no_run(*args, **kwargs):
        raise AssertionError("a run started")

    monkeypatch.setattr(simulate, "simulate_hexapod", no_run)
    with pytest.raises(ParameterError, match=match):
        simulate_setup(load_hexapod(SHIPPED_DEFAULT), **{"duration": 1.0, **options})


def test_a_given_dt_is_literal_and_recorded_as_given():
    from qzs.workflows.hexapod.setups import simulate_setup

    result = simulate_setup(load_hexapod(SHIPPED_DEFAULT), duration=0.5, dt=5e-4)
    assert result.run["dt"] == 5e-4 and result.run["steps"] == 1000
    assert result.run["step"] == "given" and "Step: dt = 0.0005 s, given" in result.summary()


def test_simulate_setup_takes_tolerance_db_as_the_deprecated_name_of_tolerance():
    from qzs.workflows.hexapod.setups import simulate_setup

    with pytest.warns(DeprecationWarning, match="use `tolerance`"), \
            pytest.raises(ParameterError, match="got `dt` and `tolerance`"):
        simulate_setup(load_hexapod(SHIPPED_DEFAULT), excitation={"z": {"kind": "chirp"}},
                       dt=1e-3, tolerance_db=0.01)
