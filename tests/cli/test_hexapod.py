"""``qzs hexapod linear`` and the hexapod files: closed forms through the command line."""
import json
import math

import numpy as np
import pytest

from qzs.cli import main
from qzs.errors import ParameterError
from qzs.model.hexapod import leg_unit_vectors
from qzs.model.isolator import IsolatorParameters, spring_force
from qzs.workflows.hexapod.setups import (default_cube_center_height, hexapod_setup, load_hexapod,
                                          supported_mass)
from qzs.iotools.cf_layout import from_file_layout


def run_json(capsys, *argv):
    code = main(["hexapod", "linear", *argv, "--json"])
    assert code == 0
    return json.loads(capsys.readouterr().out)


@pytest.mark.parametrize("edge", [0.1, 0.25])
def test_cubic_stiffness_at_the_cube_centre_is_the_published_diagonal(capsys, edge):
    """k * diag(2, 2, 2, a^2/2, a^2/2, 2 a^2) for every leg of axial stiffness k."""
    k = 1234.0
    record = run_json(capsys, "--cubic", "--cube-edge", str(edge), "--leg-stiffness", str(k),
                      "--no-preload", "--frame", "cube-center")
    expected = k * np.diag([2, 2, 2, edge ** 2 / 2, edge ** 2 / 2, 2 * edge ** 2])
    np.testing.assert_allclose(record["stiffness_matrix"], expected, rtol=1e-12,
                               atol=1e-9 * k)
    assert record["frame"] == "cube_center"
    m = record["platform_mass"]
    # translations: 2k on mass m
    assert record["natural_frequencies"][0] == pytest.approx(
        math.sqrt(2 * k / m) / (2 * math.pi), rel=1e-9)


def test_off_the_centre_translations_and_rotations_couple(capsys):
    edge, k = 0.2, 1000.0
    centre = run_json(capsys, "--cubic", "--cube-edge", str(edge), "--leg-stiffness", str(k),
                      "--no-preload", "--frame", "cube-center")
    setup = hexapod_setup()
    raised = run_json(capsys, "--cubic", "--cube-edge", str(edge), "--leg-stiffness", str(k),
                      "--no-preload", "--frame", "origin", "--set", "pi_kp=50")
    assert np.allclose(np.asarray(centre["stiffness_matrix"])[:3, 3:], 0.0, atol=1e-9 * k)
    assert setup.kind == "cubic" and np.allclose(raised["stiffness_matrix"],
                                                 centre["stiffness_matrix"])


def test_the_default_payload_is_what_the_springs_hold():
    """Six springs at the setpoint push with f along their legs: m g = f * sum(u_z)."""
    setup = hexapod_setup()
    f = float(spring_force(setup.controller.position_setpoint, IsolatorParameters()))
    uz = leg_unit_vectors(setup.geometry)[:, 2]
    assert setup.platform.mass * 9.81 == pytest.approx(f * uz.sum(), rel=1e-12)
    assert uz == pytest.approx(np.full(6, 1 / math.sqrt(3)))  # cubic legs: 54.7 deg off vertical
    assert supported_mass(setup.geometry, gravity=9.81) == pytest.approx(setup.platform.mass)


def test_set_stiffens_every_leg(capsys):
    """pi_kp adds Kp to each leg's axial stiffness: 2 Kp in each translation of the cube."""
    base = run_json(capsys, "--cubic", "--frame", "cube-center", "--no-preload")
    stiffer = run_json(capsys, "--cubic", "--frame", "cube-center", "--no-preload",
                       "--set", "pi_kp=550")
    difference = np.diag(stiffer["stiffness_matrix"]) - np.diag(base["stiffness_matrix"])
    assert difference[:3] == pytest.approx([1000.0] * 3, rel=1e-9)


def test_paper_legs_are_statically_unstable_under_their_own_preload(capsys):
    """Compressed legs on spherical joints: negative stiffness -4 f/a in each translation
    of the cube, far above the legs' 2 (k_spring + Kp) with the paper's Kp = 50 N/m:
    unstable directions get no frequency."""
    record = run_json(capsys, "--cubic")
    assert record["stable"] is False
    assert any(f is None for f in record["natural_frequencies"])
    assert any("statically unstable" in note for note in record["notes"])
    text_code = main(["hexapod", "linear", "--cubic"])
    assert text_code == 0


