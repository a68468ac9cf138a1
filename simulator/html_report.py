"""A report's Markdown as one self-contained HTML page: every image the Markdown links (the
report's ``plots/*.png``) embedded as a base64 data URI, the style inline, nothing fetched, so
the one file opens in any browser and travels by mail. The reports are written as Markdown
(``simulator.scoring.report``, ``simulator.reproduce.report``); this module is the one home of
their HTML. The Markdown is read by markdown-it-py (CommonMark with tables).

Public names
------------
markdown_page, write_html_report.
"""

from __future__ import annotations

import base64
import html
import mimetypes
from collections.abc import Iterator, Mapping
from pathlib import Path

STYLE = """body{font-family:sans-serif;max-width:1200px;margin:auto;padding:1em;}
table{border-collapse:collapse;margin:0.5em 0;font-size:0.9em;}
td,th{border:1px solid #bbb;padding:4px 6px;vertical-align:top;text-align:left;}
th{background:#eee;} img{max-width:100%;} code{background:#f4f4f4;}"""


def _tokens(tokens: list) -> Iterator:
    for token in tokens:
        yield token
        yield from _tokens(token.children or [])


def _data_uri(path: Path) -> str:
    kind = mimetypes.guess_type(path.name)[0] or "application/octet-stream"
    return f"data:{kind};base64,{base64.b64encode(path.read_bytes()).decode('ascii')}"


def markdown_page(markdown_text: str, directory: Path,
                  word_classes: Mapping[str, str] | None = None) -> str:
    """The HTML page of ``markdown_text``, whose relative image links are files under
    ``directory``; its title is the first heading. ``word_classes`` gives a bold word a CSS
    class with its colour, e.g. ``{"shown": "color:#1b6e20"}`` (the reproduction's verdicts).

    Raises
    ------
    FileNotFoundError
        When an image the Markdown links is missing.
    """
    from markdown_it import MarkdownIt  # imported here: only a report being written needs it

    md = MarkdownIt("commonmark", {"html": False}).enable("table")
    tokens = md.parse(markdown_text)
    title = "landnav report"
    for i, token in enumerate(tokens):
        if token.type == "heading_open" and i + 1 < len(tokens):
            title = tokens[i + 1].content
            break
    for token in _tokens(tokens):
        if token.type == "image":
            src = str(token.attrGet("src") or "")
            if src and ":" not in src.split("/")[0]:  # a relative file, not a URI
                token.attrSet("src", _data_uri(directory / src))
    body = md.renderer.render(tokens, md.options, {})
    style = STYLE
    for n, (word, css) in enumerate((word_classes or {}).items()):
        body = body.replace(f"<strong>{html.escape(word)}</strong>",
                            f"<strong class='w{n}'>{html.escape(word)}</strong>")
        style += f"\n.w{n}{{{css};}}"
    return ("<!DOCTYPE html>\n<html><head><meta charset='utf-8'>"
            f"<title>{html.escape(title)}</title><style>{style}</style></head>\n<body>\n"
            f"{body}</body></html>\n")


def write_html_report(markdown_path: Path,
                      word_classes: Mapping[str, str] | None = None) -> Path:
    """Write ``report.html`` beside ``markdown_path`` (``report.md``), its images embedded;
    the path of the page."""
    markdown_path = Path(markdown_path)
    page = markdown_page(markdown_path.read_text(encoding="utf-8"), markdown_path.parent,
                         word_classes)
    out = markdown_path.with_suffix(".html")
    out.write_text(page, encoding="utf-8")
    return out
