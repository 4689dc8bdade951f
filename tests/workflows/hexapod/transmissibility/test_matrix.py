"""The simulated 6x6 transmissibility and the shipped hexapod study (docs/hexapod.md §10).

Reference checks, each able to fail: frictionless small-amplitude chirps reproduce the linear
model's matrix (the diagonal and the coupling the preload and an off-centre payload make);
the entries a symmetric platform keeps at zero come out untrusted, which the coherence alone
would not do; the energy ledger closes; bad arguments are refused before any run; the
command line writes its files; the study's quick report states its choices.

The platform of the small-signal checks is ``tests/engine/hexapod/test_dynamics.py``'s: the cube of
edge 0.3 m, 22.17 kg, ``Kp`` 2000 N/m, ``Ki`` 800 N/(m*s), ``Kd`` 20 N*s/m (a stable loop).
Chirps are 100 s or shorter at dt = 1 ms: each run takes well under a second.
"""
import json
import time

import numpy as np
import pytest

from qzs import ControllerParameters, IsolatorParameters, ParameterError, StabilityError
from qzs.analysis.spectral import transmissibility
from qzs.cli import main
from qzs.model.excitation import Chirp
from qzs.model.hexapod import PlatformParameters, cubic_geometry
from qzs.workflows.hexapod.setups import hexapod_setup, load_hexapod
from qzs.defaults import AXES
from qzs.workflows.hexapod.transmissibility import (HexapodTransmissibility,
                                                    hexapod_transmissibility)

FRICTIONLESS = IsolatorParameters(stiction_force=0.0, coulomb_force=0.0)
#: Coulomb friction only (Fs = Fc): stick-slip without the Stribeck branch, which keeps a
#: symmetric platform symmetric to rounding (docs/hexapod.md §9.8).
COULOMB = IsolatorParameters(stiction_force=5.0, coulomb_force=5.0)
LOOP = ControllerParameters(pi_kp=2000.0, pi_ki=800.0, damping_gain=20.0)
AMPLITUDE = 1e-4  # [m]: 1/3000 of the 0.3 m legs, so the geometric nonlinearity is ~3e-4


def setup_with(isolator, center_of_mass=(0.0, 0.0, 0.0)):
    geometry = cubic_geometry(cube_edge=0.3, cube_center_height=0.3)
    platform = PlatformParameters(mass=22.17, inertia=np.diag([0.3, 0.3, 0.5]),
                                  center_of_mass=center_of_mass)
    return hexapod_setup(geometry=geometry, platform=platform, isolator=isolator,
                         controller=LOOP, kind="cubic")


@pytest.fixture(scope="module")
def raised():
    """Frictionless legs, the payload 8 cm above the cube's centre: the matrix is taken at
    the cube's centre (the top frame origin), off the centre of mass, so x and ry couple
    through the inertia as well as through the preload."""
    setup = setup_with(FRICTIONLESS, center_of_mass=(0.0, 0.0, 0.08))
    result = hexapod_transmissibility(setup, axes=("z", "x"), amplitude=AMPLITUDE,
                                      duration=100.0, dt=1e-3, workers=2, progress=False)
    return setup, result


