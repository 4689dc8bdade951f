"""A run's metadata (qzs.engine.metadata): every parameter with the registry's unit, every run
entry with a unit, None kept and listed, the history line naming the run and its end."""
import pytest

import qzs
from qzs import Chirp, ControllerParameters, IsolatorParameters
from qzs.engine.metadata import (RUN_UNITS, file_attributes, history_line, parameter_metadata,
                                 run_metadata)
from qzs.model.controller import BLOCKS
from qzs.model.registry import BLOCK_PARAMETERS, parameter_fields, unit_of

RUN = {"solver": "ode3", "dt": 1e-4, "sample_rate": 500.0, "steps": 100, "elapsed": 0.5,
       "completed": True, "stop_contacts": 0, "stick_events": 2, "stop_low": -0.14,
       "stop_high": 0.02, "samples": 6, "preview_every": 1}


@pytest.fixture(scope="module")
def parameters():
    return IsolatorParameters(), ControllerParameters(), Chirp(duration=2.0)


def test_every_parameter_has_the_registry_unit(parameters):
    isolator, controller, excitation = parameters
    meta = parameter_metadata(isolator, controller, excitation)
    for section, params in (("isolator", isolator), ("controller", controller)):
        for field in parameter_fields(params):  # the blocks: next test
            value, unit = meta[f"{section}.{field.name}"]
            assert unit == unit_of(field.name), field.name
            expected = getattr(params, field.name)
            assert value == (int(expected) if isinstance(expected, bool) else expected)
    assert not [key for key in meta  # no blocks here: none of their parameters recorded
                if key.startswith(tuple(f"controller.{block}." for block in BLOCKS))]
    assert meta["excitation"] == ("Chirp", "")
    assert meta["excitation.duration"] == (2.0, "s")


def test_every_block_parameter_has_the_registry_unit(parameters):
    isolator, _, excitation = parameters
    controller = (qzs.PIDamping() + qzs.FrictionCompensation(fraction=0.5)
                  + qzs.Dither(amplitude=2.0) + qzs.LinearController(a=[[-1.0]], b=[[1.0]],
                                                                       c=[1.0], d=[0.0]))
    meta = parameter_metadata(isolator, controller, excitation)
    assert BLOCK_PARAMETERS  # compensation, dither and linear scalars
    for name in BLOCK_PARAMETERS:
        block, field = name.split(".")
        value, unit = meta[f"controller.{name}"]
        assert unit == unit_of(name) and unit, name
        assert value == getattr(getattr(controller, block), field), name


def test_every_run_entry_has_its_unit_and_booleans_become_ints():
    meta = run_metadata(RUN)
    assert set(meta) == {f"run.{key}" for key in RUN}
    for key in RUN:
        assert meta[f"run.{key}"][1] == RUN_UNITS[key]
    assert meta["run.completed"] == (1, "1") and type(meta["run.completed"][0]) is int


def test_file_attributes_split_before_and_after_the_run(parameters):
    head, tail = file_attributes(*parameters, None)
    assert tail == {} and head["Conventions"].startswith("CF-")
    assert head["qzs_version"] == qzs.__version__
    assert head["isolator.stop_center"] == "none"  # None kept, and listed
    assert "isolator.stop_center" in head["none_parameters"].split()
    head2, tail = file_attributes(*parameters, RUN, history="made by hand")
    assert head2 == head and tail["history"] == "made by hand"
    assert tail["run.solver"] == "ode3" and tail["run.dt_units"] == "s"


def test_history_line_names_the_run_and_an_interruption(parameters):
    excitation = parameters[2]
    line = history_line(excitation, RUN)
    assert f"qzs {qzs.__version__}" in line and "Chirp base excitation" in line
    assert "solver ode3" in line and "100 steps" in line and "interrupted" not in line
    assert history_line(excitation, {**RUN, "completed": False}).endswith(", interrupted")
