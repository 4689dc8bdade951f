"""Output paths checked before the work (qzs.iotools.paths): each way a path cannot be
written is refused with the argument's name, and nothing is left behind by the check."""
import os
import shutil
from collections import namedtuple

import pytest

from qzs.errors import OutputPathError
from qzs.iotools import paths
from qzs.iotools.paths import check_output_path, format_bytes, removed_on_error


def test_a_writable_path_passes_and_the_check_writes_nothing(tmp_path):
    target = tmp_path / "new" / "deeper" / "run.NC"   # missing folders can be created
    assert check_output_path(target, argument="--out", suffixes=("nc", ".csv")) == target
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("make, name, options, reason", [
    (None, "run.txt", {"suffixes": (".nc", ".csv")},
     "has extension '.txt'; it must end in .nc or .csv"),
    (None, "run.txt", {"suffixes": (".nc", ".csv", ".mat")},
     "has extension '.txt'; it must end in .nc, .csv or .mat"),
    (None, "run", {"suffixes": (".nc",)}, "has no extension"),
    ("folder", "run.nc", {"suffixes": (".nc",)}, "is a folder; give a file name"),
    ("file", "out", {"suffixes": None, "directory": True}, "is a file, not a folder"),
    ("parent file", "run.nc", {"suffixes": (".nc",)}, "is a file, not a folder"),
])
def test_each_unwritable_path_is_named_with_its_reason(tmp_path, make, name, options, reason):
    path = tmp_path / name
    if make == "folder":
        path.mkdir()
    elif make == "file":
        path.write_text("")
    elif make == "parent file":
        (tmp_path / "blocker").write_text("")
        path = tmp_path / "blocker" / "sub" / name
    with pytest.raises(OutputPathError, match=reason) as error:
        check_output_path(path, argument="--out", **options)
    assert (error.value.argument, error.value.value) == ("--out", str(path))


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_a_read_only_folder_is_refused(tmp_path):
    folder = tmp_path / "locked"
    folder.mkdir()
    folder.chmod(0o500)
    try:
        with pytest.raises(OutputPathError, match="is read-only"):
            check_output_path(folder / "run.nc", argument="out", suffixes=(".nc",))
    finally:
        folder.chmod(0o700)


def test_too_little_free_space_says_how_much_is_needed(tmp_path, monkeypatch):
    usage = namedtuple("usage", "total used free")
    monkeypatch.setattr(shutil, "disk_usage", lambda path: usage(2 ** 40, 0, 3 * 2 ** 20))
    assert paths.shutil is shutil
    check_output_path(tmp_path / "a.nc", argument="out", suffixes=None,
                      estimated_bytes=3 * 2 ** 20)
    with pytest.raises(OutputPathError, match=r"needs about 4\.0 MiB but only 3\.0 MiB are free"):
        check_output_path(tmp_path / "a.nc", argument="out", suffixes=None,
                          estimated_bytes=4 * 2 ** 20)


def test_byte_counts_in_binary_units():
    assert [format_bytes(n) for n in (0, 1023, 1024, 1536, 5 * 2 ** 30, 3 * 2 ** 50)] == [
        "0 B", "1023 B", "1.0 KiB", "1.5 KiB", "5.0 GiB", "3072.0 TiB"]


@pytest.mark.parametrize("directory", [False, True])
def test_an_empty_name_says_it_is_empty_not_that_it_is_a_folder(directory, tmp_path,
                                                                 monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(OutputPathError) as caught:
        check_output_path("", argument="--out", suffixes=None if directory else (".nc",),
                          directory=directory)
    assert caught.value.argument == "--out" and caught.value.value == ""
    assert "empty" in str(caught.value) and "'.'" not in str(caught.value)


def test_a_free_name_is_the_name_itself_or_the_next_numbered_one(tmp_path):
    from qzs.iotools.paths import free_name

    store = tmp_path / "pi.zarr"
    assert free_name(store, directory=True) == store
    store.mkdir()
    assert free_name(store, directory=True) == store          # an empty folder is free
    (store / "a").write_text("")
    (tmp_path / "pi-2.zarr").mkdir()
    (tmp_path / "pi-2.zarr" / "a").write_text("")
    assert free_name(store, directory=True) == tmp_path / "pi-3.zarr"
    (tmp_path / "results").write_text("")
    assert free_name(tmp_path / "results") == tmp_path / "results-2"


def test_removed_on_error_takes_back_what_a_failed_block_made_and_nothing_else(tmp_path):
    store = tmp_path / "a" / "b" / "s.zarr"
    with pytest.raises(ValueError):
        with removed_on_error(store):
            store.mkdir(parents=True)
            (store / "zarr.json").write_text("{}")
            raise ValueError("refused")
    assert list(tmp_path.iterdir()) == []  # the store and the two folders made for it
    with pytest.raises(ValueError):
        with removed_on_error(store) as made:
            store.mkdir(parents=True)
            made.keep()  # a batch is in it: kept for a resume
            raise ValueError("a later batch failed")
    assert store.is_dir()
    with pytest.raises(ValueError):
        with removed_on_error(store):  # it existed before: never removed
            raise ValueError("refused")
    assert store.is_dir()
    other = tmp_path / "other.zarr"
    with pytest.raises(KeyboardInterrupt):
        with removed_on_error(other):  # Ctrl-C keeps what is there, for a resume
            other.mkdir()
            raise KeyboardInterrupt
    assert other.is_dir()
