"""``qzs hexapod simulate --spring FILE.toml`` and ``--leg-spring N=FILE.toml``: each leg's
spring law from the command line, the same run as the Python API's (bit for bit), each leg's
law in the file's attributes; bad legs refused with exit 2 before any run."""
import numpy as np
import pytest

import qzs
from qzs.cli import main
from qzs.iotools.cf_layout import from_file_layout
from qzs.model.springs import ObliqueSpringQZS, PolynomialSpring
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
EVERY = "[spring]\nlaw = \"oblique\"\n"
LEG = "[spring]\nlaw = \"polynomial\"\ncoefficients = [70.0, -300.0, 0.0, -2e5]\n" \
      "center = -0.06\n"
RUN = ["--axis", "z", "--excitation", "sine", "--amplitude", "0.02", "--frequency", "3",
       "--duration", "0.3", "--dt", "1e-4", "--quiet"]


@pytest.fixture
def files(tmp_path):
    paths = {}
    for name, text in (("platform", PLATFORM), ("every", EVERY), ("leg", LEG)):
        paths[name] = tmp_path / f"{name}.toml"
        paths[name].write_text(text)
    return paths


def test_leg_springs_from_the_command_line_run_as_the_python_api_bit_for_bit(tmp_path, files):
    import dataclasses

    import xarray as xr

    out = tmp_path / "run.nc"
    assert main(["hexapod", "simulate", "--config", str(files["platform"]), "--spring",
                 str(files["every"]), "--leg-spring", f"3={files['leg']}", "--out", str(out),
                 *RUN]) == 0
    setup = load_hexapod(files["platform"])
    every = dataclasses.replace(setup.isolator, spring=ObliqueSpringQZS())
    legs = [every] * 6
    legs[2] = dataclasses.replace(setup.isolator, spring=PolynomialSpring(
        coefficients=(70.0, -300.0, 0.0, -2e5), center=-0.06))
    result = qzs.simulate_hexapod(setup.geometry, setup.platform, tuple(legs), setup.controller,
                                  excitation={"z": qzs.Sine(amplitude=0.02, frequency=3.0)},
                                  duration=0.3, dt=1e-4)
    with xr.open_dataset(out, engine="h5netcdf") as raw:
        data = from_file_layout(raw)
        for name in ("platform_pose", "relative_position", "spring_force", "spring_energy"):
            np.testing.assert_array_equal(data[name].values, result[name], err_msg=name)
        assert data.attrs["isolator.leg3.spring.law"] == "polynomial"
        assert data.attrs["isolator.leg1.spring.law"] == "oblique"
    # the laws act: leg 3's spring force is its polynomial's, 7.2 N above the oblique law's
    z = result["relative_position"][:, 2]
    np.testing.assert_allclose(result["spring_force"][:, 2], legs[2].spring.force(z),
                               rtol=1e-12, atol=1e-9)
    assert np.min(np.abs(ObliqueSpringQZS().force(z) - result["spring_force"][:, 2])) > 7.0


@pytest.mark.parametrize("options, message", [
    (["--leg-spring", "0=LEG"], "--leg-spring '0=LEG': '0' is not a leg: the legs are "
                                "numbered 1 to 6; give --leg-spring N=FILE.toml"),
    (["--leg-spring", "2=LEG", "--leg-spring", "2=EVERY"], "--leg-spring: leg 2 is given twice"),
    (["--spring", "PLATFORM"], "must hold a [spring] table and nothing else"),
])
def test_bad_spring_options_exit_2_before_any_run(files, capsys, options, message):
    options = [o.replace("LEG", str(files["leg"])).replace("EVERY", str(files["every"]))
               .replace("PLATFORM", str(files["platform"])) for o in options]
    message = message.replace("LEG", str(files["leg"]))
    assert main(["hexapod", "simulate", "--config", str(files["platform"]), *options,
                 *RUN]) == 2
    captured = capsys.readouterr()
    assert message in captured.err
    assert "Hexapod run" not in captured.out
