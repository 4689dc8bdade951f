"""``qzs paper``'s runner: its arguments checked before any study runs."""
import pytest


@pytest.mark.parametrize("make", ["file", "read-only"])
def test_a_bad_output_folder_fails_before_any_study_runs(tmp_path, monkeypatch, make, request):
    """`qzs paper --out <file>` used to fail only after the studies ran (minutes, cold)."""
    import qzs.workflows.paper.report as report
    from qzs.errors import OutputPathError

    monkeypatch.setattr(report, "run_studies",
                        lambda *args, **kwargs: pytest.fail("a study ran before the check"))
    if make == "file":
        folder = tmp_path / "a-file"
        folder.write_text("in the way")
    else:
        folder = request.getfixturevalue("read_only_folder") / "report"
    with pytest.raises(OutputPathError) as caught:
        report.run_paper(["stiction"], folder, quick=True, argument="--out")
    assert (caught.value.argument, caught.value.value) == ("--out", str(folder))
