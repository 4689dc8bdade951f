"""The design-space package's entry points (qzs.workflows.design_space)."""
import qzs.workflows.design_space as design_space


def test_the_package_exports_the_search_and_its_parts():
    for name in design_space.__all__:
        assert getattr(design_space, name) is not None
    assert callable(design_space.optimize) and callable(design_space.load_problem)