def linear_reference(setup, result, axis):
    """The linear model driven by the run's own base velocity, through the same estimator.

    ``transmissibility_system`` maps the base's displacement to the platform's at the top
    frame origin; being linear and starting at rest, it maps the base velocity to the
    platform's velocity. Its Welch estimate carries the estimator's own bias (a 0.2 Hz/s
    sweep is not slow against the 1.4-3.8 Hz modes), so what is left between it and the
    simulation's estimate is the simulation.
    """
    import control

    from qzs.analysis.hexapod_linear import hexapod_linearize
    from qzs.engine.hexapod import simulate_hexapod

    j = AXES.index(axis)
    run = simulate_hexapod(setup.geometry, setup.platform, setup.isolator, setup.controller,
                           excitation={axis: Chirp(amplitude=AMPLITUDE, duration=100.0)},
                           dt=1e-3)
    model = hexapod_linearize(setup.geometry, setup.platform, setup.isolator,
                              setup.controller, frame="origin")
    inputs = np.zeros((6, run["time"].size))
    inputs[j] = run["base_velocity"][:, j]
    outputs = control.forced_response(model.transmissibility_system, T=run["time"],
                                      U=inputs).outputs
    n = result.frequency.size
    columns = []
    for i in range(6):
        estimate = transmissibility(inputs[j], outputs[i], result.settings["sample_rate"],
                                    fft_length=result.settings["fft_length"], estimator="h1")
        columns.append((estimate.magnitude * np.exp(1j * estimate.phase))[:n])
    return np.array(columns).T


@pytest.mark.parametrize("axis, entries", [("z", [("z", "z")]),
                                           ("x", [("x", "x"), ("ry", "x")])])
def test_frictionless_chirps_reproduce_the_linear_matrix(raised, axis, entries):
    """Diagonal and coupling entries equal the linear model's on every trusted bin.

    Against the linear model run through the same chirp and estimator: within 1e-3 of the
    base motion (dimensionless, rotations times the platform's size), three times the
    geometric nonlinearity amplitude/leg length, and within 0.05 dB (measured: 1.4e-4 and
    0.012 dB). Against the exact linear transmissibility, the diagonal within 0.5 dB: the
    estimator's sweep bias, 0.41 dB at most on the linear model itself.
    """
    setup, result = raised
    reference = linear_reference(setup, result, axis)
    size = result.settings["platform_size"]
    for output, base in entries:
        i, j = AXES.index(output), AXES.index(base)
        trusted = result.trusted[:, i, j]
        assert trusted.sum() > 200  # most of the 0.8-20 Hz band
        scale = (size if i >= 3 else 1.0) / (size if j >= 3 else 1.0)
        simulated = result.response[trusted, i, j]
        difference = np.abs(simulated - reference[trusted, i]) * scale
        assert np.max(difference) < 1e-3
        ratio = np.abs(simulated) / np.abs(reference[trusted, i])
        assert np.max(np.abs(20 * np.log10(ratio))) < 0.05
        exact = result.linear_response[trusted, i, j]
        if i == j:
            assert np.max(np.abs(20 * np.log10(np.abs(simulated) / np.abs(exact)))) < 0.5
        assert np.max(np.abs(exact) * scale) > 0.3  # a real entry, not a zero one


def test_the_coupling_is_real_and_grows_off_the_centre(raised):
    """x -> ry at the cube's centre: the payload 8 cm above it couples them (the simulated
    peak exceeds what the preload alone gives a payload at the centre)."""
    _, result = raised
    centred = hexapod_transmissibility(setup_with(FRICTIONLESS), axes="x",
                                       amplitude=AMPLITUDE, duration=60.0, dt=1e-3,
                                       workers=1, progress=False)
    i, j = AXES.index("ry"), AXES.index("x")
    peak_raised = np.max(result.magnitude[result.trusted[:, i, j], i, j])
    peak_centred = np.max(centred.magnitude[centred.trusted[:, i, j], i, j])
    assert peak_raised > 1.5 * peak_centred > 0


