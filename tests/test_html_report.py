"""The reports' self-contained HTML page (``simulator.html_report``): parsed with the standard
library's HTML parser, every plot the Markdown links is embedded byte for byte, nothing is
fetched from elsewhere, and the tables and text of the Markdown are there."""

from __future__ import annotations

import base64
import re
from html.parser import HTMLParser
from pathlib import Path

import pytest

from simulator.html_report import markdown_page, write_html_report

PNG = bytes.fromhex("89504e470d0a1a0a") + b"not really a picture, but bytes to carry"


class _Page(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.images: list[str] = []
        self.links: list[str] = []
        self.tags: list[str] = []
        self.text: list[str] = []

    def handle_starttag(self, tag: str, attrs: list) -> None:
        self.tags.append(tag)
        attrs = dict(attrs)
        if tag == "img":
            self.images.append(attrs.get("src") or "")
        for key in ("href", "src"):
            if key in attrs and tag != "img":
                self.links.append(attrs[key])

    def handle_data(self, data: str) -> None:
        self.text.append(data)


def parse(page: str) -> _Page:
    parser = _Page()
    parser.feed(page)
    parser.close()
    return parser


def check_report_html(directory: Path) -> _Page:
    """``directory/report.html`` holds every plot ``directory/report.md`` links, embedded with
    the PNG's own bytes, in the Markdown's order, and fetches nothing; returns the parsed
    page."""
    markdown = (directory / "report.md").read_text()
    page = parse((directory / "report.html").read_text())
    linked = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", markdown)
    assert linked, "the report links no plot"
    assert len(page.images) == len(linked)
    for src, path in zip(page.images, linked, strict=True):
        kind, _, data = src.partition(";base64,")
        assert kind == "data:image/png", src[:40]
        assert base64.b64decode(data) == (directory / path).read_bytes(), path
    assert not page.links and "script" not in page.tags and "link" not in page.tags
    assert page.tags.count("table") == sum(1 for line in markdown.splitlines()
                                           if re.fullmatch(r"\|(\s*-+\s*\|)+", line.strip()))
    return page


def test_markdown_page_embeds_images_and_renders_tables(tmp_path):
    (tmp_path / "plots").mkdir()
    (tmp_path / "plots" / "map.png").write_bytes(PNG)
    markdown = ("# Scores on q\n\nDrive: 193 s.\n\n| label | rms |\n|---|---|\n| a \\| b | 1.5 |\n"
                "\n## Map\n\n![Map](plots/map.png)\n\n**shown**: yes\n")
    (tmp_path / "report.md").write_text(markdown)
    out = write_html_report(tmp_path / "report.md", {"shown": "color:#1b6e20"})
    assert out == tmp_path / "report.html"
    page = check_report_html(tmp_path)
    text = "".join(page.text)
    assert "Scores on q" in text and "a | b" in text and "1.5" in text
    assert "<title>Scores on q</title>" in out.read_text()
    assert "<strong class='w0'>shown</strong>" in out.read_text()


def test_a_missing_plot_is_an_error_not_a_broken_page(tmp_path):
    with pytest.raises(FileNotFoundError):
        markdown_page("![Map](plots/none.png)\n", tmp_path)
