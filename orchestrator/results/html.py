"""One self-contained HTML page per report (issue 23 item 4).

    page = Page("Paper 000: reproduction of section 5", base=folder)
    page.add_text("Runs of the shipped scenarios.")
    page.add_table(df, caption="Runs", units={"final_rate_error": "rad/s"})
    page.add_figure("fig6_omega_estimate.png", caption="000 Fig. 6")   # or a matplotlib Figure
    page.add_markdown(md)            # Markdown prose and tables (markdown-it-py, raw HTML escaped)
    page.write(folder / "report.html")  # atomic

The page is rendered from the jinja2 template ``templates/page.html.j2``; tables come from pandas
DataFrames through ``Styler.to_html`` (cells and headers HTML-escaped, units in the column headers
as ``name [unit]``); figures are embedded as base64 data URIs (PNG, and SVG as an image, so no
script inside an SVG runs), so the page opens anywhere without its folder.

:func:`markdown_table` gives the same DataFrame as a valid GitHub-flavoured Markdown table
(``|`` and line breaks escaped in cells) for the ``report.md`` beside the page.

Data is hostile (folder names, campaign descriptions, units, metric names may hold anything): every
link and image source of a page goes through one sanitiser, :func:`safe_href`. It keeps relative
paths that stay inside the report folder once symbolic links are followed (and ``#anchors``), and
refuses everything else: a scheme (``javascript:``, ``data:``, ``http:``, ``file:``), an absolute path,
``..`` out of the folder, control characters. Links built from names (the results index) are made
with :func:`relative_href`, which percent-encodes each name, so a folder named
``javascript:alert(1)`` is the relative link ``./javascript%3Aalert%281%29/``. Markdown links and
images are held to the same rule (a refused one is shown as text). Text in figures built from data
is drawn as plain text (:func:`plain_text`: no mathtext, whose parser fails on a ``$`` in a unit).
"""
from __future__ import annotations

import base64
import contextlib
import html
import io
import math
import os
import re
import tempfile
import urllib.parse
from importlib import metadata
from pathlib import Path

import jinja2
import numpy as np
import pandas as pd
from markdown_it import MarkdownIt
from markupsafe import Markup

from plant import units

__all__ = ["Page", "markdown_table", "with_units", "format_cell", "write_text_atomic", "safe_href", "relative_href",
           "plain_text", "unit_tag", "spell_units"]

_ENV = jinja2.Environment(loader=jinja2.FileSystemLoader(Path(__file__).parent / "templates"),
                          autoescape=jinja2.select_autoescape(["html", "j2"]), keep_trailing_newline=True)
_MIME = {".png": "image/png", ".svg": "image/svg+xml", ".jpg": "image/jpeg", ".jpeg": "image/jpeg"}
_ANCHOR = re.compile(r"[^a-z0-9]+")


def safe_href(href, base=None) -> str | None:
    """``href`` if it is a relative path that stays inside the folder ``base`` (symbolic links
    followed; without ``base`` lexically) or a ``#fragment``, else None (see the module docstring)."""
    if not isinstance(href, str) or not href or any(not c.isprintable() for c in href):
        return None
    if href.startswith("#"):
        return href if re.fullmatch(r"#[A-Za-z0-9_.-]*", href) else None
    parts = urllib.parse.urlsplit(href)
    if parts.scheme or parts.netloc or href.startswith(("/", "\\")) or "\\" in href:
        return None
    path = urllib.parse.unquote(parts.path)
    if not path or path.startswith("/") or "\x00" in path:
        return None
    rel = os.path.normpath(path)
    if rel == ".." or rel.startswith("../"):
        return None
    if base is not None:
        root = os.path.realpath(base)
        target = os.path.realpath(os.path.join(root, rel))
        if os.path.commonpath([root, target]) != root:
            return None
    return href if href.startswith("./") else "./" + href


def relative_href(*names, folder: bool = False) -> str:
    """A relative link to ``names`` (path components, e.g. a folder name read from disk) below the
    page's folder, each percent-encoded: no name can become a scheme, a host or a climb out."""
    # the name's bytes on disk, percent-encoded (a name that is not UTF-8 links to itself too)
    quoted = [urllib.parse.quote(os.fsencode(str(n)), safe="") for n in names if str(n) not in ("", ".", "..")]
    return "./" + "/".join(quoted) + ("/" if folder else "")