@pytest.mark.parametrize("isolator", [FRICTIONLESS, COULOMB], ids=["frictionless", "coulomb"])
def test_entries_a_symmetric_platform_keeps_at_zero_are_untrusted(isolator):
    """Payload at the cube's centre, diagonal inertia: a z chirp moves z alone, an x chirp
    never moves y, rx, rz (the mirror in the xz plane). Those entries are rounding and come
    out untrusted in every bin, and every bin of them lies below the numerical floor, so
    they stay untrusted where rounding happens to be coherent with the base (a few bins
    per long run reach a coherence of 0.9 to 0.999: rounding is as deterministic as the
    chirp)."""
    result = hexapod_transmissibility(setup_with(isolator), axes=("z", "x"), amplitude=2e-4,
                                      duration=60.0, dt=1e-3, workers=2, progress=False)
    zero = [(i, AXES.index("z")) for i in range(6) if AXES[i] != "z"]
    zero += [(AXES.index(a), AXES.index("x")) for a in ("y", "rx", "rz")]
    size = result.settings["platform_size"]
    for i, j in zero:
        assert not result.trusted[:, i, j].any(), f"{AXES[i]}/{AXES[j]} has trusted bins"
        scale = (size if i >= 3 else 1.0) / (size if j >= 3 else 1.0)
        assert np.nanmax(result.magnitude[1:, i, j]) * scale < 1e-9  # rounding
        assert result.below_floor[1:, i, j].all()
    for axis in ("z", "x"):
        j = AXES.index(axis)
        assert result.trusted[:, j, j].sum() > 100
    assert result.trusted[:, AXES.index("ry"), AXES.index("x")].any()  # the preload's coupling
    if isolator is COULOMB:
        assert np.mean(result.runs["z"]["locked_fraction"]) > 0.01  # stick-slip did happen


def test_coherent_rounding_and_the_sweeps_start_are_untrusted():
    """The two rules beyond the single axis's, on a column built by hand: an entry at 1e-14
    of the base motion with coherence 1 is rounding, not response; bins the chirp crossed
    in the first quarter of the first segment carry a coherence of 1 by construction."""
    from qzs.workflows.hexapod.transmissibility import matrix, plan

    setup = setup_with(FRICTIONLESS)
    axes, amplitudes, common, _, _ = plan._plan(
        setup, ("z",), None, 0.0, 20.0, 60.0, 1e-3, None, None, None, "h1", -100.0, 1, False)
    n = common["fft_length"] // 2 + 1
    frequency = np.arange(n) * common["sample_rate"] / common["fft_length"]
    response = np.full((6, n), 1e-14 + 0j)
    response[2] = 0.5
    response[4] = 1e-3 / common["platform_size"]  # ry per z: 1e-3 of the base motion
    column = dict(axis="z", frequency=frequency, response=response,
                  coherence=np.ones((6, n)), trusted=np.ones((6, n), dtype=bool),
                  record=dict(energy_residual=0.0, base_work_max=1.0))
    result = matrix._assemble(setup, axes, amplitudes, common, {"z": column})
    start = common["trusted_from"]
    assert start == pytest.approx(20.0 / 60.0 * (common["fft_length"] / 1000.0) / 4)
    late = result.frequency >= start
    assert result.trusted[late, 2, 2].all() and not result.trusted[~late, 2, 2].any()
    assert result.trusted[late, 4, 2].all()  # small, but above the floor
    for i in (0, 1, 3, 5):
        assert not result.trusted[:, i, 2].any() and result.below_floor[:, i, 2].all()


def test_the_energy_ledger_closes_in_every_run(raised):
    """Each run's ledger imbalance over its largest |base work|, as the engine books it
    (docs/hexapod.md §9.6): truncation error of ode3 at dt = 1 ms."""
    _, result = raised
    for axis in result.excited_axes:
        run = result.runs[axis]
        assert run["base_work_max"] > 0
        assert result.energy_residual[axis] == pytest.approx(
            run["energy_residual"] / run["base_work_max"])
        assert result.energy_residual[axis] < 1e-5
        assert run["dt"] == 1e-3 and run["step"] == "given"


