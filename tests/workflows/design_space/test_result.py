"""The search's result (qzs.workflows.design_space.result): the chosen design, the files a
user takes elsewhere (NetCDF, CSV with units, MATLAB), the run configuration and the report."""
import copy

import numpy as np
import pytest

from qzs.errors import ParameterError
from qzs.workflows.design_space.optimizer import optimize
from qzs.workflows.design_space.result import OUTPUT_FILES, write_files

from helpers import LINEAR_PROBLEM

pytest.importorskip("pymoo")

# a stiffer position loop hunts less but isolates less at 1 Hz: a real trade-off
LINEAR = {**LINEAR_PROBLEM, "optimizer": {"population": 8, "generations": 3, "seed": 4}}


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    return optimize(LINEAR, tmp_path_factory.mktemp("r") / "linear.zarr", progress=False)


def test_the_chosen_design_is_the_pareto_member_nearest_the_ideal_point(result):
    F = result.goal_values[result.pareto, :2]
    scaled = (F - F.min(axis=0)) / (F.max(axis=0) - F.min(axis=0))
    distance = np.hypot(*scaled.T)
    assert result.chosen == result.pareto[np.argmin(distance)]
    assert set(result.design()) == {"damping_gain", "pi_kp"}


def test_the_pareto_set_files_carry_units_and_read_back_equal(result, tmp_path):
    import scipy.io
    import xarray as xr


    result.save(tmp_path / "p.nc")
    data = xr.open_dataset(tmp_path / "p.nc", engine="h5netcdf").load()
    assert data.sizes["design"] == result.pareto.size
    assert data["pi_kp"].attrs["units"] == "N/m"
    assert data["damping_gain"].attrs["units"] == "N*s/m"
    assert np.array_equal(data["pi_kp"].values, result.designs[result.pareto, 1])
    assert data["linear_transmissibility_at_5_hz"].attrs["bound"] == 0.9
    assert data["pareto"].values.all() and data["chosen"].values.sum() == 1
    result.save(tmp_path / "p.mat")
    mat = scipy.io.loadmat(tmp_path / "p.mat", squeeze_me=True)
    assert np.array_equal(mat["pi_kp"], result.designs[result.pareto, 1])
    result.save(tmp_path / "p.csv")
    lines = (tmp_path / "p.csv").read_text().splitlines()
    body = [line for line in lines if not line.startswith("#")]
    names, units = body[0].split(","), body[1].split(",")
    assert units[names.index("pi_kp")] == "N/m"
    rows = np.array([line.split(",") for line in body[2:]])
    assert np.allclose(rows[:, names.index("pi_kp")].astype(float),
                       result.designs[result.pareto, 1], rtol=1e-9)
    every = result.to_xarray()
    assert every.sizes["design"] == len(result.designs)
    assert int(every["pareto"].sum()) == result.pareto.size


def test_the_chosen_design_is_a_run_configuration_qzs_simulate_reads(result, tmp_path):
    from qzs.iotools.config import load_config

    path = result.write_config(tmp_path / "chosen.toml")
    config = load_config(path)
    design = result.design()
    assert config["controller"].damping_gain == design["damping_gain"]
    assert config["controller"].pi_kp == design["pi_kp"]
    assert config["excitation"]["kind"] == "chirp"
    other = result.pareto[0] if result.pareto[0] != result.chosen else result.pareto[1]
    assert load_config(result.write_config(tmp_path / "other.toml", other))[
        "controller"].pi_kp == result.designs[other, 1]
    with pytest.raises(ParameterError, match="`index` must be a design index"):
        result.config_text(10 ** 6)


def test_no_feasible_design_chooses_nothing_and_says_so(tmp_path):
    document = copy.deepcopy(LINEAR)
    document["constraints"] = [{"metric": "linear_transmissibility_at", "frequency": 5.0,
                                "max": 1e-6}]
    result = optimize(document, tmp_path / "none.zarr", generations=1, progress=False)
    assert result.pareto.size == 0 and result.chosen is None
    with pytest.raises(ParameterError, match="no design meets every constraint"):
        result.config_text()
    assert "No design meets every constraint" in result.report()
    written = write_files(result, tmp_path / "out")
    assert not (tmp_path / "out" / "chosen.toml").exists()
    assert len(written) == len(OUTPUT_FILES) - 1


def test_the_report_and_files_name_every_goal_with_its_unit(result, tmp_path):
    report = result.report()
    assert "| pi_kp | 1 | 1000 | log | N/m |" in report
    assert "linear_transmissibility_at_5_hz <= 0.9" in report
    assert "(chosen)" in report
    written = write_files(result, tmp_path / "out")
    assert sorted(p.name for p in written) == sorted(OUTPUT_FILES)
    assert not [p for p in (tmp_path / "out").iterdir() if p.name.startswith(".")]
    summary = result.summary()
    assert f"Pareto set {result.pareto.size}" in summary


def test_the_report_states_the_chosen_design_with_units(result):
    line = result.report().split("## Chosen design")[1]
    design = result.design()
    assert f"Design {result.chosen}," in line
    assert f"pi_kp = {design['pi_kp']:.4g} N/m" in line
    assert "hunting_amplitude = " in line and " m" in line


