"""The local help pages (core/jobs/help_pages.py): one per algorithm from its spec, an index
whose links all resolve, each file written whole."""

from __future__ import annotations

from html.parser import HTMLParser

import pytest
from lidarphoto.core.jobs import ALGORITHMS
from lidarphoto.core.jobs.help_pages import (
    INDEX_NAME,
    help_page,
    index_page,
    page_name,
    write_help_pages,
)

SPECS = [job.SPEC for job in ALGORITHMS]


class _Links(HTMLParser):
    """The href of every link, and the tags left open (a broken page)."""

    VOID = frozenset({"meta", "br", "img", "hr", "link", "input"})

    def __init__(self) -> None:
        super().__init__()
        self.links: list[str] = []
        self.open: list[str] = []

    def handle_starttag(self, tag, attrs):
        if tag == "a":
            self.links.append(dict(attrs)["href"])
        if tag not in self.VOID:
            self.open.append(tag)

    def handle_endtag(self, tag):
        assert self.open and self.open[-1] == tag, (tag, self.open[-3:])
        self.open.pop()


def _parse(text: str) -> _Links:
    parser = _Links()
    parser.feed(text)
    parser.close()
    assert parser.open == [], parser.open
    return parser


@pytest.mark.parametrize("spec", SPECS, ids=lambda s: s.name)
def test_a_page_holds_the_help_and_every_parameter(spec):
    page = help_page(spec, spec.help_html())
    _parse(page)
    assert page.startswith("<!DOCTYPE html>") and '<meta charset="utf-8">' in page
    assert f"lidarphoto:{spec.name}" in page and f"lidarphoto {spec.name} --help" in page
    for p in spec.params:
        assert f"<b>{p.name}</b>" in page, p.name


def test_the_index_links_every_page_and_the_files_are_written_whole(tmp_path):
    pages = {page_name(s): help_page(s, s.help_html()) for s in SPECS}
    pages[INDEX_NAME] = index_page([(s, s.title, s.group) for s in SPECS])
    write_help_pages(tmp_path / "help", pages)
    written = sorted(p.name for p in (tmp_path / "help").iterdir())
    assert written == sorted(pages)  # no temporary left
    index = _parse((tmp_path / "help" / INDEX_NAME).read_text(encoding="utf-8"))
    assert sorted(index.links) == sorted(page_name(s) for s in SPECS)
    for s in SPECS:  # every page links back to the index
        assert _parse(pages[page_name(s)]).links[0] == INDEX_NAME
        assert (tmp_path / "help" / page_name(s)).read_text(encoding="utf-8") == pages[page_name(s)]


def test_a_translated_page_says_its_language():
    spec = SPECS[0]
    words = {"Run it": "Executar"}
    page = help_page(spec, "<p>x</p>", "Título", lambda s: words.get(s, s), "pt_BR")
    assert '<html lang="pt-BR">' in page and "<h1>Título</h1>" in page
    assert "Executar" in page
