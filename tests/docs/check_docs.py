"""ctest docs_check: the README and docs/ pages keep their promises to a reader.

- every relative link and image of README.md, CHANGELOG.md and docs/*.md names a file that exists, and every
  #anchor a heading of its page (GitHub's heading slugs);
- every repository path written in backticks (`tools/test.sh`, `docs/tunnel_closeup.png`, ...) exists;
- with --bin: every program a command names as build/bin/NAME is built;
- every page of docs/ is reachable from the README, and each topic page opens with its title and a paragraph
  saying what the reader finds there;
- the README stays a door: at most 200 lines, the two commands exactly as .ci/run and users rely on them.
The code blocks run elsewhere: the README's C++ example in ctest package_install (tests/package), its Python
example and docs/python.md's in tests/python (pytest), its pip commands in tools/pip_install_test.sh.
Usage: check_docs.py --source DIR [--bin DIR]; exit 1 listing every broken promise.
"""
import argparse
import re
import sys
from pathlib import Path

# Reports kept as they were written (issue notes, one run's report): checked for links, not for the page opening.
REPORTS = {"issue30_plan.md", "issue31_popfree.md", "speed_vs_error.md"}
TOP_DIRS = ("engine/", "modules/", "tools/", "tests/", "python/", "docs/", "cmake/", "examples/", "game/",
            "assets/", ".ci/")
TWO_COMMANDS = """```sh
# (a) install what is needed, build, and run the main job (the tunnel level)
tools/setup.sh && build/bin/tunnel

# (b) build and run every test (CI runs exactly this: .ci/run)
tools/test.sh
```"""


def slug(heading):
    """GitHub's anchor of a markdown heading: lower case, punctuation dropped, spaces to hyphens."""
    text = re.sub(r"[`*_]", "", heading.strip().lower())
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(path):
    text = strip_code(path.read_text())
    return {slug(m.group(1)) for m in re.finditer(r"^#{1,6} (.+)$", text, re.M)}


def strip_code(text):
    """The text without fenced code blocks (links and headings inside them are not links and headings)."""
    return re.sub(r"^```.*?^```", "", text, flags=re.M | re.S)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--source", required=True, type=Path)
    parser.add_argument("--bin", type=Path)
    args = parser.parse_args()
    root = args.source.resolve()
    readme = root / "README.md"
    pages = [readme, root / "CHANGELOG.md"] + sorted((root / "docs").glob("*.md"))
    problems = []
    linked = {}  # page -> pages it links

    for page in pages:
        name = page.relative_to(root)
        raw = page.read_text()
        text = strip_code(raw)
        linked[page] = set()
        for target in re.findall(r"\]\(([^)\s]+)\)", text):
            if re.match(r"[a-z]+:", target):
                continue  # https:, mailto:
            file_part, _, anchor = target.partition("#")
            dest = (page.parent / file_part).resolve() if file_part else page
            if not dest.exists():
                problems.append(f"{name}: link to {target}: {dest.relative_to(root) if dest.is_relative_to(root) else dest} does not exist")
                continue
            linked[page].add(dest)
            if anchor and dest.suffix == ".md" and anchor not in anchors(dest):
                problems.append(f"{name}: link to {target}: no heading with anchor #{anchor} in {dest.name}")
        for path in re.findall(r"`([^`\s]+)`", raw):
            path = path.rstrip(".,;:")
            if not path.startswith(TOP_DIRS) or re.search(r"[A-Z]{2,}|[{}*<>%]|\.\.\.", path):
                continue  # not a repository path, or a pattern (NAME, {a,b}, *, %04d)
            if not (root / path).exists():
                problems.append(f"{name}: `{path}` does not exist in the repository")
        if args.bin:
            for program in sorted(set(re.findall(r"\bbuild/bin/([A-Za-z0-9_]+)", raw))):
                if program.isupper():
                    continue  # a placeholder (build/bin/NAME)
                if not (args.bin / program).exists():
                    problems.append(f"{name}: names build/bin/{program}, which the build does not make")

    # Every docs page reachable from the README.
    seen, todo = {readme}, [readme]
    while todo:
        for dest in linked.get(todo.pop(), ()):
            if dest not in seen:
                seen.add(dest)
                todo.append(dest)
    for page in sorted((root / "docs").glob("*.md")):
        if page not in seen:
            problems.append(f"docs/{page.name}: not linked from the README (directly or through another page)")
        if page.name in REPORTS:
            continue
        lines = page.read_text().split("\n")
        if not (lines[0].startswith("# ") and lines[1] == "" and lines[2] and not lines[2].startswith(("#", "`", "|", "-"))):
            problems.append(f"docs/{page.name}: does not open with '# Title', a blank line and a paragraph")

    text = readme.read_text()
    if text.count("\n") > 200:
        problems.append(f"README.md: {text.count(chr(10))} lines, more than 200 (move the detail into docs/)")
    if TWO_COMMANDS not in text:
        problems.append("README.md: the two commands are not written exactly as they were (tools/setup.sh && "
                        "build/bin/tunnel; tools/test.sh)")

    for p in problems:
        print(p)
    print(f"docs_check: {len(pages)} pages, {len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
