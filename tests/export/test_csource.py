"""The system C compiler: found, or a clear error naming it; its failures reported."""
import pytest

from qzs.errors import CompilerError
from qzs.export import csource


def test_a_missing_compiler_is_a_clear_error(monkeypatch):
    monkeypatch.setenv("CC", "no-such-cc-qzs")
    with pytest.raises(CompilerError) as caught:
        csource.find_compiler()
    assert caught.value.compiler == "no-such-cc-qzs"
    assert "no-such-cc-qzs" in str(caught.value) and "CC" in str(caught.value)


def test_a_failing_compilation_reports_the_compilers_messages(tmp_path):
    try:
        csource.find_compiler()
    except CompilerError:  # pragma: no cover
        pytest.skip("no C compiler")
    bad = tmp_path / "bad.c"
    bad.write_text("int f(void) { return missing_name; }\n")
    with pytest.raises(CompilerError) as caught:
        csource.compile_shared([bad], tmp_path / "bad.so")
    assert "missing_name" in caught.value.reason
    assert not (tmp_path / "bad.so").exists()


def test_the_shipped_sources_are_there():
    for name in csource.SOURCES:
        assert (csource.source_folder() / name).is_file()
    assert "qzs_controller_step" in csource.source_text("qzs_controller.h")
