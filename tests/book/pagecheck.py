"""What a reader sees on a built page, measured in a real browser, and the checks on it.

:func:`page_facts` opens one HTML file from disk (``file://``) in a Playwright browser context
with every non-``file:`` request blocked, waits for MathJax to finish typesetting and collects
the facts the checks need in one pass. Each ``problems_*`` function returns a list of readable
problems (empty when the page passes), so that a failing test names the page and the element.
"""

from __future__ import annotations

import re
from pathlib import Path
from urllib.parse import unquote, urlparse

from hsgeo.report import MAX_PANEL_COLUMNS, PANEL_COLUMNS_KEY

#: Viewport widths (px) of a phone and of a desktop screen.
NARROW_PX = 400
WIDE_PX = 1400
#: The most rows a table a reader sees may have (a longer one goes under a toggle, issue 40).
MAX_TABLE_ROWS = 20
#: The width (px) of an A4 page's text in print: 210 mm less 10 mm margins each side, 96 px/in.
PRINT_PX = 718
#: The least width (px) of a figure's panel as shown at 400 px (the panel grid and its limit,
#: ``PANEL_COLUMNS_KEY`` and ``MAX_PANEL_COLUMNS``, are hsgeo.report's, which records it).
MIN_PANEL_PX = 150
#: The most words of a paper's statement on the scoreboard and the landing page.
MAX_STATEMENT_WORDS = 80