def test_the_result_repackages_and_delegates(raised, tmp_path):
    _, result = raised
    assert isinstance(result, HexapodTransmissibility)
    dataset = result.to_xarray()
    assert dataset["magnitude"].dims == ("frequency", "output_dof", "input_dof")
    assert dataset["frequency"].attrs["units"] == "Hz"
    assert str(dataset["entry_units"].sel(output_dof="ry", input_dof="x").item()) == "rad/m"
    assert list(dataset["excited"].values) == [1, 0, 1, 0, 0, 0]
    np.testing.assert_array_equal(dataset["trusted"].values.astype(bool), result.trusted)
    assert np.all(np.isnan(result.magnitude[:, :, 1]))  # y was not excited
    path = result.save(tmp_path / "matrix.nc")
    import xarray as xr

    from qzs.iotools.cf_layout import from_file_layout

    with xr.open_dataset(path, engine="h5netcdf") as raw:
        assert raw["settings"].attrs["floor_db_units"] == "dB"  # a container (CF)
        assert raw["magnitude_translation_per_rotation"].attrs["units"] == "m/rad"  # one unit
        back = from_file_layout(raw)  # the blocks joined again (decision 34)
        np.testing.assert_allclose(back["magnitude"].values, result.magnitude)
    with pytest.raises(ParameterError, match=r"\.xlsx.*\.nc"):  # named, before any work
        result.save(tmp_path / "matrix.xlsx")
    assert not (tmp_path / "matrix.xlsx").exists()
    text = result.summary()
    assert "untrusted everywhere" in text and "ledger" in text


@pytest.mark.parametrize("change, match", [
    (dict(axes=("w",)), "`axes`"), (dict(axes=()), "`axes`"),
    (dict(axes=("z", "z")), "more than once"),
    (dict(amplitude=-1e-3), "amplitude"),
    (dict(axes=("z", "rx"), amplitude=1e-3), "mix translations"),
    (dict(axes=("z",), amplitude={"x": 1e-3}), "not among the excited"),
    (dict(f0=5.0, f1=2.0), "`f0` < `f1`"), (dict(f1=600.0), "Nyquist"),
    (dict(duration=0.0), "`duration`"), (dict(dt=-1e-3), "`dt`"),
    (dict(dt=3e-4), "sample_rate"), (dict(fft_length=10 ** 7), "`fft_length`"),
    (dict(estimator="psd_ratio"), "`estimator`"), (dict(floor_db=5.0), "`floor_db`"),
    (dict(workers=0), "`workers`"), (dict(progress="yes"), "`progress`"),
    (dict(setup="paper_legs_cubic"), "`setup` must be a HexapodSetup"),
    (dict(dt=0.1, sample_rate=10.0, f1=4.0), "too large for a stable"),
    (dict(dt=1e-3, tolerance=0.01), "`dt`.*`tolerance`.*not both"),
    (dict(tolerance=-0.01), "`tolerance`.*-0.01"),
    (dict(tolerance=0.01, tolerance_db=0.01), "give `tolerance` only"),
])
def test_bad_arguments_raise_before_any_run(monkeypatch, change, match):
    import qzs.engine.hexapod

    def no_run(*args, **kwargs):
        raise AssertionError("a simulation started before the arguments were checked")

    monkeypatch.setattr(qzs.engine.hexapod, "simulate_hexapod", no_run)
    arguments = dict(setup=load_hexapod("paper_legs_cubic"), axes=("z",), duration=10.0,
                     progress=False)
    arguments.update(change)
    error = StabilityError if "stable" in match else ParameterError
    start = time.perf_counter()
    with pytest.raises(error, match=match):
        hexapod_transmissibility(arguments.pop("setup"), **arguments)
    assert time.perf_counter() - start < 1.0


def test_tolerance_db_is_the_deprecated_name_of_tolerance():
    with pytest.warns(DeprecationWarning, match="use `tolerance`"), \
            pytest.raises(ParameterError, match="`dt`.*`tolerance`.*not both"):
        hexapod_transmissibility(load_hexapod("paper_legs_cubic"), axes=("z",), dt=1e-3,
                                 tolerance_db=0.01, progress=False)


