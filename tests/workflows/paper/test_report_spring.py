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


def test_the_fit_s_paragraph_names_the_true_law_and_the_fit_apart():
    """The report's spring paragraph says which law was measured (the true one) and what the
    fit found (its summary): with noise they differ, and each is in its place."""
    import html

    import numpy as np

    from qzs.workflows.paper.report_spring import spring_fit_html

    law = qzs.PolynomialSpring(coefficients=(62.78, -100.0, 0.0, -5e4), center=-0.06)
    z = np.linspace(-0.1, 0.02, 41)
    measured = law.force(z) + np.random.default_rng(2).normal(0.0, 0.6, z.size)
    fit = qzs.fit_spring(z, measured, law="polynomial", degree=3, center=-0.06)
    assert fit.law.describe() != law.describe()
    result = SimpleNamespace(cases=[SimpleNamespace(extra={"law_fit": fit, "true_law": law})])
    text = html.unescape(spring_fit_html(result))
    true_part, fitted_part = text.split("fitted:", 1)
    assert f"true {law.describe()}" in true_part and fit.law.describe() not in true_part
    assert fit.summary() in fitted_part