# One pass over the page, after MathJax: everything below is measured, nothing is inferred.
_FACTS_JS = r"""
async () => {
  const MAX_ROWS = __MAX_ROWS__;
  if (window.MathJax && MathJax.startup && MathJax.startup.promise) {
    await MathJax.startup.promise;
  }
  const main = document.querySelector("main") || document.body;
  const describe = (el) => {
    let s = el.tagName.toLowerCase();
    if (el.id) s += "#" + el.id;
    if (el.className && typeof el.className === "string") {
      s += "." + el.className.trim().split(/\s+/).slice(0, 3).join(".");
    }
    const text = (el.textContent || "").trim().replace(/\s+/g, " ").slice(0, 60);
    return text ? s + " «" + text + "»" : s;
  };
  // visible prose: the main content without code, scripts and MathJax's own output
  const clone = main.cloneNode(true);
  clone.querySelectorAll("pre, code, script, style, mjx-container, mjx-assistive-mml, textarea")
    .forEach((el) => el.remove());
  const prose = clone.textContent || "";
  const raw_tex = [];
  for (const token of ["\\(", "\\)", "\\[", "\\]", "$$"]) {
    let i = prose.indexOf(token);
    if (i >= 0) raw_tex.push(prose.slice(Math.max(0, i - 30), i + 40).replace(/\s+/g, " "));
  }
  const images = [...main.querySelectorAll("img, svg.figure, figure")].filter(
    (el) => el.tagName.toLowerCase() !== "figure"
  );
  const uncaptioned = [];
  for (const img of images) {
    if (img.closest("mjx-container, .admonition-title, .sd-card-header, button, a.headerlink")) {
      continue;
    }
    const fig = img.closest("figure");
    const caption = fig && fig.querySelector("figcaption");
    if (!caption || !caption.textContent.trim()) {
      uncaptioned.push(describe(img.closest(".cell") || img) + " " + (img.src || ""));
    }
  }
  // images a screen reader cannot describe: no alt text, or a file path as alt text
  const no_alt = [];
  for (const img of main.querySelectorAll("img")) {
    if (img.closest("mjx-container, button, a.headerlink")) continue;
    const alt = (img.getAttribute("alt") || "").trim();
    // a path: one word with a slash, or a file name (a caption may hold "E/N" or "MTF/CTF")
    if (!alt || /^\S*[\/\\]\S*$|\.(png|svg|jpe?g)$/i.test(alt)) {
      no_alt.push(describe(img.closest("figure") || img) + " alt «" + alt.slice(0, 40) + "»");
    }
  }
  const figures = main.querySelectorAll("figure").length;
  const nan_cells = [];
  for (const cell of main.querySelectorAll("table td, table th")) {
    if (/(^|[^A-Za-z])nan([^A-Za-z]|$)/i.test(cell.textContent)) {
      const table = cell.closest("table");
      nan_cells.push(describe(table) + ": " + cell.textContent.trim().slice(0, 40));
    }
  }
  const width = window.innerWidth;
  const too_wide = [];
  for (const el of document.querySelectorAll("body *")) {
    const r = el.getBoundingClientRect();
    if (r.width > 0 && r.right > width + 1 && getComputedStyle(el).position !== "fixed") {
      // report the outermost offender only
      const parent = el.parentElement;
      if (parent && parent.getBoundingClientRect().right > width + 1) continue;
      too_wide.push(describe(el) + " right=" + Math.round(r.right));
    }
  }
  const clipped = [];
  const boxes = main.querySelectorAll(
    "pre, table, .cell_output, .cell_output .output, div.math, mjx-container[display='true'], " +
    ".highlight, .pst-scrollable-table-container"
  );
  for (const el of boxes) {
    if (el.closest("details:not([open])") || el.offsetParent === null) continue;
    const style = getComputedStyle(el);
    const overflowing = el.scrollWidth > el.clientWidth + 1;
    if (overflowing && !["auto", "scroll"].includes(style.overflowX)) {
      // content wider than its box and the box neither scrolls nor lets it show
      clipped.push(describe(el) + " content " + el.scrollWidth + " px in " + el.clientWidth
        + " px, overflow-x " + style.overflowX);
    }
  }
  // what leaks from the machinery into what a reader sees (issue 28): the prose and the cell
  // outputs, not the (collapsed) code of the cells
  const visible = main.cloneNode(true);
  visible.querySelectorAll("div.cell_input, script, style, mjx-container, mjx-assistive-mml, "
    + "textarea, .hsgeo-run-box").forEach((el) => el.remove());
  const seen = (visible.textContent || "").replace(/\s+/g, " ");
  const leaks = [];
  const leakPatterns = [
    [/np\.(float|int|bool_)\d*\(/, "a numpy repr"],
    [/\/tmp\//, "a /tmp/ path"],
    [/\bissues? #?\d+/i, "an issue number"],
    [/\b[A-Z][A-Za-z]*Warning\b/, "a Python warning"],
    [/Traceback \(most recent call last\)/, "a traceback"],
  ];
  for (const [re, what] of leakPatterns) {
    const m = seen.match(re);
    if (m) {
      const i = m.index;
      leaks.push(what + ": …" + seen.slice(Math.max(0, i - 40), i + 50) + "…");
    }
  }
  for (const el of main.querySelectorAll(".cell_output .output.stderr")) {
    leaks.push("stderr output: " + describe(el));
  }
  // glue slips in running text: a repeated word ("Exercise Exercise"), a range with equal ends
  const slips = [];
  const textEls = main.querySelectorAll(
    "p, li, figcaption, dt, dd, h1, h2, h3, h4, td, th, .admonition-title, caption");
  for (const el of textEls) {
    if (el.closest("div.cell_input, pre, .highlight")) continue;
    const c = el.cloneNode(true);
    c.querySelectorAll("code, pre, mjx-container, mjx-assistive-mml, script")
      .forEach((x) => x.remove());
    // only the element's own text, not that of a nested paragraph or list (checked by itself)
    c.querySelectorAll("p, li, ul, ol, dl, table").forEach((x) => x.remove());
    const t = (c.textContent || "").replace(/\s+/g, " ");
    const rep = t.match(/\b([A-Za-z]{2,})\s+\1\b/i);
    if (rep) slips.push("repeated word «" + rep[0] + "» in " + describe(el));
    const range = t.match(/(?<![\d.,])(\d+(?:\.\d+)?)\s*(?:–|to)\s*\1(?![\d.]*\d)/);
    if (range) slips.push("range with equal ends «" + range[0] + "» in " + describe(el));
    // the machinery's words in what a reader reads: the developers' guide, internal keys
    // (lever_arm_m[z_m]), a hyphen-minus for a minus sign (−0.8, not -0.8)
    const guide = t.match(/\bGUIDE\b.{0,20}/);
    if (guide) slips.push("the developers' GUIDE «" + guide[0] + "» in " + describe(el));
    const key = t.match(/\b[a-z][a-z0-9]*_[a-z0-9_]*\[[^\]\s]+\]/);
    if (key) slips.push("an internal key «" + key[0] + "» in " + describe(el));
    // (not in a pandas table a chapter prints as it is: only hsgeo's own tables are typeset)
    const typeset = !el.closest("table") || el.closest("table.hsgeo-table");
    const minus = typeset && t.match(/(?:^|[\s(\[=:,;])-\d[\d.]*/);
    if (minus) slips.push("a hyphen for a minus «" + minus[0].trim() + "» in " + describe(el));
  }
  // table cells whose text would touch their neighbour's: no horizontal padding
  const unpadded = [];
  let cells = 0;
  for (const cell of main.querySelectorAll("table td, table th")) {
    if (cell.closest("pre, .highlight, mjx-container") || cell.offsetParent === null) continue;
    if (!(cell.textContent || "").trim()) continue;
    cells += 1;
    const st = getComputedStyle(cell);
    const left = parseFloat(st.paddingLeft), right = parseFloat(st.paddingRight);
    if (!(left >= 2 && right >= 2)) {
      unpadded.push(describe(cell.closest("table")) + ": cell «"
        + cell.textContent.trim().slice(0, 30) + "» padding " + left + "/" + right + " px");
    }
  }
  // result tables (hsgeo.report, class hsgeo-table) that hide a column beyond a sideways scroll
  const hidden_columns = [];
  let result_tables = 0;
  for (const table of main.querySelectorAll("table.hsgeo-table")) {
    if (table.offsetParent === null) continue;
    result_tables += 1;
    const box = table.getBoundingClientRect();
    const beyond = [...table.querySelectorAll("td")].filter((td) => {
      const r = td.getBoundingClientRect();
      return r.width > 0 && (r.right > box.right + 1 || r.right > width + 1);
    });
    if (table.scrollWidth > table.clientWidth + 1 || beyond.length) {
      hidden_columns.push(describe(table) + ": " + table.scrollWidth + " px wide in "
        + table.clientWidth + " px; cells beyond: " + beyond.length
        + (beyond.length ? " (first «" + beyond[0].textContent.trim().slice(0, 30) + "», column «"
          + (beyond[0].getAttribute("data-label") || "?") + "»)" : ""));
    }
  }
  // tables wider than the column of text they sit in (on a wide screen and in print, where a
  // sideways scroll cannot be printed): measured against the article, not the scroll box
  const wide_tables = [];
  for (const table of main.querySelectorAll("table")) {
    if (table.closest("pre, .highlight, mjx-container") || table.offsetParent === null) continue;
    const column = (table.closest("article") || main).getBoundingClientRect();
    const r = table.getBoundingClientRect();
    // the table itself may be the scroll box (the theme makes tables display: block)
    const content = Math.max(r.width, table.scrollWidth);
    if (r.width > 0 && (r.left + content > column.right + 1)) {
      wide_tables.push(describe(table) + ": " + Math.round(content) + " px wide, "
        + Math.round(r.left + content - column.right) + " px beyond its column");
    }
  }
  // long tables and empty columns (issue 40): a table a reader sees (not one under a toggle,
  // <details>, where a long table belongs) has at most MAX_ROWS rows, and no column whose every
  // cell is "—"
  const long_tables = [];
  const empty_columns = [];
  for (const table of main.querySelectorAll("table")) {
    if (table.closest("pre, .highlight, mjx-container")) continue;
    const body = [...table.querySelectorAll("tr")].filter((tr) => tr.querySelector("td"));
    if (!table.closest("details") && body.length > MAX_ROWS) {
      long_tables.push(describe(table) + ": " + body.length + " rows");
    }
    const heads = [...(table.querySelector("thead tr:last-child") || {children: []}).children]
      .map((th) => (th.textContent || "").trim());
    const n = Math.max(0, ...body.map((tr) => tr.children.length));
    for (let j = 0; j < n && body.length; j++) {
      const vals = body.map((tr) => ((tr.children[j] || {}).textContent || "").trim());
      if (vals.every((v) => v === "—")) {
        empty_columns.push(describe(table) + ": column «" + (heads[j] || j) + "» is all —");
      }
    }
  }
  // every "differs" with a cause: in a table with a verdict column and a reason column (why,
  // reason, cause), a row judged "differs" gives more than its distance from the paper
  const uncaused = [];
  for (const table of main.querySelectorAll("table")) {
    const heads = [...(table.querySelector("thead tr:last-child") || {children: []}).children]
      .map((th) => (th.textContent || "").trim().toLowerCase());
    const iv = heads.indexOf("verdict");
    const iw = heads.findIndex((h) => /^(why|reason|cause)\b/.test(h));
    if (iv < 0 || iw < 0) continue;
    for (const tr of table.querySelectorAll("tr")) {
      const cells = tr.children;
      if (!tr.querySelector("td") || cells.length <= Math.max(iv, iw)) continue;
      if (!/^differs?\b/.test(cells[iv].textContent.trim())) continue;
      const why = cells[iw].textContent.trim();
      const bare = new RegExp("^(tuning missed:\\s*)?[\\d.]+σ̂? (off|from the paper)('s value)?"
        + "\\.?(\\s*\\([^)]*\\))?\\.?$");
      if (!why || why === "—" || bare.test(why)) {
        uncaused.push(describe(table) + ": «" + cells[0].textContent.trim().slice(0, 40)
          + "» differs, why «" + why.slice(0, 50) + "»");
      }
    }
  }
  // Python reprs in what a reader reads (prose and outputs, not the code cells)
  const reprs = [];
  for (const [re, what] of [
    [/\barray\(/, "a numpy array repr"], [/np\.(float|int)\d*\(/, "a numpy scalar repr"],
    [/<hsgeo\./, "an hsgeo object repr"], [/\{'/, "a dict repr"],
  ]) {
    const m = seen.match(re);
    if (m) reprs.push(what + ": …" + seen.slice(Math.max(0, m.index - 40), m.index + 50) + "…");
  }
  // the per-paper statements of the scoreboard and the landing page: words each
  const statements = [...main.querySelectorAll(".hsgeo-statement")].map((el) => {
    const t = (el.textContent || "").replace(/\s+/g, " ").trim();
    return {text: t.slice(0, 80), words: t ? t.split(" ").length : 0};
  });
  // the figures' images and their width as shown (the panel grid is read from the PNG)
  const figure_images = [...main.querySelectorAll("figure img")].map((img) => ({
    src: img.src, width: Math.round(img.getBoundingClientRect().width),
    text: describe(img.closest("figure") || img),
  }));
  const hrefs = [...document.querySelectorAll("a[href]")].map((a) => a.getAttribute("href"));
  const downloads = hrefs.filter((h) => /\.ipynb$/.test(h));
  const sources = hrefs.filter((h) => /_sources\/.*\.md$/.test(h));
  return {
    title: document.title,
    figure_images: figure_images,
    display_math: main.querySelectorAll("mjx-container[display='true']").length,
    long_tables: long_tables.slice(0, 8),
    wide_tables: wide_tables.slice(0, 8),
    empty_columns: empty_columns.slice(0, 8),
    uncaused: uncaused.slice(0, 8),
    reprs: reprs,
    statements: statements,
    math_sources: main.querySelectorAll(".math, span.math, div.math").length,
    mathjax_output: main.querySelectorAll("mjx-container").length,
    mathjax_src: [...document.querySelectorAll("script[src]")]
      .map((s) => s.getAttribute("src")).filter((s) => /mathjax/i.test(s)),
    raw_tex: raw_tex,
    images: images.length,
    figures: figures,
    uncaptioned: uncaptioned,
    no_alt: no_alt.slice(0, 8),
    nan_cells: nan_cells,
    scroll_width: document.scrollingElement.scrollWidth,
    inner_width: width,
    too_wide: too_wide.slice(0, 8),
    clipped: clipped.slice(0, 8),
    ipynb_links: downloads,
    md_links: sources,
    leaks: leaks,
    slips: slips.slice(0, 8),
    unpadded: unpadded.slice(0, 8),
    table_cells: cells,
    result_tables: result_tables,
    hidden_columns: hidden_columns.slice(0, 8),
    footer: [...document.querySelectorAll("footer, .bd-footer, .extra_footer")]
      .map((el) => el.textContent || "").join(" "),
    exercises: main.querySelectorAll(".exercise").length,
    solutions: main.querySelectorAll(".solution").length,
    // per-chapter numbering: the page's number and its figures', tables' and exercises' labels
    chapter_number: ((main.querySelector("h1 .section-number") || {}).textContent || "").trim(),
    caption_numbers: [...main.querySelectorAll(".caption-number")]
      .map((el) => (el.textContent || "").trim()).slice(0, 200),
  };
}
"""


