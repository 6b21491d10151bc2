"""MkDocs hooks of the documentation site (`hooks:` in mkdocs.yml): the pages that are not in docs/.

- `index.md` and `tutorial.md` are README.md, split at build time: the tutorial page is the
  README's sections in TUTORIAL_SECTIONS (now its "## Tutorial", headings one level up), the home
  page all the rest.
- `architecture.md`, `changelog.md` and `benchmarks.md` are ARCHITECTURE.md, CHANGELOG.md and
  benches/README.md as they are.
- `cli.md` is the `--help` of `latentrl` and of every subcommand, from `latentrl.cli.build_parser()`.

Links. Each page's relative links are written for the file the page comes from, as GitHub shows it
(README.md says `docs/tasks.md`, docs/tasks.md says `../python/latentrl/tasks/two_arms.toml`).
The hook reads every such link as a path in the repository and points it at that path's place in
the site: a page's page, a file under docs/ itself, and any other file of the repository (a task
file, an example, a sweep file) a copy of it under `repo/<its path>`. So the site needs no
repository host, it is whole offline, and `mkdocs build --strict` still fails on a link to a file
that does not exist (the link is left as written and MkDocs reports it). A link to a heading of
the other half of the README goes to that page.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import posixpath
import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from markdown.extensions.toc import slugify
from mkdocs.config.defaults import MkDocsConfig
from mkdocs.structure.files import File, Files
from mkdocs.structure.pages import Page

REPO = Path(__file__).resolve().parent.parent
DOCS = "docs"
TUTORIAL_SECTIONS = ("## Tutorial",)
"""The README's sections (h2 headings as they begin) that make the tutorial page."""
COPIES = "repo"
"""Where files of the repository outside docs/ that a page links to are copied in the site."""

README_PAGES = ("index.md", "tutorial.md")
OTHER_PAGES = {"ARCHITECTURE.md": "architecture.md", "CHANGELOG.md": "changelog.md",
               "benches/README.md": "benchmarks.md"}
"""Markdown files outside docs/ that are pages of the site: repository path → page."""

HELP_COLUMNS = "100"
"""Terminal width argparse formats the `--help` texts for, so the page is the same on any machine."""

# Inline code (left alone) or the start of an inline link or image, then its target.
LINK = re.compile(r"(?P<code>`+[^`]*?`+)|(?P<open>!?\[[^\]]*\]\()(?P<target>[^)\s]+)")
FENCE = re.compile(r"^(```|~~~)")
HEADING = re.compile(r"^(#{1,6})\s+(.*?)\s*#*\s*$")
EXTERNAL = re.compile(r"^([a-z][a-z0-9+.-]*:|/|#)", re.IGNORECASE)

_origin: dict[str, str] = {}
"""Page (src_uri) → the repository file its links are written for."""
_anchors: dict[str, set[str]] = {}
"""README page → the slugs of its headings, for links from one half of the README to the other."""


def on_config(config: MkDocsConfig, **kwargs: Any) -> MkDocsConfig:
    """Checks that the docs directory is the one beside this file (the paths above assume it)."""
    if Path(config.docs_dir).resolve() != REPO / DOCS:
        raise ValueError(f"docs_dir must be {REPO / DOCS}, got {config.docs_dir}")
    return config


def on_files(files: Files, config: MkDocsConfig) -> Files:
    """Adds the generated pages, and a copy of each file outside docs/ that a page links to."""
    _origin.clear()
    _anchors.clear()
    home, tutorial = _split_readme((REPO / "README.md").read_text(encoding="utf-8"))
    generated = {"index.md": home, "tutorial.md": tutorial, "cli.md": _cli_page()}
    for source, page in OTHER_PAGES.items():
        generated[page] = (REPO / source).read_text(encoding="utf-8")
        _origin[page] = source
    for page in README_PAGES:
        _origin[page] = "README.md"
        _anchors[page] = _slugs(generated[page])
    for src_uri, content in generated.items():
        if files.get_file_from_path(src_uri) is not None:
            raise ValueError(f"{DOCS}/{src_uri} exists, but the hook generates that page")
        files.append(File.generated(config, src_uri, content=content))
    copies: set[str] = set()
    for file in files.documentation_pages():
        origin = _origin.setdefault(file.src_uri, f"{DOCS}/{file.src_uri}")
        _, needed = _rewrite(file.content_string, origin, file.src_uri)
        copies |= needed
    for path in sorted(copies):
        files.append(File.generated(config, f"{COPIES}/{path}", abs_src_path=str(REPO / path)))
    return files


def on_page_markdown(markdown: str, page: Page, config: MkDocsConfig, files: Files) -> str:
    """The page's links, pointed at their places in the site."""
    src_uri = page.file.src_uri
    return _rewrite(markdown, _origin.get(src_uri, f"{DOCS}/{src_uri}"), src_uri)[0]