def plain_text(fig):
    """``fig`` with every text in it (labels, titles, legends, ticks) drawn as plain text: matplotlib's
    mathtext off, so a ``$`` in a unit, a metric or a scenario name is a dollar sign, not a formula
    that fails to parse when the figure is saved; a log axis's numbers, which matplotlib writes in mathtext,
    are written plain (``1e-3``). Call it before ``savefig``; returns ``fig``."""
    from matplotlib.text import Text
    from matplotlib.ticker import LogFormatter, LogFormatterMathtext

    for ax in fig.axes:  # numbers a log axis writes in mathtext ("$\\mathdefault{10^{-3}}$"): the same, plain
        for axis in (ax.xaxis, ax.yaxis):
            for which in ("major", "minor"):
                f = getattr(axis, f"get_{which}_formatter")()
                if isinstance(f, LogFormatterMathtext):
                    plain = LogFormatter(base=f._base, labelOnlyBase=f.labelOnlyBase,
                                         minor_thresholds=f.minor_thresholds, linthresh=f._linthresh)
                    getattr(axis, f"set_{which}_formatter")(plain)
    for t in fig.findobj(Text):
        t.set_parse_math(False)
        t.set_usetex(False)
    return fig


def _version() -> str:
    try:
        return metadata.version("ftcsim")
    except metadata.PackageNotFoundError:  # pragma: no cover - a source checkout without install
        return "unknown"


def format_cell(x, digits: int = 4) -> str:
    """A table cell as text: numbers with ``digits`` significant digits, None / NaN as an em dash,
    booleans as yes / no, lists element-wise."""
    if x is None or x is pd.NA or x is pd.NaT:
        return "—"
    if isinstance(x, (bool, np.bool_)):
        return "yes" if x else "no"
    if isinstance(x, (int, np.integer)):
        return str(int(x))
    if isinstance(x, (float, np.floating)):
        return "—" if math.isnan(x) else (f"{x:.{digits}g}" if math.isfinite(x) else str(float(x)))
    if isinstance(x, (list, tuple, np.ndarray)):
        return "[" + ", ".join(format_cell(v, digits) for v in x) + "]"
    return str(x)


_UNIT_TAG = re.compile(r"\{unit:([^{}]*)\}")


def unit_tag(unit: str) -> str:
    """A unit inside text given to a :class:`Page` or a Markdown table: spelled for the page
    (``N²·m²·s``) in HTML, in the file spelling (``N2.m2.s``) in Markdown (:func:`spell_units`)."""
    return "{unit:" + str(unit) + "}"


def spell_units(text: str, pretty: bool) -> str:
    """``text`` with every :func:`unit_tag` and every unit in square brackets (a label's ``[N.m]``,
    :func:`plant.units.respell_bracketed`) spelled for a page (``pretty``) or a file."""
    spell = units.pretty if pretty else units.ucum
    return units.respell_bracketed(_UNIT_TAG.sub(lambda m: spell(m.group(1)), str(text)), pretty)


def with_units(df: pd.DataFrame, units_of: dict | None, pretty: bool = False) -> pd.DataFrame:
    """A copy of ``df`` whose column headers carry their unit as ``name [unit]`` (empty units:
    the name alone), spelled for a page (``pretty``: ``N·m``) or a file (``N.m``,
    :mod:`plant.units`)."""
    if not units_of:
        units_of = {}
    spell = units.pretty if pretty else units.ucum
    named = {c: f"{c} [{spell(units_of[c])}]" for c in df.columns if units_of.get(c)}
    return df.rename(columns={c: spell_units(named.get(c, c), pretty) for c in df.columns if isinstance(c, str)})


def markdown_table(df: pd.DataFrame, units: dict | None = None, digits: int = 4, index: bool = False) -> str:
    """``df`` as a GitHub-flavoured Markdown table; ``|`` in a cell is escaped and line breaks become
    spaces, so the table stays one table whatever the cells hold."""
    d = with_units(df, units)
    if index:
        d = d.reset_index()

    def cell(x) -> str:
        text = spell_units(format_cell(x, digits), pretty=False)
        return text.replace("\\", "\\\\").replace("|", "\\|").replace("\r", " ").replace("\n", " ")

    head = "| " + " | ".join(cell(c) for c in d.columns) + " |"
    rule = "|" + "---|" * len(d.columns)
    rows = ["| " + " | ".join(cell(x) for x in row) + " |" for row in d.itertuples(index=False, name=None)]
    return "\n".join([head, rule, *rows]) + "\n"


