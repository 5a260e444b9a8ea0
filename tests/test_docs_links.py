"""Every relative link in README.md and docs/*.md points at a file that exists (and a heading that exists).

Links are Markdown ``[text](target)`` and ``![alt](target)`` outside code; targets are
resolved from the linking file's folder, as GitHub does. External links (``http:``,
``https:``, ``mailto:``) are not fetched.
"""

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent

#: Pages other branches are writing; links to them are allowed until they land. Empty this
#: set when they are merged (an entry whose file exists is an error, so it cannot go stale).
PENDING = {}

#: Pages whose README link is written by the lead at merge (helpers do not edit README.md);
#: docs/index.md links them meanwhile. Remove an entry when README.md links it.
README_PENDING: set = set()

_LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(([^()\s]+)(?:\s+\"[^\"]*\")?\)")
_FENCE = re.compile(r"^\s*(```|~~~)")
_CODE_SPAN = re.compile(r"`[^`\n]*`")


def doc_files() -> list[Path]:
    return [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]


def prose_lines(text: str):
    """Yield ``(line_number, line)`` outside fenced code blocks, with inline code removed."""
    in_fence = False
    for number, line in enumerate(text.splitlines(), 1):
        if _FENCE.match(line):
            in_fence = not in_fence
            continue
        if not in_fence:
            yield number, _CODE_SPAN.sub("", line)


def links(path: Path) -> list[tuple[int, str]]:
    """``(line_number, target)`` of every Markdown link and image in ``path``."""
    return [(n, m.group(1)) for n, line in prose_lines(path.read_text(encoding="utf-8")) for m in _LINK.finditer(line)]


def slug(heading: str) -> str:
    """GitHub's anchor for a heading: lower case, punctuation dropped, spaces to hyphens."""
    text = re.sub(r"[^\w\- ]", "", heading.strip().lower().replace("`", ""))
    return text.replace(" ", "-")


def anchors(path: Path) -> set[str]:
    """The anchors GitHub gives ``path``'s headings (a repeated heading gets ``-1``, ``-2``, ...)."""
    seen: dict[str, int] = {}
    out = set()
    for _, line in prose_lines(path.read_text(encoding="utf-8")):
        m = re.match(r"#{1,6}\s+(.*?)\s*#*\s*$", line)
        if not m:
            continue
        base = slug(m.group(1))
        k = seen.get(base, 0)
        seen[base] = k + 1
        out.add(base if k == 0 else f"{base}-{k}")
    return out


def broken_links(path: Path, root: Path = ROOT, pending=frozenset(PENDING)) -> list[str]:
    """One message per link in ``path`` whose file, or heading, does not exist.

    ``root`` is the repository (links may not leave it); targets in ``pending`` are skipped.
    """
    problems = []
    for number, target in links(path):
        if re.match(r"[a-z][a-z0-9+.-]*:", target):  # http:, https:, mailto:
            continue
        file_part, _, fragment = target.partition("#")
        dest = (path.parent / file_part).resolve() if file_part else path
        where = f"{path.relative_to(root)}:{number}: link {target!r}"
        try:
            rel = dest.relative_to(root).as_posix()
        except ValueError:
            problems.append(f"{where} leaves the repository")
            continue
        if rel in pending:
            continue
        if not dest.exists():
            problems.append(f"{where}: {rel} does not exist")
        elif fragment and dest.suffix == ".md" and fragment not in anchors(dest):
            problems.append(f"{where}: no heading #{fragment} in {rel}")
    return problems


def test_docs_exist_and_have_links():
    # A link check over no files, or files without links, would pass on nothing: the README
    # and the docs map must exist and link somewhere (the README links every docs page).
    files = doc_files()
    assert (ROOT / "docs" / "index.md") in files
    assert links(ROOT / "docs" / "index.md"), "docs/index.md: no links found (a parser that finds none checks nothing)"
    readme_targets = {t.partition("#")[0] for _, t in links(ROOT / "README.md")}
    for page in files[1:]:
        if f"docs/{page.name}" in README_PENDING:
            continue
        assert f"docs/{page.name}" in readme_targets, f"README.md does not link docs/{page.name}"


@pytest.mark.parametrize("path", doc_files(), ids=lambda p: p.relative_to(ROOT).as_posix())
def test_relative_links_resolve(path):
    problems = broken_links(path)
    assert not problems, "\n".join(problems)


def test_pending_pages_do_not_exist_yet():
    # Once a pending page lands, its links must be checked like any other: drop it from PENDING.
    landed = sorted(p for p in PENDING if (ROOT / p).exists())
    assert not landed, f"remove from PENDING in {Path(__file__).name}: {landed}"


def test_checker_finds_broken_links(tmp_path):
    # Hand-made page: one good file link, one missing file, one missing heading, one good
    # anchor, one link inside code (ignored), one external link (ignored).
    page = tmp_path / "page.md"
    (tmp_path / "there.md").write_text("# Here it is\n", encoding="utf-8")
    page.write_text(
        "# Top\n\n[ok](there.md) [gone](missing.png) ![img](there.md#nope)\n"
        "[self](#top) [good](there.md#here-it-is) `[x](code.md)` [web](https://example.org)\n"
        "```\n[fenced](fenced.md)\n```\n",
        encoding="utf-8",
    )
    assert [t for _, t in links(page)] == [
        "there.md",
        "missing.png",
        "there.md#nope",
        "#top",
        "there.md#here-it-is",
        "https://example.org",
    ]
    assert anchors(page) == {"top"}
    assert slug("`crosscheck`: what it says") == "crosscheck-what-it-says"
    problems = broken_links(page, root=tmp_path, pending=frozenset())
    assert len(problems) == 2, problems
    assert "missing.png does not exist" in problems[0]
    assert "no heading #nope in there.md" in problems[1]