def test_writing_the_files_advances_a_progress_bar_file_by_file(result, tmp_path, monkeypatch):
    """Never silent while the figure and files are written: a step after each file is there."""
    from qzs.engine import progress

    folder, steps, bars = tmp_path / "out", [], []

    class Recorder:
        def __init__(self, total, disable):
            self.total, self.disable = total, disable

        def update(self, n):
            steps.append((n, {p.name for p in folder.iterdir()}))

        def __enter__(self):
            return self

        def __exit__(self, *_):
            return False

    def bar(*, total, disable, **_):
        bars.append(Recorder(total, disable))
        return bars[-1]

    monkeypatch.setattr(progress, "progress_bar", bar)
    written = write_files(result, folder, progress=True)
    (recorder,) = bars
    assert not recorder.disable and [n for n, _ in steps] == [1] * recorder.total
    # each step once its file is there; the figure, drawn meanwhile (into a hidden
    # temporary file first), may come sooner
    def others(names):
        return {name for name in names if "pareto.png" not in name}

    for k, (_, files) in enumerate(steps, start=1):
        assert others(files) == others(p.name for p in written[:k])
    assert written[-1].name == "pareto.png" and "pareto.png" in steps[-1][1]


def record_process(result, path):
    """Stand-in for the figure task: writes the id of the process it runs in."""
    import os
    from pathlib import Path

    Path(path).write_text(str(os.getpid()))
    return Path(path)


def test_the_figure_is_drawn_beside_the_files_and_equals_one_drawn_here(result, tmp_path,
                                                                        monkeypatch):
    import os

    from qzs.workflows import forked
    from qzs.workflows.design_space import result as result_module

    here = result_module.draw_figure(result, tmp_path / "here.png")
    write_files(result, tmp_path / "out")
    assert (tmp_path / "out" / "pareto.png").read_bytes() == here.read_bytes()
    monkeypatch.setattr(result_module, "draw_figure", record_process)
    write_files(result, tmp_path / "where")
    drawn_by = int((tmp_path / "where" / "pareto.png").read_text())
    assert (drawn_by != os.getpid()) == forked.available()


def fail_to_draw(result, path):
    """Stand-in for the figure task that fails."""
    raise ParameterError("the figure could not be drawn")


def test_a_figure_that_fails_fails_the_writing(result, tmp_path, monkeypatch):
    from qzs.workflows.design_space import result as result_module

    monkeypatch.setattr(result_module, "draw_figure", fail_to_draw)
    with pytest.raises(ParameterError, match="could not be drawn"):
        write_files(result, tmp_path / "out")


def test_a_writer_started_before_the_search_writes_the_files_write_files_writes(result,
                                                                              tmp_path):
    import multiprocessing

    import xarray as xr

    from qzs.workflows.design_space.result import file_writer

    here = write_files(result, tmp_path / "here")
    with file_writer(tmp_path / "there") as writer:
        there = writer.write(result)
    assert [p.name for p in there] == [p.name for p in here]
    for name in ("pareto.nc", "designs.nc"):
        with xr.open_dataset(tmp_path / "here" / name) as a, \
                xr.open_dataset(tmp_path / "there" / name) as b:
            assert a.equals(b)  # values, coordinates; and every attribute but the time
            assert {**a.attrs, "history": ""} == {**b.attrs, "history": ""}
    for name in ("pareto.png", "pareto.csv", "chosen.toml", "report.md"):
        assert (tmp_path / "here" / name).read_bytes() == (tmp_path / "there" / name).read_bytes()
    assert not multiprocessing.active_children()  # the writer is gone


def test_a_writer_says_why_it_could_not_write_and_leaves_when_told_nothing(result, tmp_path):
    import multiprocessing

    from qzs.workflows.design_space.result import file_writer

    blocked = tmp_path / "file"
    blocked.write_text("not a folder")
    with pytest.raises(OSError), file_writer(blocked) as writer:
        writer.write(result)
    with file_writer(tmp_path / "never") as writer:  # the search stopped: no result
        pass
    assert not (tmp_path / "never").exists() and not multiprocessing.active_children()


def test_a_figure_process_that_dies_leaves_the_figure_to_this_one(result, tmp_path,
                                                                  monkeypatch):
    """The figure's helper killed before it draws: this process draws it, the same bytes."""
    import os
    import signal

    from qzs.workflows import forked

    if not forked.available():
        pytest.skip("needs fork and two cores")
    write_files(result, tmp_path / "here")
    real_send = forked.Forked.send
    killed = []

    def kill_then_send(self, item):
        os.kill(self.pid, signal.SIGKILL)
        self._process.join()
        killed.append(self._process.exitcode)
        real_send(self, item)

    monkeypatch.setattr(forked.Forked, "send", kill_then_send)
    written = write_files(result, tmp_path / "there")
    assert killed == [-signal.SIGKILL]
    assert written[-1] == tmp_path / "there" / "pareto.png"
    assert (tmp_path / "there" / "pareto.png").read_bytes() == \
        (tmp_path / "here" / "pareto.png").read_bytes()


def test_a_writer_that_died_leaves_the_files_to_this_process(result, tmp_path):
    import os
    import signal

    from qzs.workflows import forked
    from qzs.workflows.design_space.result import file_writer

    if not forked.available():
        pytest.skip("needs fork and two cores")
    here = write_files(result, tmp_path / "here")
    with file_writer(tmp_path / "there") as writer:
        os.kill(writer.helper.pid, signal.SIGKILL)
        there = writer.write(result)
    assert [p.name for p in there] == [p.name for p in here]
    for name in ("pareto.png", "pareto.csv", "report.md"):
        assert (tmp_path / "here" / name).read_bytes() == (tmp_path / "there" / name).read_bytes()