@pytest.mark.parametrize("command", ["linear", "simulate", "transmissibility"])
def test_every_subcommand_defaults_to_the_shipped_platform(capsys, command):
    """One default platform for every six-axis command: without --config or --cubic,
    `hexapod linear` analysed a bare cube with Kp = 50 N/m (three unstable modes) while
    `simulate` and `transmissibility` ran the shipped paper_legs_cubic."""
    from qzs.cli import build_parser
    from qzs.cli.hexapod import DEFAULT_SETUP, _setup
    from qzs.workflows.hexapod.setups import SHIPPED_DEFAULT

    setup = _setup(build_parser().parse_args(["hexapod", command]))
    shipped = load_hexapod(SHIPPED_DEFAULT)
    assert setup.source == shipped.source and setup.controller == shipped.controller
    assert setup.platform.mass == shipped.platform.mass
    assert main(["hexapod", command, "--help"]) == 0
    assert SHIPPED_DEFAULT in DEFAULT_SETUP
    assert " ".join(DEFAULT_SETUP.split()) in " ".join(capsys.readouterr().out.split())


def test_the_default_linear_model_is_the_shipped_platforms_and_stable(capsys):
    from qzs.workflows.hexapod.setups import SHIPPED_DEFAULT

    default = run_json(capsys)
    assert default == run_json(capsys, "--config", SHIPPED_DEFAULT)
    assert default["stable"] is True  # Kp = 2000 N/m holds the preload (docs/hexapod.md §6)


def test_hexapod_file(tmp_path, capsys):
    path = tmp_path / "radial.toml"
    path.write_text("[geometry]\nkind = 'radial'\nbase_radius = 0.2\ntop_radius = 0.12\n"
                    "base_angle = 20.0\ntop_angle = 30.0\nheight = 0.25\n"
                    "[platform]\nmass = 10.0\nprincipal_inertia = [0.1, 0.1, 0.15]\n"
                    "[leg]\nviscous_damping = 50.0\n[controller]\npi_kp = 3000.0\n")
    setup = load_hexapod(path)
    assert setup.kind == "radial" and setup.platform.mass == 10.0
    assert setup.isolator.viscous_damping == 50.0 and setup.controller.pi_kp == 3000.0
    record = run_json(capsys, "--config", str(path), "--no-preload")
    assert np.allclose(record["stiffness_matrix"], np.asarray(record["stiffness_matrix"]).T)
    assert record["stable"] is True
    assert main(["hexapod", "linear", "--config", str(path), "--frame", "cube-center"]) == 2
    assert "needs a cubic geometry" in capsys.readouterr().err


@pytest.mark.parametrize("text, match", [
    ("[geometry]\nkind = 'square'\n", "`kind` must be one of"),
    ("[geometry]\nkind = 'cubic'\n", "missing key\\(s\\) \\['cube_edge'\\]"),
    ("[geometry]\nkind = 'cubic'\ncube_edge = 0.1\nwidth = 2\n", "unknown key\\(s\\) \\['width'\\]"),
    ("[geometry]\nkind = 'cubic'\ncube_edge = 0.1\n[leg]\npi_kp = 3.0\n",
     "`pi_kp` is not an isolator parameter"),
    ("[geometry]\nkind = 'cubic'\ncube_edge = 0.1\n[platform]\nmass = 3.0\n"
     "inertia = [[1,0,0],[0,1,0],[0,0,1]]\nprincipal_inertia = [1, 1, 1]\n", "not both"),
    ("[geometry]\nkind = 'cubic'\ncube_edge = 0.1\n[excitation.w]\nkind = 'sine'\n",
     "unknown axis name\\(s\\) \\['w'\\] in \\[excitation\\]"),
    ("[geometry]\nkind = 'cubic'\ncube_edge = 0.1\n[wheels]\n", "unknown table"),
    ("[geometry]\nkind = 'cubic'\ncube_edge = 0.1\n[cartesian]\ngain = 3\n",
     "unknown key\\(s\\) \\['gain'\\] in \\[cartesian\\]"),
    ("[geometry]\nkind = 'cubic'\ncube_edge = 0.1\n[cartesian]\nposition_gain = [1, 2]\n",
     "position_gain"),
    ("[geometry]\nkind = 'cubic'\ncube_edge = 0.1\n[cartesian]\npoint = 'centre'\n", "point"),
])
def test_bad_hexapod_files_name_what_is_wrong(tmp_path, text, match):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(ParameterError, match=match):
        load_hexapod(path)


def test_bad_options_are_usage_errors(capsys):
    assert main(["hexapod", "linear", "--cube-edge", "0.1"]) == 2
    assert "add --cubic" in capsys.readouterr().err
    assert main(["hexapod", "linear", "--cubic", "--cube-edge", "-1"]) == 2
    assert "`--cube-edge` must be positive, got -1.0" in capsys.readouterr().err
    assert main(["hexapod", "linear", "--leg-stiffness", "0"]) == 2
    assert default_cube_center_height(0.3) == pytest.approx(0.3 / (2 * math.sqrt(3)))


