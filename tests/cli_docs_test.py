#!/usr/bin/env python3
"""docs/cli.md against the tool: every flag of `seamcl render --help` has a row in the render
options table, and every flag the page names is a flag of some command's `--help` (or the global
`--device`), so the reference cannot miss an option or keep one that is gone.

    tests/cli_docs_test.py --seamcl build/seamcl [--doc docs/cli.md]
"""
import argparse
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FLAG = re.compile(r"--[a-z0-9][a-z0-9-]*")


def help_text(seamcl, *command):
    return subprocess.run([seamcl, *command, "--help"], capture_output=True, text=True, check=True).stdout


def help_flags(seamcl, *command):
    """The flags of a command's --help and of its subcommands' (`ptx lookup`), recursively."""
    text = help_text(seamcl, *command)
    flags = {m.group(1) for line in text.splitlines() for m in [re.match(r"\s+(?:-\w,)?(--[a-z0-9-]+)", line)] if m}
    for name in subcommands(text):
        flags |= help_flags(seamcl, *command, name)
    return flags


def subcommands(text):
    return re.findall(r"^  ([a-z][a-z-]+)\s", text.split("Subcommands:")[1], re.M) if "Subcommands:" in text else []


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seamcl", required=True)
    ap.add_argument("--doc", default=os.path.join(ROOT, "docs", "cli.md"))
    args = ap.parse_args()
    doc = open(args.doc, encoding="utf-8").read()
    table_rows = [line for line in doc.splitlines() if line.startswith("| `-")]
    in_table = {flag for row in table_rows for flag in FLAG.findall(re.split(r"(?<!\\)\|", row)[1])}  # the first cell
    failures = []

    render = help_flags(args.seamcl, "render") - {"--help"}
    for flag in sorted(render - in_table):
        failures.append(f"docs/cli.md: `render {flag}` has no row in the options table")

    names = subcommands(help_text(args.seamcl))
    if "render" not in names or len(names) < 5:
        failures.append(f"seamcl --help: expected the subcommands, read {names}")
    known = help_flags(args.seamcl)  # the global flags and every command's
    for flag in sorted(set(FLAG.findall(doc)) - known):
        failures.append(f"docs/cli.md names {flag}, which no command's --help lists")

    for f in failures:
        print("FAIL: " + f, file=sys.stderr)
    print(f"{len(render)} render flags, {len(known)} flags over {len(names)} commands; {len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