def png_panel_columns(src: str) -> int | None:
    """The panel columns a PNG records (``hsgeo.report.PANEL_COLUMNS_KEY``, written by
    ``hsgeo.report.glue_figure``) from a ``file:`` or ``data:image/png;base64`` URL; None for
    another image or a PNG without the record.
    """
    import base64
    import io

    from PIL import Image

    if src.startswith("data:image/png;base64,"):
        data = io.BytesIO(base64.b64decode(src.split(",", 1)[1]))
    elif src.startswith("file:") and src.lower().endswith(".png"):
        data = Path(unquote(urlparse(src).path))
        if not data.is_file():
            return None
    else:
        return None
    with Image.open(data) as image:
        value = getattr(image, "text", {}).get(PANEL_COLUMNS_KEY)
    return int(value) if value and value.isdigit() else None


def page_facts(browser, path: Path, width_px: int, media: str = "screen") -> dict:
    """Open ``path`` offline at ``width_px`` and measure it (see the module docstring);
    ``media="print"`` lays it out as printed (at :data:`PRINT_PX`, an A4 page's text width).
    """
    context = browser.new_context(viewport={"width": width_px, "height": 900}, offline=True)
    blocked: list[str] = []
    failed: list[str] = []

    def route(request_route):
        url = request_route.request.url
        if url.startswith(("file:", "data:", "about:", "blob:")):
            request_route.continue_()
        else:
            blocked.append(url)
            request_route.abort()

    context.route("**/*", route)
    page = context.new_page()
    page.on(
        "requestfailed",
        lambda r: failed.append(r.url) if r.url.startswith("file:") else None,
    )
    try:
        page.emulate_media(media=media)
        page.goto(path.resolve().as_uri(), wait_until="load")
        facts = page.evaluate(_FACTS_JS.replace("__MAX_ROWS__", str(MAX_TABLE_ROWS)))
        page.wait_for_timeout(100)  # let late font and component loads report
    finally:
        context.close()
    for image in facts["figure_images"]:
        image["panel_columns"] = png_panel_columns(image["src"])
    facts["blocked"] = blocked
    facts["failed"] = failed
    facts["path"] = str(path)
    return facts


