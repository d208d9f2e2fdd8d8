#!/usr/bin/env python3
"""Offline checks of the guide, run by scripts/test-all.sh after `mdbook build docs`.

- Every relative link in the built book (docs/book/**/*.html) resolves to a file of the book,
  and every anchor (`page.html#id`, `#id`) to an element with that id in its page.
- Every relative link in README.md and in docs/src/**/*.md names a file that exists (links
  inside the book are also checked, with their anchors, in the built pages above).
- Every shell block (```sh, ```bash) in README.md and docs/src parses (`bash -n`).

Usage: scripts/check-docs.py [REPO_ROOT]   (exit 1 with one line per fault)
"""

import html.parser
import pathlib
import re
import subprocess
import sys
import urllib.parse

root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()
book = root / "docs" / "book"
src = root / "docs" / "src"
faults = []


class Page(html.parser.HTMLParser):
    """The ids and the links of one HTML page."""

    def __init__(self):
        super().__init__()
        self.ids, self.links = set(), []

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if a.get("id"):
            self.ids.add(a["id"])
        if tag == "a" and a.get("name"):
            self.ids.add(a["name"])
        for key in ("href", "src"):
            if a.get(key) is not None and tag in ("a", "img", "link", "script"):
                self.links.append(a[key])


def external(link):
    return re.match(r"^[a-z][a-z0-9+.-]*:", link) is not None or link.startswith("//")


if not (book / "index.html").is_file():
    sys.exit(f"check-docs: {book}/index.html is missing: run `mdbook build docs` first")

pages = {}
for f in sorted(book.rglob("*.html")):
    p = Page()
    p.feed(f.read_text(encoding="utf-8"))
    pages[f.resolve()] = p

# The print page repeats every chapter with its links rewritten to its own anchors, and the
# 404 page is served from the book's root: neither is a chapter.
skip = {(book / "print.html").resolve(), (book / "404.html").resolve()}
checked = 0
for f, p in pages.items():
    if f in skip:
        continue
    for link in p.links:
        if external(link):
            continue
        checked += 1
        target, _, anchor = link.partition("#")
        target = urllib.parse.unquote(target)
        dest = (f.parent / target).resolve() if target else f
        rel = f.relative_to(book.resolve())
        if not dest.exists():
            faults.append(f"{rel}: link {link!r}: no file {dest.relative_to(root) if dest.is_relative_to(root) else dest}")
            continue
        if dest.is_dir():
            dest = dest / "index.html"
        if anchor and dest.suffix == ".html":
            ids = pages.get(dest.resolve())
            if ids is None or urllib.parse.unquote(anchor) not in ids.ids:
                faults.append(f"{rel}: link {link!r}: no anchor #{anchor} in {dest.name}")

md_link = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
fence = re.compile(r"^```(\w*)\s*$")
md_files = [root / "README.md"] + sorted(src.rglob("*.md"))
blocks = 0
for md in md_files:
    text = md.read_text(encoding="utf-8")
    rel = md.relative_to(root)
    lines = text.splitlines()
    in_block, lang, block, start = False, "", [], 0
    for n, line in enumerate(lines, 1):
        m = fence.match(line.strip())
        if m and not in_block:
            in_block, lang, block, start = True, m.group(1), [], n
            continue
        if line.strip() == "```" and in_block:
            in_block = False
            if lang in ("sh", "bash", "shell"):
                blocks += 1
                r = subprocess.run(["bash", "-n"], input="\n".join(block), text=True,
                                   capture_output=True)
                if r.returncode != 0:
                    faults.append(f"{rel}:{start}: shell block does not parse: {r.stderr.strip()}")
            continue
        if in_block:
            block.append(line)
            continue
        for link in md_link.findall(re.sub(r"`[^`]*`", "", line)):
            if external(link) or link.startswith("#"):
                continue
            target = urllib.parse.unquote(link.partition("#")[0])
            if not (md.parent / target).exists():
                faults.append(f"{rel}:{n}: link {link!r}: no file {target}")
    if in_block:
        faults.append(f"{rel}:{start}: code block never closed")

for f in faults:
    print(f"check-docs: {f}", file=sys.stderr)
if faults:
    sys.exit(1)
print(f"check-docs: {checked} links in {len(pages) - len(skip)} pages resolve; "
      f"{len(md_files)} Markdown files' links exist; {blocks} shell blocks parse")
