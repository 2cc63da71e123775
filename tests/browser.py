"""Open an HTML page in a real headless browser and say what a reader would see wrong.

    from tests.browser import open_page, require_browser
    require_browser()                       # pytest.skip with the reason where Chromium is absent
    seen = open_page(path)                  # PageCheck; several pages: with Browser() as b: b.check(p)
    assert seen.console_errors == [] and seen.broken_images == [] and seen.images > 0

Chromium and its driver come from Debian's packages (``apt-get install chromium chromium-driver``,
which ``.ci/run`` does when they are missing): /usr/bin/chromium driven by /usr/bin/chromedriver
through selenium (a test dependency). No network: the page is opened as a file:// URL and every
host name resolves to nothing. Override the binaries with FTCSIM_CHROMIUM / FTCSIM_CHROMEDRIVER.
"""
from __future__ import annotations

import os
import shutil
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

CHROMIUM_CANDIDATES = ("chromium", "chromium-browser", "google-chrome")


@dataclass
class PageCheck:
    """What the browser saw: console messages of level SEVERE (JavaScript errors, failed loads),
    the images that did not render (``naturalWidth == 0``; their alt text or source), the number
    of images and the captions (or first header cells) of the tables."""

    title: str
    console_errors: list = field(default_factory=list)
    broken_images: list = field(default_factory=list)
    images: int = 0
    tables: list = field(default_factory=list)
    links: list = field(default_factory=list)


def binaries() -> tuple[str | None, str | None]:
    """(chromium, chromedriver) paths, or None for the one not found."""
    browser = os.environ.get("FTCSIM_CHROMIUM") or next(filter(None, map(shutil.which, CHROMIUM_CANDIDATES)), None)
    driver = os.environ.get("FTCSIM_CHROMEDRIVER") or shutil.which("chromedriver")
    return browser, driver


def missing() -> str | None:
    """Why the browser test cannot run here, or None when it can."""
    browser, driver = binaries()
    if browser is None or driver is None:
        return ("headless Chromium not installed (`apt-get install chromium chromium-driver`; .ci/run installs it): "
                f"chromium {'found' if browser else 'missing'}, chromedriver {'found' if driver else 'missing'}")
    try:
        import selenium  # noqa: F401
    except ImportError:
        return "the Python package selenium is not installed (pip install -e '.[test]')"
    return None


def require_browser() -> None:
    """Skip the calling test, with the reason, where Chromium, its driver or selenium is missing."""
    import pytest

    reason = missing()
    if reason:
        pytest.skip(reason)


_PROBE = """
const imgs = Array.from(document.images);
return {
  title: document.title,
  images: imgs.length,
  broken: imgs.filter(i => !i.complete || i.naturalWidth === 0).map(i => i.alt || i.src.slice(0, 80)),
  tables: Array.from(document.querySelectorAll('table')).map(t =>
      (t.caption && t.caption.textContent.trim()) || Array.from(t.querySelectorAll('th')).slice(0, 3)
          .map(h => h.textContent.trim()).join(' | ')),
  links: Array.from(document.querySelectorAll('a[href]')).map(a => a.getAttribute('href')),
};
"""