def problems_equations(facts: dict) -> list[str]:
    """Equations typeset by the local MathJax; no TeX source left in the visible text."""
    out = [f"raw TeX in the text: …{snippet}…" for snippet in facts["raw_tex"]]
    if facts["math_sources"] and facts["mathjax_output"] < facts["math_sources"]:
        out.append(
            f"{facts['math_sources']} equations but {facts['mathjax_output']} typeset by MathJax"
        )
    out += [
        f"MathJax not loaded from the book's own files: {s}"
        for s in facts["mathjax_src"]
        if "://" in s and not s.startswith("file:")
    ]
    return out


def problems_offline(facts: dict) -> list[str]:
    """Nothing requested from the network, no local file missing."""
    return [f"network request (blocked): {u}" for u in facts["blocked"]] + [
        f"missing file: {u}" for u in facts["failed"]
    ]


def problems_captions(facts: dict) -> list[str]:
    """Every image is part of a figure with a caption."""
    return [f"figure without caption: {d}" for d in facts["uncaptioned"]]


def problems_alt_text(facts: dict) -> list[str]:
    """Every image has an alt text that describes it (a figure's caption), not a file path."""
    return [f"image without a description: {d}" for d in facts["no_alt"]]


def problems_nan(facts: dict) -> list[str]:
    """No table cell shows NaN."""
    return [f"NaN in a table: {d}" for d in facts["nan_cells"]]