def test_the_command_writes_the_grid_and_the_matrix(tmp_path, capsys):
    out = tmp_path / "matrix"
    code = main(["hexapod", "transmissibility", "--axes", "z", "--amplitude", "z=0.001",
                 "--duration", "30", "--dt", "1e-3", "--workers", "1", "--out", str(out),
                 "--json"])
    assert code == 0
    record = json.loads(capsys.readouterr().out)
    assert record["excited_axes"] == ["z"] and record["amplitude"] == {"z": 0.001}
    assert record["runs"]["z"]["dt"] == 1e-3
    assert record["steps"]["z"]["step"] == "given"  # --dt is literal: no probe, no estimate
    assert record["steps"]["z"]["error_db"] is None and record["settings"]["tolerance_db"] is None
    assert record["trusted_bins"]["z/z"] > 0 and record["trusted_bins"]["x/z"] == 0
    assert (out / "transmissibility.png").stat().st_size > 10_000
    assert (out / "transmissibility.nc").stat().st_size > 0
    assert record["source"].endswith("paper_legs_cubic.toml")
    assert main(["hexapod", "transmissibility", "--dt", "1e-3", "--tolerance", "0.01",
                 "--out", str(out)]) == 2  # a literal step or a tolerance, not both
    assert main(["hexapod", "transmissibility", "--axes", "z,q", "--out", str(out),
                 "--overwrite"]) == 2
    assert "`axes`" in capsys.readouterr().err
    assert main(["hexapod", "transmissibility", "--amplitude", "z=big", "--out",
                 str(out)]) == 2


@pytest.fixture(scope="module")
def quick_study(tmp_path_factory):
    out = tmp_path_factory.mktemp("study")
    import contextlib
    import io

    buffer = io.StringIO()
    with contextlib.redirect_stdout(buffer):
        code = main(["hexapod", "study", "--quick", "--out", str(out), "--json"])
    assert code == 0
    return out, json.loads(buffer.getvalue())


def test_the_quick_study_writes_its_report_and_states_its_choices(quick_study):
    out, record = quick_study
    report = (out / "report.md").read_text(encoding="utf-8")
    for text in ("What \"without PI\" means here", "P only", "no position loop",
                 "statically unstable", "tolerance 0.01 dB", "ledger closure",
                 "## Findings", "trusted"):
        assert text in report, text
    figures = [line.split("(")[1].rstrip(")") for line in report.splitlines()
               if line.startswith("![")]
    assert len(figures) == 4
    for name in figures:
        assert (out / name).stat().st_size > 10_000
    assert len(record["rows"]) == 6
    assert {row["case"] for row in record["rows"]} == {"PI", "P only", "no position loop"}
    csv_lines = (out / "metrics.csv").read_text().splitlines()
    assert len(csv_lines) == 7 and "T_at_8_hz" in csv_lines[0]
    rows = {(row["case"], row["axis"]): row for row in record["rows"]}
    assert rows[("PI", "z")]["stop_contacts"] == 0
    assert rows[("PI", "z")]["linear_stable"] and not rows[("no position loop", "z")][
        "linear_stable"]
    assert all(row["ledger_closure"] < 1e-2 for row in record["rows"])
    # every run's step: chosen for the default tolerance, with its estimated error, or the
    # file's where none coarser met it (the z runs' stick-slip pattern), saying why
    for case, steps in record["steps"].items():
        for axis, step in steps.items():
            assert step["tolerance_db"] == 0.01, (case, axis)
            if step["step"] == "accuracy-driven":
                assert 0 <= step["error_db"] <= 0.01 / 2 and step["dt"] > 1e-4
                assert f"dt = {step['dt']:g} s, accuracy-driven" in report
            else:
                assert step["step"] == "fallback" and step["dt"] == 1e-4
                assert step["error_db"] is None and "redraw the response" in report  # NaN is null
    assert record["steps"]["PI"]["x"]["step"] == "accuracy-driven"
