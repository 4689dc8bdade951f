"""``qzs simulate --spring FILE.toml``: the law of a [spring] table; bad input exits 2 at once."""
import pytest

from qzs.cli import main
from qzs.cli.common import kernel_families
from qzs.iotools import read_result


@pytest.mark.parametrize("text, said", [
    ('[spring]\nlaw = "cubic"\n', "law = 'cubic'; write law = one of"),
    ('[spring]\nlaw = "oblique"\nfree_length = "long"\n', "[spring] free_length in"),
    ('spring = 3\n', "[spring] must be a table, got 3"),
    ('[spring]\nlaw = "tanh"\n[simulation]\ndt = 1e-4\n',
     "must hold a [spring] table and nothing else"),
    ('[spring]\nlaw = "polynomial"\ncoefficients = [0.0, -10.0]\n', "no stable equilibrium"),
])
def test_a_bad_spring_file_exits_2_before_any_run(tmp_path, capsys, text, said):
    path = tmp_path / "spring.toml"
    path.write_text(text)
    out = tmp_path / "run.nc"
    assert main(["simulate", "--spring", str(path), "--excitation", "sine", "--amplitude", "0.001",
                 "--frequency", "2", "--duration", "1", "--out", str(out), "--plot", "none",
                 "--quiet"]) == 2
    assert said in capsys.readouterr().err
    assert not out.exists() and list(tmp_path.iterdir()) == [path]


def test_a_spring_file_runs_the_general_kernel_and_the_result_records_the_law(tmp_path, capsys):
    path = tmp_path / "spring.toml"
    path.write_text('[spring]\nlaw = "oblique"\nvertical_stiffness = "quasi-zero"\n')
    out = tmp_path / "run.nc"
    argv = ["simulate", "--spring", str(path), "--excitation", "sine", "--amplitude", "0.001",
            "--frequency", "2", "--duration", "0.2", "--out", str(out), "--plot", "none"]
    from qzs.cli import build_parser
    assert "single_blocks" in kernel_families(build_parser().parse_args(argv))
    assert main(argv) == 0
    assert "spring           oblique-spring QZS: k_v = 200 N/m" in capsys.readouterr().out
    attrs = read_result(out).attrs
    assert attrs["isolator.spring.law"] == "oblique"
    assert attrs["isolator.spring.free_length"] == 0.1875
    assert attrs["isolator.spring.free_length_units"] == "m"


def test_set_changes_a_parameter_of_the_spring_file_s_law(tmp_path, capsys):
    """``--set spring.preload=61`` (docs/model.md §3.1) changes the --spring file's law: the
    run records the changed preload; without a law the same --set exits 2 naming the fix."""
    path = tmp_path / "spring.toml"
    path.write_text('[spring]\nlaw = "oblique"\nvertical_stiffness = "quasi-zero"\n')
    out = tmp_path / "run.nc"
    argv = ["simulate", "--excitation", "sine", "--amplitude", "0.001", "--frequency", "2",
            "--duration", "0.2", "--plot", "none", "--quiet", "--set", "spring.preload=61"]
    assert main([*argv, "--spring", str(path), "--out", str(out)]) == 0
    attrs = read_result(out).attrs
    assert attrs["isolator.spring.preload"] == 61.0
    assert attrs["isolator.spring.vertical_stiffness"] == 200.0
    capsys.readouterr()
    assert main([*argv, "--out", str(tmp_path / "none.nc")]) == 2
    assert "give the law first" in capsys.readouterr().err
    assert not (tmp_path / "none.nc").exists()
