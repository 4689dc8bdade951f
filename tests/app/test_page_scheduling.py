"""A session's results reach its page whichever thread finishes them, and whenever.

The page's computations end on the server's computing thread; their results must come
back to the session's event loop. Built in a real Bokeh server session (no browser): the
page's first computation ends on another thread while the server renders the page's HTML
(Panel's ``patch_model_css``, which holds the document and puts back the events it held
before), the moment at which a new page of the browser tests once never drew.
"""
import asyncio
import threading

import pytest
from helpers import HeldExecutor

pytest.importorskip("panel", reason='the page needs Panel: pip install -e ".[app]"')

import panel.io.resources as resources  # noqa: E402
from bokeh.document import Document  # noqa: E402
from bokeh.server.session import ServerSession  # noqa: E402
from panel.io.state import set_curdoc  # noqa: E402
from tornado.ioloop import IOLoop  # noqa: E402

from qzs.app import page as page_module  # noqa: E402
from qzs.app.compute import page_request  # noqa: E402


def _finish_on_another_thread(executor):
    """Run the waiting computations on a new thread, as the server's computing thread
    would (their futures' callbacks run there), and wait for it."""
    thread = threading.Thread(target=lambda: [executor.finish() for _ in list(executor.jobs)])
    thread.start()
    thread.join()


async def _serve_and_render(monkeypatch, during):
    """A page in a server session whose first result ends while Panel renders the page
    (``during``) or after; returns the page and the document's hold when it ended."""
    document = Document()
    executor = HeldExecutor()
    with set_curdoc(document):
        page = page_module.TuningPage(executor=executor)  # the server's own scheduling
        root = page.layout.get_root(document)
    document.add_root(root)
    ServerSession("qzs-test", document, io_loop=IOLoop.current())
    seen = {}
    patch_stylesheet = resources.patch_stylesheet

    def finish_while_rendering(stylesheet, dist_url):
        if during and not seen:  # the first stylesheet: the document is held now
            seen["hold"] = document.callbacks.hold_value
            _finish_on_another_thread(executor)
        return patch_stylesheet(stylesheet, dist_url)

    monkeypatch.setattr(resources, "patch_stylesheet", finish_while_rendering)
    resources.patch_model_css(root, dist_url="static/extensions/panel/")  # as GET / does
    if not during:
        seen["hold"] = document.callbacks.hold_value
        _finish_on_another_thread(executor)
    for _ in range(200):  # the event loop runs the session's callbacks
        if page.data is not None:
            break
        await asyncio.sleep(0.01)
    return page, seen.get("hold")


@pytest.mark.parametrize("during", [True, False], ids=["while-rendered", "after"])
def test_a_result_that_ends_while_the_page_is_rendered_is_drawn(monkeypatch, during):
    page, hold = asyncio.run(_serve_and_render(monkeypatch, during))
    assert (hold is not None) is during  # it ended inside the document's hold, or not
    assert page.data is not None, "the first result never reached the page"
    assert page.data.request == page_request()
    assert len(page.sources["transmissibility"].data["x"]) == len(page.data.frequency[
        page.data.frequency > 0]) > 0
    assert not page.updates.running and page.updates.delivered == 1


async def _close_before_the_loop_runs():
    """A page in a server session whose first result ends on another thread, the session
    destroyed before the event loop gets to it; returns the page after the loop ran."""
    document = Document()
    executor = HeldExecutor()
    with set_curdoc(document):
        page = page_module.TuningPage(executor=executor)
        root = page.layout.get_root(document)
    document.add_root(root)
    ServerSession("qzs-test", document, io_loop=IOLoop.current())
    _finish_on_another_thread(executor)  # handed to the loop, which has not run it yet
    page._destroyed(None)  # the browser went away meanwhile
    for _ in range(50):  # the event loop runs what was handed to it
        await asyncio.sleep(0.01)
    return page


def test_a_result_that_ends_after_its_session_closed_is_not_drawn():
    """A result handed to the loop for a session that is closed by the time the loop runs
    it touches the session's document no more: the page stays as it was, undrawn."""
    page = asyncio.run(_close_before_the_loop_runs())
    assert page.data is None
    assert not any(len(source.data.get("x", ())) for source in page.sources.values())
