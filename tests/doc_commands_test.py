#!/usr/bin/env python3
"""The documentation's commands run as written, so the tour and the reference pages cannot drift
from the tool: every command of README.md's `sh` blocks, and of the blocks of docs/*.md whose
fence says so (```sh runnable: examples at a small size; the others show full-size runs, ranges
of options or set-up). Each `build/seamcl ...` line runs with this build's binary, each
`/usr/bin/python3 examples/...` line with that interpreter (skipped with a note when it lacks
matplotlib), in a scratch directory, with the repository's relative paths (tests/, examples/)
made absolute. A command must exit 0 and leave every file it names (`-o FILE`, `> FILE`, `--out
DIR`, `--images DIR`) non-empty. Lines that install or build (`scripts/...`) are what CI itself
runs and are not repeated.

    tests/doc_commands_test.py --seamcl build/seamcl [--doc README.md --doc docs/cli.md ...]
"""
import argparse
import glob
import os
import re
import shlex
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


RUNNABLE = "```sh runnable"


def shell_lines(page, marked_only):
    """The commands of the page's ```sh blocks (with `marked_only`, of its ```sh runnable blocks),
    a trailing backslash joining lines."""
    lines, block, pending = [], False, ""
    for line in open(page, encoding="utf-8").read().split("\n"):
        if line.startswith("```"):
            fence = line.strip()
            block = (fence == RUNNABLE or (fence == "```sh" and not marked_only)) if not block else False
            continue
        if not block:
            continue
        pending += line.rstrip("\\").rstrip() + " " if line.endswith("\\") else line
        if not line.endswith("\\"):
            if pending.strip():
                lines.append(pending.strip())
            pending = ""
    return lines


def absolute(word):
    first = word.split("/", 1)[0]
    return os.path.join(ROOT, word) if first in ("tests", "examples") and "/" in word else word


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seamcl", required=True)
    ap.add_argument("--doc", action="append",
                    help="a page whose ```sh runnable blocks run (repeatable) [README.md, every sh block, and docs/*.md]")
    args = ap.parse_args()
    if args.doc:
        pages = [(os.path.abspath(p), True) for p in args.doc]
    else:
        pages = [(os.path.join(ROOT, "README.md"), False)] + \
                [(p, True) for p in sorted(glob.glob(os.path.join(ROOT, "docs", "*.md")))]
    commands = [(os.path.relpath(page, ROOT), text) for page, marked in pages for text in shell_lines(page, marked)]
    failures, ran = [], 0
    runnable_pages = {page for page, _ in commands}
    matplotlib = subprocess.run(["/usr/bin/python3", "-c", "import matplotlib"], capture_output=True).returncode == 0
    with tempfile.TemporaryDirectory(prefix="seamcl-readme-") as scratch:
        for page, text in commands:
            words = shlex.split(text, comments=True)
            if not words or words[0].startswith("scripts/"):
                continue
            stdout_file = None
            if ">" in words:
                at = words.index(">")
                stdout_file, words = words[at + 1], words[:at]
            if words[0] == "build/seamcl":
                words[0] = os.path.abspath(args.seamcl)
            elif words[0] == "/usr/bin/python3":
                if not matplotlib:
                    print(f"not run (no matplotlib for /usr/bin/python3): {text}")
                    continue
            else:
                failures.append(f"{page}: a command this test does not know how to run: {text}")
                continue
            words = [absolute(w) for w in words]
            outputs = [words[i + 1] for i, w in enumerate(words[:-1]) if w in ("-o", "--out", "--images")]
            if stdout_file:
                outputs.append(stdout_file)
            out = open(os.path.join(scratch, stdout_file), "w") if stdout_file else subprocess.PIPE
            try:
                done = subprocess.run(words, cwd=scratch, stdout=out, stderr=subprocess.PIPE, text=True, timeout=240)
            finally:
                if stdout_file:
                    out.close()
            ran += 1
            if done.returncode != 0:
                failures.append(f"{page}: exit {done.returncode}: {text}\n{done.stderr.strip()[-1500:]}")
                continue
            for name in outputs:
                path = os.path.join(scratch, name)
                empty = not os.path.exists(path) or (
                    os.path.isdir(path) and not os.listdir(path)) or (os.path.isfile(path) and os.path.getsize(path) == 0)
                if empty:
                    failures.append(f"{page}: {text}: wrote nothing to {name}")
            print(f"ok ({page}): {text}")
    if ran == 0:
        failures.append("no command ran (are the blocks still marked ```sh, or ```sh runnable?)")
    if not args.doc and len(runnable_pages) < 2:
        failures.append(f"commands of {sorted(runnable_pages)} only: no page under docs/ has a ```sh runnable block")
    for f in failures:
        print("FAIL: " + f, file=sys.stderr)
    print(f"{ran} command(s) of {len(runnable_pages)} page(s) ran, {len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
