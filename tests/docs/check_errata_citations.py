#!/usr/bin/env python3
"""Every citation of an item of the paper's errata resolves to a section.

The code and the docs cite the paper's known inconsistencies by the upper-case
word for errata followed by the item's number, 1 to 12. The list itself
(../shared/paper/, outside the repository) is not part of the project, so each
cited number must have a section in docs/decisions.md whose heading starts
with "## " + the word + " <n>:".

Usage: python3 tests/docs/check_errata_citations.py REPO_ROOT [--list]

Fails (exit 1), printing file:line, when a citation's number has no such
section, or when the word appears without a number (the file name, the word
followed by ".md", is a reference to the file, not a citation, and is
allowed). Sections that nothing cites are reported as information only.
--list prints every citation found. Exit 2 on a usage error. Standard
library only. (This file never writes the word itself, so that it does not
cite anything; it also skips its own path.)
"""

import os
import re
import sys

WORD = "ERR" + "ATA"  # spelt in two parts so that this file does not cite anything

# The parts of the repository that hold sources and docs. Missing ones are
# skipped (calibrate/ does not exist in every checkout).
SCAN_DIRS = [
    "engine", "geometry", "scenario", "analysis", "sweep", "viz", "cli", "common",
    "calibrate", "bench", "docs", "tests", "scripts", "studies", "venues", "fuzz", "cmake",
]
SCAN_TOP_FILES = ["README.md", "CMakeLists.txt", "Makefile"]
SKIP_DIRS = {"build", "out", ".git", ".cache", "__pycache__"}
TEXT_SUFFIXES = {
    ".c", ".cc", ".cpp", ".cxx", ".h", ".hh", ".hpp", ".cu", ".cuh", ".inl",
    ".py", ".sh", ".cmake", ".md", ".txt", ".json", ".yaml", ".yml", ".toml",
}
TEXT_NAMES = {"CMakeLists.txt", "Makefile"}

DECISIONS = os.path.join("docs", "decisions.md")
SELF = os.path.join("tests", "docs", "check_errata_citations.py")
# Any occurrence of the word; what follows decides whether it is a citation.
OCCURRENCE = re.compile(r"\b" + WORD + r"\b")
NUMBERED = re.compile(r"[ \t]+(\d+)\b")
FILE_NAME = re.compile(r"\.md\b")
HEADING = re.compile(r"^## " + WORD + r" (\d+):")


def source_files(root):
    """Relative paths of the text files to scan, in a fixed order."""
    found = []
    for name in SCAN_TOP_FILES:
        if os.path.isfile(os.path.join(root, name)):
            found.append(name)
    for top in SCAN_DIRS:
        base = os.path.join(root, top)
        if not os.path.isdir(base):
            continue
        for directory, dirs, files in os.walk(base):
            dirs[:] = sorted(d for d in dirs if d not in SKIP_DIRS and not d.startswith("build"))
            for name in sorted(files):
                if name in TEXT_NAMES or os.path.splitext(name)[1] in TEXT_SUFFIXES:
                    found.append(os.path.relpath(os.path.join(directory, name), root))
    return found


def sections(root):
    """Numbers of the section headings of docs/decisions.md (HEADING), with their lines."""
    path = os.path.join(root, DECISIONS)
    result = {}
    if not os.path.isfile(path):
        return result
    with open(path, encoding="utf-8", errors="replace") as f:
        for number, line in enumerate(f, 1):
            m = HEADING.match(line)
            if m:
                result.setdefault(int(m.group(1)), []).append(number)
    return result


def main(argv):
    args = [a for a in argv[1:] if a != "--list"]
    listing = "--list" in argv[1:]
    if len(args) != 1 or not os.path.isdir(args[0]):
        print("usage: python3 tests/docs/check_errata_citations.py REPO_ROOT [--list]", file=sys.stderr)
        return 2
    root = args[0]
    defined = sections(root)
    self_path = os.path.realpath(__file__)

    citations = []  # (path, line, number)
    problems = []
    file_references = 0
    for rel in source_files(root):
        path = os.path.join(root, rel)
        if rel == SELF or os.path.realpath(path) == self_path:
            continue
        try:
            with open(path, encoding="utf-8", errors="replace") as f:
                lines = f.readlines()
        except OSError as e:
            problems.append(f"{rel}: cannot read: {e}")
            continue
        for number, line in enumerate(lines, 1):
            for m in OCCURRENCE.finditer(line):
                rest = line[m.end():]
                if FILE_NAME.match(rest):
                    file_references += 1
                    continue
                if rel == DECISIONS and HEADING.match(line):
                    continue  # a section's own heading
                cited = NUMBERED.match(rest)
                if not cited:
                    problems.append(
                        f"{rel}:{number}: '{WORD}' without a number: cite '{WORD} <n>' "
                        f"(a section of {DECISIONS}) or name {DECISIONS}: {line.strip()[:120]}")
                    continue
                n = int(cited.group(1))
                citations.append((rel, number, n))
                if listing:
                    print(f"{rel}:{number}: {WORD} {n}")
                if n not in defined:
                    problems.append(
                        f"{rel}:{number}: {WORD} {n} has no section '## {WORD} {n}:' in {DECISIONS}")

    for n, lines in sorted(defined.items()):
        if len(lines) > 1:
            print(f"info: {DECISIONS} has {len(lines)} sections for {WORD} {n} "
                  f"(lines {', '.join(map(str, lines))})")
    cited_numbers = {n for _, _, n in citations}
    uncited = [n for n in sorted(defined) if n not in cited_numbers]
    if uncited:
        print(f"info: sections of {DECISIONS} that nothing cites: "
              + ", ".join(f"{WORD} {n}" for n in uncited))
    if file_references:
        print(f"info: {file_references} reference(s) to the file {WORD}.md (outside the repository) not checked")

    if problems:
        for p in problems:
            print(p)
        print(f"FAILED: {len(problems)} problem(s) in {len(citations)} citation(s) "
              f"of {WORD} items; {DECISIONS} has sections for "
              + (", ".join(str(n) for n in sorted(defined)) or "none"))
        return 1
    print(f"OK: {len(citations)} {WORD} citations in {len({p for p, _, _ in citations})} files checked; "
          f"all resolve to the {len(defined)} sections of {DECISIONS}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
