"""Drive the tuning page in a real, headless Chromium (Playwright): the browser tests and
``benchmarks/bench_app.py`` share these steps.

Playwright drives Debian's Chromium (``apt-get install chromium`` gives
``/usr/bin/chromium``); its own browser download is never used. Each launch gets a fresh
user-data folder and the flags of :data:`CHROMIUM_ARGS`. The page's data are read where the
browser holds them: the Bokeh document's data sources, by name
(:data:`qzs.app.page.SOURCE_NAMES`).
"""
import contextlib
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

__all__ = ["CHROMIUM", "CHROMIUM_ARGS", "INSTALL_HINT", "find_chromium", "free_port",
           "start_server", "launch", "open_page", "source_data", "drag_slider", "type_value",
           "wait_until_changed", "download", "horizontal_overflow", "plot_boxes"]

#: Debian's Chromium.
CHROMIUM = "/usr/bin/chromium"
#: Flags of every launch: headless, no sandbox (root in a VM), nothing fetched in the
#: background.
CHROMIUM_ARGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync", "--no-first-run")
#: How to get the browser where it is missing.
INSTALL_HINT = (f"{CHROMIUM} is missing: install Debian's Chromium with `sudo apt-get update && "
                "sudo apt-get install -y chromium` (the browser tests use it through Playwright; "
                "never `playwright install`, whose download does not work on these machines)")
_READY = ("() => { const d = window.Bokeh && Bokeh.documents[0]; if (!d) return false; "
          "const m = d.get_model_by_name(NAME); return !!m && m.data.x.length > 0; }")
_CHANGED = """([name, old]) => {
  const m = Bokeh.documents[0].get_model_by_name(name);
  const y = Array.from(m.data.y);
  const changed = y.length !== old.length || y.some((v, i) => v !== old[i]);
  if (changed && !window.__qzs_changed) {
    window.__qzs_changed = performance.now();
    requestAnimationFrame(() => requestAnimationFrame(() => {
      window.__qzs_drawn = performance.now(); }));
  }
  return changed;
}"""


def find_chromium(install=False):
    """The path of Chromium, or None; installs Debian's package first if asked and possible.

    Parameters
    ----------
    install : bool
        If it is missing and this process is root with ``apt-get``, run
        ``apt-get install -y chromium`` (after ``apt-get update`` if the first try fails).

    Returns
    -------
    str or None
    """
    if os.path.exists(CHROMIUM):
        return CHROMIUM
    if install and hasattr(os, "geteuid") and os.geteuid() == 0 and shutil.which("apt-get"):
        env = {**os.environ, "DEBIAN_FRONTEND": "noninteractive"}
        for commands in ([["apt-get", "install", "-y", "chromium"]],
                         [["apt-get", "update"], ["apt-get", "install", "-y", "chromium"]]):
            if all(subprocess.run(c, env=env, capture_output=True).returncode == 0
                   for c in commands) and os.path.exists(CHROMIUM):
                return CHROMIUM
    return None


