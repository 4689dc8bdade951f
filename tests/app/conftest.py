"""The default page, computed once for the tests of the page's data and of its figure."""
import pytest

from qzs.app.compute import compute_page, page_request


@pytest.fixture(scope="package")
def default_page():
    return compute_page(page_request())
