"""The [spring] table of a config or spring file (docs/model.md §3.1): one reader, clear errors."""
import numpy as np
import pytest

from qzs.errors import DataError, ParameterError
from qzs.iotools.config import config_text, load_config, load_spring, spring_text
from qzs.model.isolator import IsolatorParameters
from qzs.model.springs import ObliqueSpringQZS, PolynomialSpring, TabulatedSpring, TanhSpring


def _write(path, text):
    path.write_text(text, encoding="utf-8")
    return path


def test_a_config_spring_table_sets_the_isolators_law(tmp_path):
    path = _write(tmp_path / "run.toml", '[isolator]\nmass = 6.4\n[spring]\nlaw = "oblique"\n'
                  'vertical_stiffness = "quasi-zero"\noblique_stiffness = 300.0\n')
    law = load_config(path)["isolator"].spring
    assert law == ObliqueSpringQZS.quasi_zero(oblique_stiffness=300.0)
    assert float(law.stiffness(law.center)) == pytest.approx(0.0, abs=1e-9)


def test_a_spring_file_reads_a_table_from_csv_relative_to_it_with_its_units(tmp_path):
    z_mm = np.linspace(-150.0, 30.0, 19)
    forces = TanhSpring().force(z_mm * 1e-3)
    (tmp_path / "curves").mkdir()
    (tmp_path / "curves" / "rig.csv").write_text(
        "position [mm],force [N]\n"
        + "".join(f"{float(z)!r},{float(f)!r}\n" for z, f in zip(z_mm, forces)))
    path = _write(tmp_path / "spring.toml",
                  '[spring]\nlaw = "table"\ncsv = "curves/rig.csv"\noutside = "extend"\n')
    law = load_spring(path)
    assert isinstance(law, TabulatedSpring) and law.outside == "extend"
    np.testing.assert_allclose(law.positions, z_mm * 1e-3, rtol=1e-15)
    np.testing.assert_array_equal(law.forces, forces)


LAWS = [TanhSpring(plateau=55.0, shape=70.0), ObliqueSpringQZS(),
        PolynomialSpring(coefficients=(62.78, -300.0, 0.0, -2e5), center=-0.06),
        TabulatedSpring.from_law(ObliqueSpringQZS(), np.linspace(-0.15, 0.03, 7))]


@pytest.mark.parametrize("law", LAWS)
def test_spring_text_is_a_spring_file_of_the_law(tmp_path, law):
    path = _write(tmp_path / "spring.toml", spring_text(law, note="from a fit"))
    assert path.read_text().splitlines()[1] == "# from a fit"
    assert load_spring(path) == law
    with pytest.raises(ParameterError, match="`law` must be a spring law"):
        spring_text(law.to_dict())


@pytest.mark.parametrize("law", LAWS)
def test_config_text_writes_the_law_as_its_spring_table_and_reads_it_back(tmp_path, law):
    path = _write(tmp_path / "run.toml", config_text(IsolatorParameters(spring=law)))
    assert "[spring]" in path.read_text()
    assert load_config(path)["isolator"].spring == law


@pytest.mark.parametrize("text, match", [
    ('[spring]\nplateau = 60.0\n', r"\[spring\] has no `law`; write law = one of 'tanh'"),
    ('[spring]\nlaw = "cubic"\n', r"law = 'cubic'; write law = one of"),
    ('[spring]\nlaw = "oblique"\nstiffness = 3.0\n', r"unknown key\(s\) \['stiffness'\]"),
    ('[spring]\nlaw = "oblique"\nfree_length = -1.0\n',
     r"\[spring\] free_length in '.*spring.toml'"),
    ('[spring]\nlaw = "table"\n', r"needs csv = \"FILE.csv\", or positions \[m\] and forces \[N\]"),
    ('[spring]\nlaw = "table"\ncsv = "a.csv"\npositions = [0.0, 1.0, 2.0]\n',
     r"gives both csv and \['positions'\]: give the force curve once"),
    ('[spring]\nlaw = "table"\npositions = [0.0, 1.0, 1.0]\nforces = [1.0, 2.0, 3.0]\n',
     r"\[spring\] positions in .* must be strictly increasing, but it is repeated"),
    ('[spring]\nlaw = "table"\npositions = [0.0, 1.0, 2.0]\nforces = [1.0, 2.0, 3.0]\n'
     'position_unit = "mm"\n', r"\['position_unit'\] are options of csv, which is not given"),
    ('[spring]\nlaw = "tanh"\n[isolator]\nmass = 1.0\n', r"must hold a \[spring\] table and "
                                                        r"nothing else"),
])
def test_bad_spring_tables_are_refused_naming_the_key_and_the_fix(tmp_path, text, match):
    path = _write(tmp_path / "spring.toml", text)
    with pytest.raises(ParameterError, match=match):
        load_spring(path)


def test_a_missing_csv_and_mismatched_units_are_refused(tmp_path):
    path = _write(tmp_path / "spring.toml", '[spring]\nlaw = "table"\ncsv = "none.csv"\n')
    with pytest.raises(DataError, match="none.csv"):
        load_spring(path)
    (tmp_path / "c.csv").write_text("position [mm],force [N]\n0,1\n1,2\n2,3\n")
    _write(path, '[spring]\nlaw = "table"\ncsv = "c.csv"\nposition_unit = "m"\n')
    with pytest.raises(ParameterError, match=r"\[spring\] position_unit in .* mismatched units"):
        load_spring(path)


def test_a_tanh_law_and_other_tanh_fields_in_one_config_are_refused(tmp_path):
    path = _write(tmp_path / "run.toml", '[isolator]\nspring_force = 50.0\n[spring]\n'
                  'law = "tanh"\nplateau = 60.84\nshape = 78.1\n')
    with pytest.raises(ParameterError, match=r"`spring_force` \(50.0\) disagree"):
        load_config(path)