def problems_page_width(facts: dict) -> list[str]:
    """The page is not wider than the viewport (no sideways scrolling of the page)."""
    if facts["scroll_width"] <= facts["inner_width"]:
        return []
    return [
        f"page is {facts['scroll_width']} px wide in a {facts['inner_width']} px viewport",
        *[f"  too wide: {d}" for d in facts["too_wide"]],
    ]


def problems_clipped(facts: dict) -> list[str]:
    """Every box whose content is wider than itself scrolls."""
    return [f"clipped: {d}" for d in facts["clipped"]]


def _downloads(facts: dict, key: str, suffix: str) -> list[str]:
    if not facts[key]:
        return [f"no {suffix} download link"]
    base = Path(facts["path"]).parent
    out = []
    for href in facts[key]:
        target = (base / unquote(urlparse(href).path)).resolve()
        if not target.is_file():
            out.append(f"{suffix} link {href} resolves to a missing file {target}")
    return out


def problems_ipynb(facts: dict) -> list[str]:
    """The page offers an .ipynb download that exists next to it."""
    return _downloads(facts, "ipynb_links", ".ipynb")


def problems_md_source(facts: dict) -> list[str]:
    """The page offers its .md source (``_sources/…md``) and the file exists."""
    return _downloads(facts, "md_links", ".md")