def write_text_atomic(path, text: str) -> None:
    """``text`` (UTF-8) into ``path`` through a temporary file in the same folder, flushed and
    renamed: a reader sees the old file or the whole new one, never a part. A file name that is not
    UTF-8 (its undecodable bytes held as surrogates) is written as backslash escapes."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    umask = os.umask(0)
    os.umask(umask)
    try:
        os.chmod(tmp, 0o666 & ~umask)
        with os.fdopen(fd, "w", encoding="utf-8", errors="backslashreplace") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def _data_uri(data: bytes, mime: str) -> str:
    return f"data:{mime};base64," + base64.b64encode(data).decode("ascii")


class Page:
    """A report page: blocks (headings, text, Markdown, tables, figures, links) in order; see the
    module docstring. ``base`` is the folder relative figure paths (and Markdown images) are read
    from; a path that leaves it is refused (ValueError)."""

    def __init__(self, title: str, base=None):
        self.title = str(title)
        self.base = Path(base) if base is not None else None
        self.blocks: list[str] = []
        self.figures = 0
        self.tables = 0
        self._md = MarkdownIt("commonmark", {"html": False}).enable("table")
        # a Markdown link or image from data is a link only if the sanitiser keeps it (else its text stays)
        # no scheme, no host, no absolute path parsed as a link at all; the render rules below then keep a
        # link or an image only if it stays inside the report folder (a refused image says so)
        self._md.validateLink = lambda url: not (urllib.parse.urlsplit(url).scheme or url.startswith(("/", "\\"))
                                                 or "\\" in url or not url.isprintable())
        self._md.add_render_rule("image", lambda _renderer, tokens, idx, options, env: self._md_image(tokens[idx]))
        self._md.add_render_rule("link_open", lambda renderer, tokens, idx, options, env:
                                 self._md_link(renderer, tokens, idx, options, env))

    # -- blocks -------------------------------------------------------------------------------
    def add_heading(self, text: str, level: int = 2) -> Page:
        level = min(max(int(level), 2), 6)
        text = spell_units(text, pretty=True)
        anchor = _ANCHOR.sub("-", str(text).lower()).strip("-")
        self.blocks.append(f'<h{level} id="{html.escape(anchor)}">{html.escape(str(text))}</h{level}>')
        return self

    def add_text(self, text: str, small: bool = False) -> Page:
        """A paragraph of plain text (escaped; blank lines separate paragraphs); ``small``: in the
        page's small print (legends, notes)."""
        tag = '<p class="small">' if small else "<p>"
        for para in re.split(r"\n\s*\n", spell_units(text, pretty=True).strip()):
            if para:
                self.blocks.append(f"{tag}{html.escape(para)}</p>")
        return self

    def add_items(self, items) -> Page:
        """A compact bulleted list of plain-text items (escaped)."""
        lis = "".join(f"<li>{html.escape(str(x))}</li>" for x in items if str(x).strip())
        self.blocks.append(f'<ul class="items">{lis}</ul>')
        return self

    def add_markdown(self, md: str) -> Page:
        """Markdown (CommonMark with GFM tables; raw HTML is shown as text, not interpreted); images
        ``![caption](file.png)`` are embedded from ``base``."""
        self.blocks.append(self._md.render(spell_units(md, pretty=True)))
        return self

    def add_table(self, df: pd.DataFrame, caption: str | None = None, units: dict | None = None,
                  digits: int = 4, index: bool = False, failed_rows=None) -> Page:
        """``df`` as an HTML table (pandas Styler): ``units`` {column: unit} go into the headers,
        numbers get ``digits`` significant digits, missing values an em dash; ``failed_rows`` (a
        boolean sequence over the rows) marks rows drawn in the failure colour."""
        d = with_units(df, units, pretty=True)
        if not index:
            d = d.reset_index(drop=True)
        styler = d.style.format(lambda x: spell_units(format_cell(x, digits), pretty=True), escape="html")
        styler = styler.format_index(escape="html", axis=1).format_index(escape="html", axis=0)
        if not index:
            styler = styler.hide(axis="index")
        if caption:
            styler = styler.set_caption(html.escape(spell_units(caption, pretty=True)))
        if failed_rows is not None:
            styles = pd.DataFrame("", index=d.index, columns=d.columns)
            styles.iloc[np.flatnonzero(np.asarray(failed_rows, dtype=bool)), :] = "color: #a00000"
            styler = styler.apply(lambda _: styles, axis=None)
        self.blocks.append(styler.to_html(table_attributes='class="data"'))
        self.tables += 1
        return self

    def add_figure(self, fig, caption: str | None = None, alt: str | None = None) -> Page:
        """A matplotlib Figure (rendered to PNG) or an image file (PNG, JPEG, SVG; relative to
        ``base``), embedded as a data URI."""
        if hasattr(fig, "savefig"):
            buf = io.BytesIO()
            plain_text(fig).savefig(buf, format="png", dpi=110)
            uri, name = _data_uri(buf.getvalue(), "image/png"), caption or "figure"
        else:
            path = self._resolve(fig)
            mime = _MIME.get(path.suffix.lower())
            if mime is None:
                raise ValueError(f"{path}: not an image this page embeds (PNG, JPEG, SVG)")
            uri, name = _data_uri(path.read_bytes(), mime), path.name
        cap = f"<figcaption>{html.escape(str(caption))}</figcaption>" if caption else ""
        self.blocks.append(f'<figure><img src="{uri}" alt="{html.escape(str(alt or caption or name))}">{cap}</figure>')
        self.figures += 1
        return self

    def add_links(self, links, caption: str | None = None) -> Page:
        """A list of links [(text, href)] (hrefs relative to where the page is written, inside its
        folder: :func:`safe_href`; a refused one is listed as text)."""
        items = "".join(f'<li><a href="{html.escape(safe)}">{html.escape(str(t))}</a></li>'
                        if (safe := safe_href(h, self.base)) is not None else f"<li>{html.escape(str(t))}</li>"
                        for t, h in links)
        cap = f"<p>{html.escape(str(caption))}</p>" if caption else ""
        self.blocks.append(f"{cap}<ul>{items}</ul>")
        return self

    @contextlib.contextmanager
    def details(self, summary: str, open: bool = False):  # noqa: A002 - the HTML attribute's name
        """A collapsible section: the blocks added inside the ``with`` go under a ``<summary>`` line
        (escaped), shown when the reader opens it (or at once with ``open``)."""
        self.blocks.append(f"<details{' open' if open else ''}><summary>{html.escape(str(summary))}</summary>")
        try:
            yield self
        finally:
            self.blocks.append("</details>")

    # -- output -------------------------------------------------------------------------------
    def render(self) -> str:
        return _ENV.get_template("page.html.j2").render(
            title=self.title, blocks=[Markup(b) for b in self.blocks], version=_version())

    def write(self, path) -> Path:
        """The page into ``path``, atomically; returns the path."""
        write_text_atomic(path, self.render())
        return Path(path)

    # -- helpers ------------------------------------------------------------------------------
    def _resolve(self, path) -> Path:
        """An image file of the report folder: a relative path that :func:`safe_href` keeps (absolute
        paths, schemes, ``..`` and links out of the folder refused: ValueError)."""
        if self.base is None:
            raise ValueError(f"{path}: a figure path needs the page's base folder")
        if safe_href(str(path), self.base) is None:
            raise ValueError(f"{path}: leaves the report folder {self.base} (or is not a relative path)")
        p = Path(os.path.realpath(self.base / urllib.parse.unquote(str(path))))
        if not p.is_file():
            raise ValueError(f"{path}: no such image in {self.base}")
        return p

    def _md_link(self, renderer, tokens, idx, options, env) -> str:
        """A Markdown link kept only if it stays in the report folder once links are followed."""
        tok = tokens[idx]
        if safe_href(tok.attrGet("href") or "", self.base) is None:
            tok.attrs.pop("href", None)
        return renderer.renderToken(tokens, idx, options, env)

    def _md_image(self, tok) -> str:
        src = tok.attrGet("src") or ""
        alt = "".join(c.content for c in (tok.children or []))
        try:
            path = self._resolve(src)
            mime = _MIME.get(path.suffix.lower())
            if mime is None or not path.is_file():
                raise ValueError(src)
            uri = _data_uri(path.read_bytes(), mime)
        except (ValueError, OSError):
            return f"<em>[figure {html.escape(src)} not found]</em>"
        self.figures += 1
        return f'<img src="{uri}" alt="{html.escape(alt)}">'
