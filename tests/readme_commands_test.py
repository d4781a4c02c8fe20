#!/usr/bin/env python3
"""Every command of README.md's `sh` blocks runs as written, so the tour cannot drift from the
tool: each `build/seamcl ...` line runs with this build's binary, each `/usr/bin/python3
examples/...` line with that interpreter (skipped with a note when it lacks matplotlib), in a
scratch directory, with the repository's relative paths (tests/, examples/) made absolute. A
command must exit 0 and leave every file it names (`-o FILE`, `> FILE`, `--out DIR`) non-empty.
Lines that install or build (`scripts/...`) are what CI itself runs and are not repeated.

    tests/readme_commands_test.py --seamcl build/seamcl [--readme README.md]
"""
import argparse
import os
import re
import shlex
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def shell_lines(readme):
    """The commands of the ```sh blocks, a trailing backslash joining lines."""
    lines, block, pending = [], False, ""
    for line in open(readme, encoding="utf-8").read().split("\n"):
        if line.startswith("```"):
            block = line.strip() == "```sh" if not block else False
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
    ap.add_argument("--readme", default=os.path.join(ROOT, "README.md"))
    args = ap.parse_args()
    commands = shell_lines(args.readme)
    failures, ran = [], 0
    matplotlib = subprocess.run(["/usr/bin/python3", "-c", "import matplotlib"], capture_output=True).returncode == 0
    with tempfile.TemporaryDirectory(prefix="seamcl-readme-") as scratch:
        for text in commands:
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
                failures.append(f"README.md: a command this test does not know how to run: {text}")
                continue
            words = [absolute(w) for w in words]
            outputs = [words[i + 1] for i, w in enumerate(words[:-1]) if w in ("-o", "--out")]
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
                failures.append(f"exit {done.returncode}: {text}\n{done.stderr.strip()[-1500:]}")
                continue
            for name in outputs:
                path = os.path.join(scratch, name)
                empty = not os.path.exists(path) or (
                    os.path.isdir(path) and not os.listdir(path)) or (os.path.isfile(path) and os.path.getsize(path) == 0)
                if empty:
                    failures.append(f"{text}: wrote nothing to {name}")
            print(f"ok: {text}")
    if ran == 0:
        failures.append("README.md: no command ran (are its blocks still marked ```sh?)")
    for f in failures:
        print("FAIL: " + f, file=sys.stderr)
    print(f"{ran} README command(s) ran, {len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