def free_port():
    """A port free on 127.0.0.1 now [-]."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


@contextlib.contextmanager
def start_server(port=None, timeout=600.0, log=None, options=()):
    """Run ``qzs app --no-browser --port PORT`` as a child process until the block ends.

    Parameters
    ----------
    port : int, optional
        Default :func:`free_port`.
    timeout : float
        Seconds to wait for the page to answer (the first start compiles the kernels).
    log : file, optional
        Where the server's output goes (default a temporary file, shown if it fails).
    options : sequence of str
        More options of ``qzs app`` (``("--spring", "FILE.toml")``).

    Yields
    ------
    url : str
        The page's address.
    """
    port = port or free_port()
    url = f"http://127.0.0.1:{port}/"
    output = log or tempfile.TemporaryFile(mode="w+")
    process = subprocess.Popen([sys.executable, "-m", "qzs", "app", "--no-browser", "--port",
                                str(port), *options], stdout=output,
                               stderr=subprocess.STDOUT)
    try:
        deadline = time.monotonic() + timeout
        while True:
            if process.poll() is not None:
                raise RuntimeError(f"`qzs app` exited with {process.returncode}:\n"
                                   f"{_read(output)}")
            try:
                with urllib.request.urlopen(url, timeout=5) as answer:
                    if answer.status == 200:
                        break
            except OSError:
                pass
            if time.monotonic() > deadline:
                raise RuntimeError(f"`qzs app` did not answer within {timeout:g} s:\n"
                                   f"{_read(output)}")
            time.sleep(0.25)
        yield url
    finally:
        process.terminate()
        try:
            process.wait(timeout=20)
        except subprocess.TimeoutExpired:  # pragma: no cover
            process.kill()
            process.wait()
        if log is None:
            output.close()


def _read(output):
    try:
        output.seek(0)
        return output.read()[-4000:]
    except (OSError, ValueError):  # pragma: no cover
        return ""


@contextlib.contextmanager
def launch(viewport=(1500, 1000)):
    """A headless Chromium browser context (Playwright) with a fresh user-data folder.

    Parameters
    ----------
    viewport : (int, int)
        Width and height of the page [px].

    Yields
    ------
    playwright.sync_api.BrowserContext
    """
    from playwright.sync_api import sync_playwright

    with tempfile.TemporaryDirectory(prefix="qzs-chromium-") as profile, \
            sync_playwright() as playwright:
        context = playwright.chromium.launch_persistent_context(
            profile, executable_path=CHROMIUM, args=list(CHROMIUM_ARGS), headless=True,
            viewport={"width": viewport[0], "height": viewport[1]}, accept_downloads=True)
        try:
            yield context
        finally:
            context.close()


def open_page(context, url, timeout=60.0):
    """Load the page and wait until its transmissibility is drawn.

    Parameters
    ----------
    context : playwright.sync_api.BrowserContext
        The browser.
    url : str
        The server's address.
    timeout : float
        Seconds to wait [s].

    Returns
    -------
    playwright.sync_api.Page
    """
    from qzs.app.page import SOURCE_NAMES

    page = context.new_page()
    page.goto(url)
    page.wait_for_function(_READY.replace("NAME", repr(SOURCE_NAMES["transmissibility"])),
                           timeout=timeout * 1e3)
    page.evaluate("() => document.addEventListener('pointerup', () => {"
                  " window.__qzs_release = performance.now(); window.__qzs_changed = 0;"
                  " window.__qzs_drawn = 0; }, true)")
    return page


def source_data(page, key):
    """The columns of one of the page's data sources, as the browser holds them.

    Parameters
    ----------
    page : playwright.sync_api.Page
        The loaded page.
    key : str
        A key of :data:`qzs.app.page.SOURCE_NAMES` (``transmissibility``, ``pinned``, ...).

    Returns
    -------
    dict of list
    """
    from qzs.app.page import SOURCE_NAMES

    return page.evaluate(
        "(name) => { const m = Bokeh.documents[0].get_model_by_name(name); const out = {};"
        " for (const [k, v] of Object.entries(m.data)) out[k] = Array.from(v, (x) =>"
        " (x && x.length !== undefined && typeof x !== 'string') ? Array.from(x) : x);"
        " return out; }", SOURCE_NAMES[key])


def horizontal_overflow(page):
    """How far the page is wider than the window [px] (0: nothing clipped or scrolled).

    Parameters
    ----------
    page : playwright.sync_api.Page
        The loaded page.

    Returns
    -------
    int
        ``document.documentElement.scrollWidth`` minus the window's inner width.
    """
    return page.evaluate("() => document.documentElement.scrollWidth - window.innerWidth")


def plot_boxes(page, name):
    """Where a Bokeh plot's frame (the data region) and its legend are drawn.

    Parameters
    ----------
    page : playwright.sync_api.Page
        The loaded page.
    name : str
        The plot's Bokeh ``name`` (``qzs-transmissibility-plot``, ``qzs-response-plot``).

    Returns
    -------
    frame, legend : tuple of float
        ``(left, top, right, bottom)`` in the plot's canvas [px]; ``legend`` is None for a
        plot without one.
    """
    return page.evaluate("""(name) => {
      const model = Bokeh.documents[0].get_model_by_name(name);
      let view = null;
      for (const root of Bokeh.index) { view = root.owner.find_one(model); if (view) break; }
      const box = (b) => [b.left, b.top, b.right, b.bottom];
      const legend = [...model.center, ...model.above, ...model.below, ...model.left,
                      ...model.right].find((r) => r.type === "Legend");
      return [box(view.frame.bbox),
              legend === undefined ? null : box(view.owner.find_one(legend).bbox)];
    }""", name)


def wait_until_changed(page, old_y, key="transmissibility", timeout=30.0):
    """Wait until a data source's ``y`` differs from ``old_y``; seconds from the last
    release of a slider (or Enter in a field, :func:`type_value`) to that change and to
    the frame after it.

    Parameters
    ----------
    page : playwright.sync_api.Page
        The loaded page.
    old_y : list of float
        The column before.
    key : str
        A key of :data:`qzs.app.page.SOURCE_NAMES`.
    timeout : float
        Seconds to wait [s].

    Returns
    -------
    changed, drawn : float
        Seconds from the release to the new data, and to the second animation frame after
        it (the plot redrawn) [s].
    """
    from qzs.app.page import SOURCE_NAMES

    page.evaluate("() => { window.__qzs_changed = 0; window.__qzs_drawn = 0; }")
    page.wait_for_function(_CHANGED, arg=[SOURCE_NAMES[key], old_y], timeout=timeout * 1e3,
                           polling="raf")
    page.wait_for_function("() => window.__qzs_drawn > 0", timeout=timeout * 1e3)
    changed, drawn, release = page.evaluate(
        "() => [window.__qzs_changed, window.__qzs_drawn, window.__qzs_release]")
    return (changed - release) / 1e3, (drawn - release) / 1e3


def drag_slider(page, name, pixels):
    """Drag a setting's slider handle by ``pixels`` and release it.

    Parameters
    ----------
    page : playwright.sync_api.Page
        The loaded page.
    name : str
        The setting (``stiction_force``, ``pi_kp``, ...).
    pixels : float
        Horizontal distance [px]; negative: to the left.
    """
    from qzs.app.page import css_class

    handle = page.locator(f".{css_class(name)} .noUi-handle").first
    handle.scroll_into_view_if_needed()
    box = handle.bounding_box()
    x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    page.mouse.move(x, y)
    page.mouse.down()
    page.mouse.move(x + pixels, y, steps=4)
    page.mouse.up()


def type_value(page, name, text):
    """Type ``text`` into a setting's number field and press Enter.

    Parameters
    ----------
    page : playwright.sync_api.Page
        The loaded page.
    name : str
        The setting (``coulomb_force``, ...).
    text : str
        What to type.
    """
    from qzs.app.page import css_class

    field = page.locator(f".{css_class(name)} input").first
    field.fill(text)
    page.evaluate("() => { window.__qzs_release = performance.now(); }")  # the clock starts
    field.press("Enter")


def download(page, label, folder):
    """Click the button labelled ``label`` and save the download it starts.

    Parameters
    ----------
    page : playwright.sync_api.Page
        The loaded page.
    label : str
        The button's text (``Export TOML config``, ``Export figure PNG``).
    folder : str or Path
        Where to save it.

    Returns
    -------
    Path
        The saved file (the name the page suggested).
    """
    with page.expect_download() as event:
        page.get_by_text(label, exact=True).click()
    path = Path(folder) / event.value.suggested_filename
    event.value.save_as(path)
    return path
