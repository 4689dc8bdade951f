"""The spring of the paper's studies as the report states it (qzs.workflows.paper.report_spring)."""
from types import SimpleNamespace

import qzs
from qzs.workflows.paper.report_spring import spring_record, spring_statement


def test_the_default_is_the_magspring_of_table_1_and_another_law_is_named_as_not_the_papers():
    default = [SimpleNamespace(spring=None), SimpleNamespace(spring=None)]
    iso = qzs.IsolatorParameters()
    assert spring_record(default) == {"law": "tanh", "plateau": [iso.spring_force, "N"],
                                      "shape": [iso.spring_shape, "1/m"]}
    assert "MagSpring" in spring_statement(default)
    assert spring_statement(default).endswith("(the paper's, the default)")
    law = qzs.ObliqueSpringQZS.quasi_zero()
    given = [SimpleNamespace(spring=None), SimpleNamespace(spring=law)]
    record = spring_record(given)
    assert record["law"] == "oblique" and record["free_length"] == [law.free_length, "m"]
    assert record["vertical_stiffness"] == [law.vertical_stiffness, "N/m"]
    assert spring_statement(given).startswith(law.describe())
    assert "not the paper's MagSpring" in spring_statement(given)
