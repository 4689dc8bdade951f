"""The exported controller.c with the controller's blocks (issue 40): every block carried,
its forces the simulated blocks' sample for sample."""
import pytest
from helpers import EXPORT_DISCRETE

import qzs
from qzs.errors import CompilerError
from qzs.export import controller as exported
from qzs.export.csource import find_compiler

try:
    find_compiler()
except CompilerError:  # pragma: no cover
    pytest.skip("no C compiler", allow_module_level=True)

SAMPLED = qzs.PIDamping(controller_rate=1000.0)


@pytest.mark.parametrize("block", [
    qzs.FrictionCompensation(fraction=0.5), qzs.Dither(amplitude=1.0, frequency=50.0),
    EXPORT_DISCRETE], ids=["compensation", "dither", "linear"])
def test_a_block_is_not_dropped_from_the_export(block):
    """A controller with a block is not exported as its PI + damping alone (it was, silently)."""
    assert exported.controller_source(SAMPLED + block) != exported.controller_source(SAMPLED)