def test_linear_plot_is_written_and_draws_the_model(tmp_path, capsys):
    """--plot writes the 6x6 grid; the diagonal panels carry the model's own curve."""
    import matplotlib.pyplot as plt

    from qzs.analysis.hexapod_linear import hexapod_linearize
    from qzs.viz.hexapod_matrix import plot_transmissibility_matrix

    out = tmp_path / "grid.png"
    assert main(["hexapod", "linear", "--set", "pi_kp=2500", "--plot", str(out)]) == 0
    assert out.stat().st_size > 10_000 and not list(tmp_path.glob("*.tmp*"))
    setup = hexapod_setup(settings={"pi_kp": 2500.0})
    model = hexapod_linearize(setup.geometry, setup.platform, setup.isolator, setup.controller)
    frequency = np.geomspace(0.1, 10, 50)
    figure = plot_transmissibility_matrix(frequency, linear=model)
    line = figure.axes[2 * 6 + 2].get_lines()[0]  # platform z per base z
    expected = 20 * np.log10(np.abs(model.transmissibility(frequency)[:, 2, 2]))
    np.testing.assert_allclose(line.get_ydata(), expected)
    plt.close(figure)
    with pytest.raises(ParameterError, match="shape"):
        plot_transmissibility_matrix(frequency, simulated=np.ones((3, 6, 6)))
    assert main(["hexapod", "linear", "--plot", str(tmp_path / "grid.txt")]) == 2


def test_hexapod_simulate_command(tmp_path, capsys):
    """The shipped platform under an x sine: a summary per leg, a CF file with a dof
    dimension, a figure; options that need an axis say so."""
    import xarray as xr

    out, figure = tmp_path / "run.nc", tmp_path / "run.png"
    assert main(["hexapod", "simulate", "--axis", "x", "--excitation", "sine", "--frequency",
                 "4", "--amplitude", "0.003", "--duration", "2", "--out", str(out), "--plot",
                 str(figure), "--quiet"]) == 0
    text = capsys.readouterr().out
    assert "stroke used" in text and "Energy ledger residual" in text
    assert "Step: dt = " in text and "(tolerance 1e-05 m" in text
    with xr.open_dataset(out, engine="h5netcdf") as raw:
        data = from_file_layout(raw)  # the containers as dotted attributes
        assert data.sizes["dof"] == 6 and data.sizes["leg"] == 6
        assert data.sizes["time"] == 2001
        # the file states the step, its estimated error and the tolerance
        assert data.attrs["run.step"] in ("accuracy-driven", "fallback")
        assert data.attrs["run.step_tolerance_m"] == 1e-5
        assert data.attrs["run.step_tolerance_m_units"] == "m"
        assert data.attrs["run.step_error_m_units"] == "m" and data.attrs["run.dt_units"] == "s"
        assert "run.step_error_m" in data.attrs
    assert figure.stat().st_size > 10_000
    assert main(["hexapod", "simulate", "--amplitude", "0.01"]) == 2
    assert "add --axis" in capsys.readouterr().err
    assert main(["hexapod", "simulate", "--out", str(tmp_path / "x.csv")]) == 2


def test_hexapod_simulate_chooses_the_step_for_a_tolerance_unless_dt_is_given(capsys):
    """By default the step is chosen (a chirp along one axis: its transmissibility in dB; a
    random motion: the pose in m) and the JSON's ``step`` says how, with the estimated error
    and the tolerance; ``--dt`` is literal; both at once, or a bad tolerance, is refused."""
    import json

    def run(*options):
        assert main(["hexapod", "simulate", "--axis", "z", "--excitation-duration", "4",
                     "--quiet", "--json", *options]) == 0
        return json.loads(capsys.readouterr().out)

    chirp = run("--f1", "8", "--tolerance", "0.05")
    step = chirp["step"]
    assert step["step"] == "accuracy-driven" and step["step_tolerance_db"] == 0.05
    assert 0 < step["step_error_db"] <= 0.05 / 2 and step["dt"] == chirp["run"]["dt"]
    assert step["step_reference_dt"] == step["dt"] / 4
    random = run("--excitation", "random", "--f1", "8")
    assert random["step"]["step_tolerance_m"] == 1e-5 and "step_error_m" in random["step"]
    assert set(random["step"]) == {"dt", "step", "step_error_m", "step_tolerance_m",
                                   "step_reference_dt", "step_probe_duration", "step_reason"}
    literal = run("--dt", "5e-4")
    assert literal["run"]["dt"] == 5e-4 and literal["step"]["step"] == "given"
    assert not any("tolerance" in key for key in literal["step"])
    assert main(["hexapod", "simulate", "--axis", "x", "--dt", "1e-3", "--tolerance",
                 "0.01"]) == 2
    assert "not allowed with argument" in capsys.readouterr().err
    assert main(["hexapod", "simulate", "--axis", "x", "--tolerance", "-1"]) == 2
    error = capsys.readouterr().err
    assert "tolerance" in error and "-1" in error


