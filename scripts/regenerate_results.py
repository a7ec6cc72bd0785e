#!/usr/bin/env python3
"""Reruns the commands of the documentation that measure a section, then writes its table.

    scripts/regenerate_results.py [SECTION...] [--list] [--tables-only]

Each section of docs/*.md is a table between `<!-- results:SECTION -->` and
`<!-- /results:SECTION -->`; the last ```sh block before it measures it and writes it with
scripts/write_results.py (one block may write several sections). This runs those blocks, once
each, from the repository's root, so that the document and what regenerates it are one text and
cannot drift apart. (The README's table is written by a block of docs/results.md.) Without
a SECTION it runs every section, which takes hours on 2 cores; --list says what there is.
"""
import argparse
import os
import re
import subprocess
import sys

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))


def sections(text):
    """(name, commands) of every section, in the order of the document."""
    out = []
    for match in re.finditer(r"^<!-- results:([\w-]+) -->$", text, re.M):
        blocks = re.findall(r"```sh\n(.*?)```", text[:match.start()], re.S)
        if not blocks:
            sys.exit(f"section '{match.group(1)}' has no ```sh block before it")
        out.append((match.group(1), blocks[-1]))
    return out


def tables_only(commands):
    """The block's scripts/write_results.py calls and picture copies, continuation lines
    joined."""
    lines = commands.replace("\\\n", " ").splitlines()
    return "\n".join(line for line in lines
                     if line.startswith(("scripts/write_results.py ", "cp data/")))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("sections", nargs="*", metavar="SECTION")
    parser.add_argument("--list", action="store_true", help="name the sections and stop")
    parser.add_argument("--tables-only", action="store_true",
                        help="only write the tables (and copy the pictures) from the outputs "
                             "the commands wrote before, without measuring again")
    args = parser.parse_args()
    found = []
    docs = os.path.join(ROOT, "docs")
    for name in sorted(os.listdir(docs)):
        if name.endswith(".md"):
            with open(os.path.join(docs, name), encoding="utf-8") as f:
                found += sections(f.read())
    if args.list:
        print("\n".join(name for name, _ in found))
        return
    names = [name for name, _ in found]
    unknown = [s for s in args.sections if s not in names]
    if unknown:
        sys.exit(f"no section {', '.join(unknown)} in docs/ (there are: {', '.join(names)})")
    done_blocks = set()
    for name, commands in found:
        if (args.sections and name not in args.sections) or commands in done_blocks:
            continue
        done_blocks.add(commands)
        if args.tables_only:
            commands = tables_only(commands)
        print(f"== {name}", flush=True)
        # The document's own commands, as a user would paste them into a shell.
        ran = subprocess.run(["bash", "-euo", "pipefail", "-c", commands], cwd=ROOT)
        if ran.returncode != 0:
            sys.exit(f"section '{name}': its commands failed (exit {ran.returncode})")


if __name__ == "__main__":
    main()