def _rewrite(markdown: str, origin: str, src_uri: str) -> tuple[str, set[str]]:
    """`markdown` of page `src_uri` with each relative link, written for the repository file
    `origin`, pointed at the site; and the repository files to copy for it (under COPIES)."""
    copies: set[str] = set()
    in_table = False

    def site_target(match: re.Match[str]) -> str:
        if match["code"] is not None:  # GitHub reads `a\|b` in a table cell as `a|b`, Python-Markdown not
            return match[0].replace("\\|", "|") if in_table else match[0]
        target = match["target"]
        path, hash_, anchor = target.partition("#")
        if not path:
            return match["open"] + _other_half(anchor, src_uri) if hash_ else match[0]
        if EXTERNAL.match(target):
            return match[0]
        repo_path = posixpath.normpath(posixpath.join(posixpath.dirname(origin), path))
        if repo_path == "README.md":
            site = _readme_page(anchor) if hash_ else "index.md"
        elif repo_path in OTHER_PAGES:
            site = OTHER_PAGES[repo_path]
        elif repo_path.startswith(DOCS + "/") and (REPO / repo_path).exists():
            site = repo_path.removeprefix(DOCS + "/")
        elif (REPO / repo_path).is_file() and not repo_path.startswith(("..", DOCS + "/")):
            site = f"{COPIES}/{repo_path}"
            copies.add(repo_path)
        else:
            return match[0]  # MkDocs reports it: a broken link fails the strict build
        relative = posixpath.relpath(site, posixpath.dirname(src_uri) or ".")
        return match["open"] + relative + hash_ + anchor

    out = []
    in_fence = False
    for line in markdown.splitlines(keepends=True):
        if FENCE.match(line.lstrip()):
            in_fence = not in_fence
        in_table = line.lstrip().startswith("|")
        out.append(line if in_fence else LINK.sub(site_target, line))
    return "".join(out), copies


def _other_half(anchor: str, src_uri: str) -> str:
    """`#anchor` on a README page: the other README page's if the heading is there, not here."""
    if src_uri not in _anchors or anchor in _anchors[src_uri]:
        return "#" + anchor
    other = next((page for page in README_PAGES if anchor in _anchors[page]), "")
    return other + "#" + anchor  # MkDocs reports an anchor on neither page


def _readme_page(anchor: str) -> str:
    """The README page with the heading `anchor` (the home page if neither has it)."""
    return next((page for page in README_PAGES if anchor in _anchors[page]), "index.md")


def _split_readme(readme: str) -> tuple[str, str]:
    """(home, tutorial): README.md without its TUTORIAL_SECTIONS, and those sections with their
    headings one level up."""
    lines = readme.splitlines(keepends=True)
    home: list[str] = []
    tutorial: list[str] = []
    part = home
    for i, line in enumerate(lines):
        fenced = _in_fence(lines, i)
        if line.startswith("## ") and not fenced:
            part = tutorial if line.startswith(TUTORIAL_SECTIONS) else home
        part.append(line[1:] if part is tutorial and HEADING.match(line) and not fenced else line)
    if not tutorial:
        raise ValueError(f"README.md has no section {TUTORIAL_SECTIONS} for the tutorial page")
    return "".join(home), "".join(tutorial)


def _in_fence(lines: list[str], index: int) -> bool:
    """Whether `lines[index]` is inside a fenced code block."""
    return sum(1 for line in lines[:index] if FENCE.match(line.lstrip())) % 2 == 1


def _slugs(markdown: str) -> set[str]:
    """The anchors MkDocs (Python-Markdown's toc) gives the headings of `markdown`."""
    lines = markdown.splitlines()
    return {slugify(m[2], "-") for i, line in enumerate(lines)
            if (m := HEADING.match(line)) and not _in_fence(lines, i)}


def _cli_page() -> str:
    """The CLI reference: the `--help` of `latentrl` and of each subcommand, in parser order."""
    from latentrl.cli import build_parser

    parts = [
        "# CLI reference\n\n",
        "The `--help` of `latentrl` and of each of its subcommands, generated when the site is built "
        "(from `latentrl.cli.build_parser()`, so it is the installed version's). `python -m latentrl` "
        "is the same command.\n\n",
    ]
    with _columns(HELP_COLUMNS):
        for name, parser in _commands(build_parser()):
            parts.append(f"## `{name}`\n\n```text\n{parser.format_help().rstrip()}\n```\n\n")
    return "".join(parts)


def _commands(parser: argparse.ArgumentParser) -> Iterator[tuple[str, argparse.ArgumentParser]]:
    """(`prog`, parser) for `parser` and, depth first, each of its subcommands."""
    yield parser.prog, parser
    for action in parser._actions:  # argparse has no public accessor for its subparsers
        if isinstance(action, argparse._SubParsersAction):
            for sub in action.choices.values():
                yield from _commands(sub)


@contextlib.contextmanager
def _columns(columns: str) -> Iterator[None]:
    """`$COLUMNS` set to `columns` (argparse formats to it) for the duration."""
    before = os.environ.get("COLUMNS")
    os.environ["COLUMNS"] = columns
    try:
        yield
    finally:
        if before is None:
            del os.environ["COLUMNS"]
        else:
            os.environ["COLUMNS"] = before
