"""Cached kernels are dropped when any kernel source changes (numba checks only their own file)."""
import os
import subprocess
import sys

_PROBE = """
import json
from pathlib import Path
import qzs.engine.arithmetic as a
print(json.dumps(str(Path(a._cache_probe._cache._cache_path))))
"""


def _folder(cache):
    import json

    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache))
    out = subprocess.run([sys.executable, "-c", _PROBE], env=env, capture_output=True, text=True,
                         check=True, timeout=120)
    from pathlib import Path

    return Path(json.loads(out.stdout.strip().splitlines()[-1]))


def test_a_changed_fingerprint_drops_the_cached_kernels_and_only_those(tmp_path):
    folder = _folder(tmp_path)  # first import: the stamp is written
    stamp = folder / "qzs-kernel-sources.sha256"
    fingerprint = stamp.read_text().strip()
    assert len(fingerprint) == 64
    stale = folder / "kernels.rhs_at-138.py311.nbi"
    other = folder / "mypackage.kernel-1.py311.nbi"
    for path in (stale, other):
        path.write_bytes(b"compiled from other sources")
    _folder(tmp_path)  # same sources: nothing is touched
    assert stale.exists() and other.exists()
    stamp.write_text("0" * 64 + "\n")  # as if a kernel source had been edited since
    _folder(tmp_path)
    assert not stale.exists()  # qzs's kernels are compiled again
    assert other.exists()      # nobody else's cache is touched
    assert stamp.read_text().strip() == fingerprint
    assert [p.name for p in folder.iterdir() if p.name.startswith(".")] == []