def problems_exercises(facts: dict) -> list[str]:
    """At least one exercise and one solution."""
    out = []
    if facts["exercises"] < 1:
        out.append("no {exercise}")
    if facts["solutions"] < 1:
        out.append("no {solution}")
    return out


def problems_numbering(facts: dict) -> list[str]:
    """A chapter has its number, and its figures, tables and exercises are numbered within it
    ("Exercise 4.2" on chapter 4, not "Exercise 21" counted across the book)."""
    num = facts["chapter_number"].rstrip(".")
    if not num:
        return ["the chapter has no number (numbered: true on its part in book/_toc.yml)"]
    within = re.compile(rf"(?<![\d.]){re.escape(num)}\.\d+")
    bad = [c for c in facts["caption_numbers"] if not within.search(c)]
    return [f"numbered across the book, not within chapter {num}: «{c}»" for c in bad[:8]]


def problems_leaks(facts: dict) -> list[str]:
    """No machinery on the page: numpy reprs, /tmp/ paths, issue numbers, Python warnings,
    tracebacks or stderr output in the prose or the cell outputs."""
    return [f"leak, {d}" for d in facts["leaks"]]


def problems_glue_slips(facts: dict) -> list[str]:
    """No repeated word and no range whose two ends are equal in the running text."""
    return list(facts["slips"])