def test_cartesian_table_and_sampled_controller_from_a_file(tmp_path, capsys):
    """``[cartesian]``: gains left out are the legs' loops' stiffness on each axis; at the
    cube's centre of a cubic platform that is the per-leg linear model exactly, and the
    simulation says which control it ran; ``controller_rate`` makes the loops sampled."""
    text = ("[geometry]\nkind = 'cubic'\ncube_edge = 0.15\n"
            "[controller]\npi_kp = 2000.0\npi_ki = 800.0\ncontroller_rate = 1000.0\n"
            "[excitation.z]\nkind = 'sine'\namplitude = 0.001\nfrequency = 2.0\n")
    per_leg, centralised = tmp_path / "legs.toml", tmp_path / "axes.toml"
    per_leg.write_text(text)
    centralised.write_text(text + "[cartesian]\npoint = 'origin'\nposition_gain = "
                           "[4000.0, 4000.0, 8000.0, 22.5, 22.5, 90.0]\n")
    setup = load_hexapod(centralised)
    assert setup.cartesian.point == "origin"
    assert setup.cartesian.position_gain[2] == 8000.0
    assert np.allclose(setup.cartesian.integral_gain[:3], 2 * 800.0)  # 2 legs' worth per axis
    one = run_json(capsys, "--config", str(per_leg), "--frame", "cube-center")
    two = run_json(capsys, "--config", str(centralised), "--frame", "cube-center")
    stiffness = np.asarray(two["stiffness_matrix"]) - np.asarray(one["stiffness_matrix"])
    assert np.allclose(stiffness, np.diag([0, 0, 4000.0, 0, 0, 0]), atol=1e-6)
    assert main(["hexapod", "simulate", "--config", str(centralised), "--duration", "0.5"]) == 0
    out = capsys.readouterr().out
    assert "centralised" in out and "sampled at 1000 Hz" in out


def test_centralised_option_equals_the_per_leg_loops_at_the_cube_centre(tmp_path, capsys):
    """``--centralised`` puts the loops on the platform's axes with the legs' stiffness on
    each: at the cube's centre that is the per-leg linear model to rounding; a file with its
    own [cartesian] table refuses the option."""
    per_leg = run_json(capsys, "--cubic", "--set", "pi_kp=2000", "--frame", "cube-center")
    axes = run_json(capsys, "--cubic", "--set", "pi_kp=2000", "--frame", "cube-center",
                    "--centralised")
    assert np.allclose(axes["stiffness_matrix"], per_leg["stiffness_matrix"], atol=1e-8)
    assert np.allclose(axes["natural_frequencies"], per_leg["natural_frequencies"])
    path = tmp_path / "axes.toml"
    path.write_text("[geometry]\nkind = 'cubic'\ncube_edge = 0.15\n[cartesian]\n")
    assert main(["hexapod", "linear", "--config", str(path), "--centralised"]) == 2
    assert "[cartesian]" in capsys.readouterr().err


@pytest.mark.parametrize("given, scale", [([], "log"), (["--frequency-axis", "linear"], "linear")])
def test_linear_plot_takes_the_frequency_axis_asked_for(tmp_path, monkeypatch, given, scale):
    """--frequency-axis reaches the grid: log by default, linear on request."""
    import qzs.viz.hexapod_matrix as module

    drawn = []
    original = module.plot_transmissibility_matrix

    def spy(*args, **kwargs):
        figure = original(*args, **kwargs)
        drawn.append({ax.get_xscale() for ax in figure.axes})
        return figure

    monkeypatch.setattr(module, "plot_transmissibility_matrix", spy)
    assert main(["hexapod", "linear", "--plot", str(tmp_path / "grid.png"), *given]) == 0
    assert drawn == [{scale}]


@pytest.mark.parametrize("command", [["hexapod", "simulate"], ["simulate"]])
def test_an_astronomical_duration_with_out_is_one_clear_line(command, tmp_path, capsys):
    out = tmp_path / "run.nc"
    assert main([*command, "--duration", "1e308", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "duration" in err and "1e+308" in err
    assert list(tmp_path.iterdir()) == []
