#!/usr/bin/env python3
"""docs/http-api.md against the service's OpenAPI document: `seamcl serve --openapi` prints the
document (without opening a device), scripts/http-reference turns it into the page, and the
committed page must be exactly that; a page that differs by one line is refused naming the line,
and input that is not an OpenAPI document is refused with exit 2.

    tests/http_reference_test.py --seamcl build/seamcl
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

from script_checks import Checks

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPT = os.path.join(ROOT, "scripts", "http-reference")
PAGE = os.path.join(ROOT, "docs", "http-api.md")


def reference(document, *args):
    r = subprocess.run([sys.executable, SCRIPT, *args], input=document, capture_output=True, text=True)
    return r.returncode, r.stdout + r.stderr


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seamcl", required=True)
    args = ap.parse_args()
    check = Checks("http_reference_test")
    # No device: an ICD list that names none must not matter.
    env = dict(os.environ, OCL_ICD_VENDORS="/nonexistent")
    printed = subprocess.run([args.seamcl, "serve", "--openapi"], capture_output=True, text=True, env=env)
    check(printed.returncode == 0, f"serve --openapi exits 0 without a device: {printed.returncode} {printed.stderr[-300:]}")
    document = printed.stdout
    parsed = json.loads(document) if printed.returncode == 0 else {}
    check(parsed.get("openapi", "").startswith("3") and "/v1/render" in parsed.get("paths", {}),
          "serve --openapi prints the OpenAPI 3 document")
    schema = parsed.get("components", {}).get("schemas", {}).get("RenderRequest", {}).get("properties", {})
    check("msaa" in schema and schema["msaa"].get("enum") == [1, 2, 4, 8, 16],
          "the printed document holds the option table's schemas, filled in")

    code, out = reference(document, "--check", PAGE)
    check(code == 0, f"docs/http-api.md is the document's page (regenerate it as the message says): {out}")
    page = open(PAGE).read()
    for needle in ("### POST /v1/render", "| `msaa` |", '<a id="schema-renderrequest"></a>', "## Response headers"):
        check(needle in page, f"the page holds {needle!r}")

    with tempfile.TemporaryDirectory() as d:
        changed = os.path.join(d, "http-api.md")
        lines = page.splitlines(keepends=True)
        at = next(i for i, line in enumerate(lines) if line.startswith("| `msaa` |"))
        lines[at] = lines[at].replace("`16`", "`32`")
        open(changed, "w").write("".join(lines))
        code, out = reference(document, "--check", changed)
        check(code == 1 and f"http-api.md:{at + 1} differs" in out and "regenerate it" in out,
              f"a page one line off is refused naming line {at + 1}: {code} {out}")
        code, out = reference('{"openapi": "3.0.3"}', "--check", PAGE)
        check(code == 2 and "not an OpenAPI document" in out, f"a document without paths: {code} {out}")
        code, out = reference("not json", "-o", os.path.join(d, "x.md"))
        check(code == 2 and "http-reference: stdin" in out, f"input that is not JSON: {code} {out}")
    return check.result()


if __name__ == "__main__":
    sys.exit(main())