def problems_cell_padding(facts: dict) -> list[str]:
    """Every table cell has horizontal padding, so no cell's text touches its neighbour's."""
    return [f"unpadded: {d}" for d in facts["unpadded"]]


def problems_result_tables(facts: dict) -> list[str]:
    """Every result table (``hsgeo-table``) shows all its columns without a sideways scroll: on
    a phone each row is a card (book/_static/hsgeo.css), so σ̂, truth, z and the verdict stay in
    view.
    """
    return [f"result table hides columns: {d}" for d in facts["hidden_columns"]]


def problems_version_footer(facts: dict) -> list[str]:
    """The footer names the hsgeo version the book was built with."""
    import re

    if re.search(r"hsgeo \d+\.\d+", facts["footer"]):
        return []
    return [f"no hsgeo version in the footer: «{facts['footer'].strip()[:80]}»"]


def problems_display_equations(facts: dict, minimum: int = 2) -> list[str]:
    """At least ``minimum`` display equations typeset by MathJax (a chapter that teaches its
    equations shows them)."""
    if facts["display_math"] >= minimum:
        return []
    return [f"{facts['display_math']} typeset display equations, fewer than {minimum}"]


def problems_long_tables(facts: dict) -> list[str]:
    """No table in view longer than :data:`MAX_TABLE_ROWS` rows, none with an all-"—" column."""
    return [f"table too long: {d}" for d in facts["long_tables"]] + [
        f"empty column: {d}" for d in facts["empty_columns"]
    ]


def problems_reprs(facts: dict) -> list[str]:
    """No Python repr (``array(``, ``np.float64(``, ``<hsgeo.``, ``{'``) in what a reader reads."""
    return [f"Python repr, {d}" for d in facts["reprs"]]


def problems_differs_cause(facts: dict) -> list[str]:
    """Every row judged "differs" (in a table with a reason column) says why, not only how far."""
    return [f"differs without a cause: {d}" for d in facts["uncaused"]]


def problems_statements(facts: dict, minimum: int = 0) -> list[str]:
    """Each per-paper statement (``.hsgeo-statement``) has at most :data:`MAX_STATEMENT_WORDS`
    words, none is empty, and the page has at least ``minimum`` of them."""
    out = [
        f"statement of {s['words']} words (> {MAX_STATEMENT_WORDS}): «{s['text']}…»"
        for s in facts["statements"]
        if s["words"] > MAX_STATEMENT_WORDS
    ]
    out += ["an empty statement" for s in facts["statements"] if s["words"] == 0]
    if len(facts["statements"]) < minimum:
        out.append(f"{len(facts['statements'])} per-paper statements, fewer than {minimum}")
    return out


def problems_panels(facts: dict) -> list[str]:
    """No figure of more than :data:`MAX_PANEL_COLUMNS` panel columns, and on a narrow screen
    none whose panels are shown narrower than :data:`MIN_PANEL_PX` each (the panel grid as
    ``hsgeo.report.glue_figure`` recorded it in the PNG).
    """
    out = []
    for image in facts["figure_images"]:
        n = image.get("panel_columns")
        if not n:
            continue
        if n > MAX_PANEL_COLUMNS:
            out.append(f"{n} panel columns (> {MAX_PANEL_COLUMNS}): {image['text']}")
        elif facts["inner_width"] <= NARROW_PX and image["width"] / n < MIN_PANEL_PX:
            out.append(
                f"panels {image['width'] / n:.0f} px wide (< {MIN_PANEL_PX}): {image['text']}"
            )
    return out


def problems_wide_tables(facts: dict) -> list[str]:
    """No table wider than the column of text it sits in (a wide screen, a printed page)."""
    return [f"table wider than its column: {d}" for d in facts["wide_tables"]]
