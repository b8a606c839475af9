"""Search results with snippets when the book is read offline from disk (``file://``).

Sphinx's search page shows a snippet under each result by fetching the result's HTML page
(``searchtools.js``, ``fetch(requestUrl)``). A browser refuses ``fetch`` of a ``file://`` URL, so
a reader who opens the downloaded book from disk — the common case in a course, on a phone, on a
train — gets titles without any text. This extension writes each page's visible text (its main
content without code-cell inputs, scripts, styles and header links) into
``_static/hsgeo_search_texts.js`` at the end of the build, and gives the search page (only it)
``_static/hsgeo_search_offline.js``, which answers the search's ``fetch`` of a page from those
texts when the page is read from disk. Served over HTTP nothing changes: the real ``fetch`` runs.

Why our own code: Sphinx has no offline-summary option, and no maintained extension does this for
Sphinx 7 / the book theme (a search engine such as lunr or pagefind would replace Sphinx's
ranking, which works offline already; only the snippets fail).
"""

from __future__ import annotations

import json
from pathlib import Path

from sphinx.application import Sphinx
from sphinx.util import logging

LOGGER = logging.getLogger(__name__)

TEXTS_JS = "hsgeo_search_texts.js"
OFFLINE_JS = "hsgeo_search_offline.js"

#: Answers searchtools.js's fetch of a page from the embedded texts when read from disk.
_OFFLINE_SOURCE = r"""// hsgeo: search snippets offline (book/_ext/hsgeo_search.py)
(function () {
  if (window.location.protocol !== "file:") return;
  const realFetch = window.fetch ? window.fetch.bind(window) : null;
  const root = new URL(document.documentElement.dataset.content_root || "./", window.location.href);
  window.fetch = function (input, init) {
    const texts = window.HSGEO_SEARCH_TEXTS || {};
    try {
      const url = new URL(typeof input === "string" ? input : input.url, window.location.href);
      let doc = decodeURIComponent(url.pathname).replace(/\.html$/, "");
      const base = decodeURIComponent(root.pathname);
      if (doc.startsWith(base)) doc = doc.slice(base.length);
      if (Object.prototype.hasOwnProperty.call(texts, doc)) {
        const main = document.createElement("div");
        main.setAttribute("role", "main");
        main.textContent = texts[doc];
        return Promise.resolve(new Response(main.outerHTML,
          { status: 200, headers: { "Content-Type": "text/html" } }));
      }
    } catch (e) { /* fall through to the real fetch */ }
    return realFetch ? realFetch(input, init) : Promise.reject(new Error("no fetch"));
  };
})();
"""


def page_text(html: str) -> str:
    """The text a reader sees in a built page's main content (``[role=main]``), without code
    inputs, scripts, styles and header links, whitespace collapsed.

    >>> page_text('<div role="main"><h1>MTF<a class="headerlink">¶</a></h1>'
    ...           '<div class="cell_input">x = 1</div><p>The  edge.</p></div>')
    'MTF The edge.'
    """
    from bs4 import BeautifulSoup

    soup = BeautifulSoup(html, "html.parser")
    main = soup.find(attrs={"role": "main"}) or soup.body or soup
    for el in main.select("script, style, .headerlink, div.cell_input, mjx-assistive-mml"):
        el.decompose()
    return " ".join(main.get_text(" ").split()).replace(" .", ".").replace(" ,", ",")


def _add_offline_script(app: Sphinx, pagename: str, templatename, context, doctree) -> None:
    if pagename == "search":  # added in html-page-context: this page only
        app.add_js_file(TEXTS_JS)
        app.add_js_file(OFFLINE_JS)


def _write_texts(app: Sphinx, exception: Exception | None) -> None:
    if exception is not None or app.builder.format != "html":
        return
    out = Path(app.outdir)
    texts = {}
    for docname in sorted(app.env.found_docs):
        page = out / f"{docname}.html"
        if page.is_file():
            texts[docname] = page_text(page.read_text(encoding="utf-8"))
    static = out / "_static"
    static.mkdir(exist_ok=True)
    payload = json.dumps(texts, ensure_ascii=False, separators=(",", ":"))
    (static / TEXTS_JS).write_text(f"window.HSGEO_SEARCH_TEXTS = {payload};\n", "utf-8")
    (static / OFFLINE_JS).write_text(_OFFLINE_SOURCE, "utf-8")
    LOGGER.info(f"[hsgeo] search snippets offline: {len(texts)} pages, {len(payload) / 1e6:.1f} MB")


def setup(app: Sphinx) -> dict:
    app.connect("html-page-context", _add_offline_script)
    app.connect("build-finished", _write_texts)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
