"""``qzs hexapod simulate --controller FILE.toml`` and ``--leg-controller N=FILE.toml``: each
leg's controller with blocks from the command line, the same run as the Python API's (bit for
bit); bad legs and blocks on centralised loops refused with exit 2 before any run."""
import numpy as np
import pytest

import qzs
from qzs.cli import main
from qzs.iotools.cf_layout import from_file_layout
from qzs.model.controller import ControllerParameters, Dither, FrictionCompensation
from qzs.workflows.hexapod.setups import load_hexapod

PLATFORM = """
[geometry]
kind = "cubic"
cube_edge = 0.15

[leg]
stiction_force = 1.0
coulomb_force = 0.8

[controller]
pi_kp = 2000.0
pi_ki = 800.0
"""
EVERY = "[controller]\npi_kp = 2000.0\npi_ki = 800.0\n[controller.dither]\namplitude = 0.5\n" \
        "frequency = 40.0\n"
LEG = "[controller]\npi_kp = 2500.0\npi_ki = 800.0\n[controller.compensation]\nfraction = 0.8\n"
RUN = ["--axis", "z", "--excitation", "sine", "--amplitude", "0.02", "--frequency", "3",
       "--duration", "0.3", "--dt", "1e-4", "--quiet"]


@pytest.fixture
def files(tmp_path):
    paths = {}
    for name, text in (("platform", PLATFORM), ("every", EVERY), ("leg", LEG)):
        paths[name] = tmp_path / f"{name}.toml"
        paths[name].write_text(text)
    return paths


def test_leg_controllers_from_the_command_line_run_as_the_python_api_bit_for_bit(
        tmp_path, files, capsys):
    import xarray as xr

    out = tmp_path / "run.nc"
    assert main(["hexapod", "simulate", "--config", str(files["platform"]), "--controller",
                 str(files["every"]), "--leg-controller", f"2={files['leg']}", "--out", str(out),
                 *RUN]) == 0
    text = capsys.readouterr().out
    assert "Leg 2:\n  controller       PI (Kp 2500 N/m" in text
    assert "compensation RMS" in text and "dither cost      platform acceleration" in text
    setup = load_hexapod(files["platform"])
    every = ControllerParameters(pi_kp=2000.0, pi_ki=800.0) + Dither(amplitude=0.5,
                                                                     frequency=40.0)
    legs = [every] * 6
    legs[1] = ControllerParameters(pi_kp=2500.0, pi_ki=800.0) + FrictionCompensation(
        fraction=0.8)
    result = qzs.simulate_hexapod(setup.geometry, setup.platform, setup.isolator, tuple(legs),
                                  excitation={"z": qzs.Sine(amplitude=0.02, frequency=3.0)},
                                  duration=0.3, dt=1e-4)
    with xr.open_dataset(out, engine="h5netcdf") as raw:
        data = from_file_layout(raw)
        for name in ("platform_pose", "motor_force", "relative_position", "dither_force",
                     "compensation_force"):
            np.testing.assert_array_equal(data[name].values, result[name], err_msg=name)
    assert not np.any(result["dither_force"][:, 1]) and np.any(result["compensation_force"][:, 1])


@pytest.mark.parametrize("options, message", [
    (["--leg-controller", "7=LEG"], "--leg-controller '7=LEG': '7' is not a leg: the legs "
                                    "are numbered 1 to 6; give --leg-controller N=FILE.toml"),
    (["--leg-controller", "3=LEG", "--leg-controller", "3=EVERY"],
     "--leg-controller: leg 3 is given twice"),
    (["--leg-controller", "3"], "--leg-controller '3' names no file"),
    (["--controller", "EVERY", "--centralised"],
     "centralised control (--centralised) models PI + damping alone; `leg 1's controller` "
     "has blocks beyond them (PI (Kp 2000 N/m, Ki 800 N/(m*s)) + dither (0.5 N at 40 Hz)); "
     "the blocks act on a leg's own motor loop (docs/hexapod.md §9.5a): leave out "
     "--centralised"),
    (["--leg-controller", "5=EVERY", "--centralised"], "`leg 5's controller` has blocks"),
])
def test_bad_controller_options_exit_2_before_any_run(files, capsys, options, message):
    options = [o.replace("LEG", str(files["leg"])).replace("EVERY", str(files["every"]))
               for o in options]
    message = message.replace("LEG", str(files["leg"]))
    assert main(["hexapod", "simulate", "--config", str(files["platform"]), *options,
                 *RUN]) == 2
    captured = capsys.readouterr()
    assert message in captured.err
    assert "Hexapod run" not in captured.out


def test_blocks_in_a_file_with_cartesian_loops_exit_2_naming_the_table(tmp_path, capsys):
    path = tmp_path / "central.toml"
    path.write_text(PLATFORM + "[legs.3.controller.dither]\namplitude = 1.0\nfrequency = 20.0\n"
                    "\n[cartesian]\npoint = 'origin'\n")
    assert main(["hexapod", "simulate", "--config", str(path), *RUN]) == 2
    err = capsys.readouterr().err
    assert f"centralised control ([cartesian] in '{path}')" in err
    assert f"`[legs.3.controller] in '{path}'` has blocks" in err and "dither (1 N at 20 Hz)" in err
