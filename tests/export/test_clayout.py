"""The C model's copies of the numba side (its packed indices, its parameter checks) are
asserted against Python at export: a parameter or an index added or moved in Python alone
stops the export, naming the difference and both values; the shipped sources pass."""
import dataclasses
from types import MappingProxyType

import pytest

from qzs.cli import main
from qzs.engine import kernels as K
from qzs.errors import CModelMismatchError
from qzs.export import clayout
from qzs.export.controller import export_controller
from qzs.export.csource import source_text
from qzs.export.fmu import export_fmu
from qzs.model import registry


def test_the_shipped_c_model_is_the_python_side():
    clayout.check_c_model()
    c = clayout.c_constants()
    # values the headers give by expression (QZS_M_B = QZS_M_A + QZS_NX_MAX * QZS_NX_MAX,
    # a macro naming another), worked out as the kernels' own arithmetic does
    assert c["QZS_M_B"] == K.M_A + K.NX_MAX * K.NX_MAX == K.M_B
    assert c["QZS_N_MODEL"] == K.N_MODEL and c["QZS_N_BASE_CHANNELS"] == K.C_F_COMPENSATION
    assert c["QZS_N_PARAMS"] == K.N_PARAMS and c["QZS_A_F_LINEAR"] == K.A_F_LINEAR
    # every packed parameter's index is compared, not only a few
    assert {f"QZS_{n}" for n in vars(K) if n.startswith("P_")} <= set(clayout.python_constants())


def test_a_moved_index_names_it_and_both_values(monkeypatch):
    monkeypatch.setattr(K, "P_VREG", 22)
    with pytest.raises(CModelMismatchError) as caught:
        clayout.check_c_model()
    assert caught.value.mismatches == (("QZS_P_VREG", 21, "kernels.P_VREG = 22"),)
    assert "QZS_P_VREG: C 21, Python kernels.P_VREG = 22" in str(caught.value)


def test_a_packed_parameter_added_in_python_alone_is_refused(monkeypatch):
    monkeypatch.setattr(K, "P_STOP_FRICTION", K.N_PARAMS, raising=False)
    monkeypatch.setattr(K, "N_PARAMS", K.N_PARAMS + 1)
    with pytest.raises(CModelMismatchError) as caught:
        clayout.check_c_model()
    assert set(caught.value.mismatches) == {
        ("QZS_N_PARAMS", 22, "kernels.N_PARAMS = 23"),
        ("QZS_P_STOP_FRICTION", None, "kernels.P_STOP_FRICTION = 22")}


def test_an_index_left_in_c_alone_is_refused(monkeypatch):
    plant = source_text("qzs_plant.h").replace("QZS_P_VREG, QZS_N_PARAMS",
                                               "QZS_P_VREG, QZS_P_OLD, QZS_N_PARAMS")
    texts = [plant if name == "qzs_plant.h" else source_text(name)
             for name in clayout.C_HEADERS]
    mismatches = clayout._index_mismatches(clayout.c_constants(texts),
                                           clayout.python_constants())
    assert ("QZS_P_OLD", 22, None) in mismatches
    assert ("QZS_N_PARAMS", 23, "kernels.N_PARAMS = 22") in mismatches


def _with_parameter(monkeypatch):
    """The registry with an isolator parameter the C model does not know."""
    extra = dataclasses.replace(registry.PARAMETERS["stop_damping"], name="stop_friction")
    monkeypatch.setattr(registry, "PARAMETERS",
                        MappingProxyType({**registry.PARAMETERS, "stop_friction": extra}))


def test_a_registry_parameter_the_fmu_does_not_read_is_refused(monkeypatch):
    _with_parameter(monkeypatch)
    with pytest.raises(CModelMismatchError) as caught:
        clayout.check_c_model()
    assert caught.value.mismatches == (
        ("isolator.stop_friction", "not read by qzs_fmu.c", "a registry parameter"),)


@pytest.mark.parametrize("c_check, python", [
    ('REQUIRE(ISOLATOR_MASS, V(ISOLATOR_MASS) >= 0.0, "non-negative [kg]");',
     ("isolator.mass", "REQUIRE >= 0", "checked > 0")),
    ("", ("isolator.mass", "REQUIRE any real", "checked > 0")),
])
def test_a_check_not_the_parameter_classes_is_refused(c_check, python):
    fmu = source_text("qzs_fmu.c")
    shipped = 'REQUIRE(ISOLATOR_MASS, V(ISOLATOR_MASS) > 0.0, "positive [kg]");'
    assert shipped in fmu
    assert clayout._check_mismatches(fmu.replace(shipped, c_check)) == [python]


def test_the_exports_refuse_before_writing_anything(monkeypatch, tmp_path, capsys):
    monkeypatch.setattr(K, "P_VREG", 22)
    with pytest.raises(CModelMismatchError, match="QZS_P_VREG"):
        export_fmu(tmp_path / "isolator.fmu")
    with pytest.raises(CModelMismatchError, match="QZS_P_VREG"):
        export_controller(tmp_path / "controller.c")
    assert main(["export", "fmu", "--out", str(tmp_path / "cli.fmu")]) == 1
    assert "QZS_P_VREG: C 21, Python kernels.P_VREG = 22" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("family", ["P", "S", "A", "I", "E", "C", "M"])
def test_an_index_of_any_packed_family_left_in_c_alone_is_refused(family):
    """Parameters, state, auxiliaries, flags, excitation, channels, controller blocks: a C
    index of any packed array with no Python twin is a difference."""
    plant = source_text("qzs_plant.h") + f"\n#define QZS_{family}_OLD 99\n"
    texts = [plant if name == "qzs_plant.h" else source_text(name)
             for name in clayout.C_HEADERS]
    mismatches = clayout._index_mismatches(clayout.c_constants(texts),
                                           clayout.python_constants())
    assert mismatches == [(f"QZS_{family}_OLD", 99, None)]


def _bound_checks():
    """Every ``REQUIRE(X, V(X) > 0.0`` or ``>= 0.0`` of a registry parameter in the shipped
    qzs_fmu.c."""
    import re

    macros = {f"{info.section}_{name}".upper() for name, info in registry.PARAMETERS.items()}
    found = re.findall(r"REQUIRE\((\w+), V\(\1\) (>=?) 0\.0\b", source_text("qzs_fmu.c"))
    return [(macro, bound) for macro, bound in found if macro in macros]


@pytest.mark.parametrize("macro, bound", _bound_checks())
def test_every_bound_the_fmu_checks_is_compared_with_the_parameter_classes(macro, bound):
    """Whatever the parameter's unit (kg, N, N/m, Hz, ...), turning its C bound from > 0 to
    >= 0 (or back) is the one difference found, naming the parameter and both bounds."""
    fmu = source_text("qzs_fmu.c")
    shipped = f"REQUIRE({macro}, V({macro}) {bound} 0.0"
    other = ">=" if bound == ">" else ">"
    shown = {">": "> 0", ">=": ">= 0"}
    flipped = fmu.replace(shipped, f"REQUIRE({macro}, V({macro}) {other} 0.0", 1)
    label = macro.lower().replace("_", ".", 1)
    assert clayout._check_mismatches(flipped) == [
        (label, f"REQUIRE {shown[other]}", f"checked {shown[bound]}")]