class Browser:
    """One headless Chromium for several pages: ``with Browser() as b: b.check(path)`` (a start
    costs seconds; a page load a fraction of one)."""

    def __init__(self, timeout: float = 60.0):
        self.timeout = timeout
        self.driver = None
        self.profile = None

    def __enter__(self) -> Browser:
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service

        browser, driver_path = binaries()
        if browser is None or driver_path is None:
            raise RuntimeError(missing())
        self.profile = tempfile.mkdtemp(prefix="ftcsim-chromium-")
        opts = webdriver.ChromeOptions()
        opts.binary_location = browser
        for arg in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--no-first-run",
                    "--disable-extensions", "--host-resolver-rules=MAP * ~NOTFOUND", f"--user-data-dir={self.profile}"):
            opts.add_argument(arg)
        opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
        try:
            self.driver = webdriver.Chrome(options=opts, service=Service(executable_path=driver_path))
            self.driver.set_page_load_timeout(self.timeout)
        except BaseException:
            shutil.rmtree(self.profile, ignore_errors=True)
            raise
        return self

    def __exit__(self, *exc) -> None:
        try:
            if self.driver is not None:
                self.driver.quit()
        finally:
            shutil.rmtree(self.profile, ignore_errors=True)

    def check(self, path) -> PageCheck:
        """Load ``path`` (waits for the load event, images included) and report what was seen."""
        drv = self.driver
        drv.get_log("browser")  # drop what an earlier page left
        drv.get(Path(path).resolve().as_uri())
        seen = drv.execute_script(_PROBE)
        errors = [e["message"] for e in drv.get_log("browser") if e.get("level") == "SEVERE"]
        return PageCheck(title=seen["title"], console_errors=errors, broken_images=list(seen["broken"]),
                         images=int(seen["images"]), tables=list(seen["tables"]), links=list(seen["links"]))


def open_page(path, timeout: float = 60.0) -> PageCheck:
    """One page in a fresh headless Chromium (see :class:`Browser` for several)."""
    with Browser(timeout) as b:
        return b.check(path)


_LEGIBILITY = """
const W = window.innerWidth;
document.querySelectorAll('details').forEach(d => { d.open = true; });
const imgs = Array.from(document.images).map(i => {
  const box = i.parentElement.getBoundingClientRect();
  return {alt: i.alt || i.src.slice(0, 60), natural: i.naturalWidth, shown: i.getBoundingClientRect().width,
          container: box.width};
});
const tables = Array.from(document.querySelectorAll('table')).map(t => {
  const r = t.getBoundingClientRect();
  return {caption: (t.caption && t.caption.textContent.trim()) || '', width: r.width, right: r.right,
          scroll: t.scrollWidth, container: t.parentElement.getBoundingClientRect().width};
});
return {width: W, page: document.documentElement.scrollWidth, images: imgs, tables: tables};
"""

_FIRST = """
const t = document.querySelector('table');
if (!t) return null;
const r = t.getBoundingClientRect();
return {caption: (t.caption && t.caption.textContent.trim()) || '', top: r.top, bottom: r.bottom, right: r.right,
        height: window.innerHeight, width: window.innerWidth};
"""


@dataclass
class Legibility:
    """What a reader of a ``width`` x ``height`` window sees too wide: images shown narrower than their
    pixels (scaled down: ``shrunk``, or wider than their container), tables wider than their container
    or running past the window, the page's horizontal overflow; and where the first table sits on the
    first screen (``first``: caption, top, bottom, right in px, before any scrolling)."""

    width: int
    page_width: int
    wide_images: list
    wide_tables: list
    first: dict | None


def legibility(path, width: int = 1400, height: int = 900, timeout: float = 60.0) -> Legibility:
    """Open ``path`` in a ``width`` x ``height`` headless Chromium window and measure it (:class:`Legibility`):
    the first screen before any click, then every ``<details>`` opened."""
    with Browser(timeout) as b:
        drv = b.driver
        drv.set_window_size(width, height)
        drv.get(Path(path).resolve().as_uri())
        inner = drv.execute_script("return [window.innerWidth, window.innerHeight];")
        # the window's outer size includes its frame: make the viewport itself width x height
        drv.set_window_size(width + (width - inner[0]), height + (height - inner[1]))
        drv.get(Path(path).resolve().as_uri())
        first = drv.execute_script(_FIRST)
        seen = drv.execute_script(_LEGIBILITY)
    wide_images = [i for i in seen["images"] if i["natural"] > i["container"] + 0.5 or i["shown"] < i["natural"] - 0.5]
    wide_tables = [t for t in seen["tables"] if t["width"] > t["container"] + 0.5 or t["right"] > seen["width"] + 0.5
                   or t["scroll"] > t["width"] + 0.5]
    return Legibility(int(seen["width"]), int(seen["page"]), wide_images, wide_tables, first)
